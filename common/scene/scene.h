#pragma once
/// @file
/// The library scene: a book cart with books, a book holder, the user's screen,
/// lighting and cameras, generated from a YAML file (config/scenes/) and a seed.
/// No MuJoCo here: the planner uses this for obstacle geometry, the simulator
/// (common/scene/sim_model.h) turns it into a MuJoCo model.
///
/// Frame: everything is expressed in `base` (robot arm mount: x forward
/// towards the cart, y left, z up), metres and radians. See docs/SCENE.md.

#include <array>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/config.h"

namespace bookgrasp::scene {

/// A static box of the scene (cart boards, stripe, holder plates, screen).
struct StaticBox {
  std::string name;             ///< unique geom name, e.g. "cart_upper_shelf"
  std::string owner;            ///< "cart", "stripe", "holder", "screen"
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< box centre in base
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();     ///< half extents along the box axes
  Eigen::Vector3d rgb = Eigen::Vector3d::Constant(0.5);    ///< colour 0..1
};

/// An AprilTag marker (family tag36h11), printed with a one-cell white border.
struct Marker {
  std::string name;  ///< "cart_marker" or "holder_marker"
  int id = 0;        ///< tag36h11 id
  double size_m = 0; ///< edge of the black square (the usual AprilTag "size")
  /// Tag centre in base. Axes: x = tag right, y = tag up (as printed, read
  /// upright), z = out of the tag face towards the viewer.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};

/// A stamp printed on a page edge (fore-edge), in face coordinates.
struct Stamp {
  double u = 0.5;   ///< centre across the thickness, 0 = right edge .. 1 = left edge
  double v = 0.5;   ///< centre along the height, 0 = top .. 1 = bottom
  double diameter_m = 0.02;  ///< stamp diameter (or edge), metres
  Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
  bool round = true;///< round or rectangular
};

/// One book. Book body frame: origin at the box centre; x = depth, pointing
/// away from the robot (the fore-edge face is at x = -depth/2), y = thickness
/// (left), z = height (up). Its pose is that frame in base.
struct Book {
  int id = 0;                 ///< 0 = right-most at generation, increasing to the left
  bool portrait = true;       ///< portrait format (tall) or landscape (short and deep)
  double width_m = 0;         ///< thickness, spine to spine (along body y)
  double height_m = 0;        ///< along body z
  double depth_m = 0;         ///< cover width, into the shelf (along body x)
  double lean_rad = 0;        ///< rotation about body x; > 0 tilts the top towards -y (right)
  double mass_kg = 0;         ///< from the volume and books.density_kg_m3
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< body in base, as generated
  Eigen::Vector3d cover_rgb = Eigen::Vector3d::Constant(0.5);
  Eigen::Vector3d page_rgb = Eigen::Vector3d::Constant(0.9);
  std::vector<Stamp> stamps;  ///< stamps on the fore-edge
  uint64_t texture_seed = 0;  ///< seed of the page-line pattern
};

/// Lighting drawn per scene.
struct Lighting {
  Eigen::Vector3d direction = Eigen::Vector3d(0, 0, -1);  ///< unit vector the light travels along, base
  double intensity = 0.7;     ///< diffuse intensity of the key light, 0..1
  double ambient = 0.3;       ///< ambient intensity, 0..1
  bool shadows = true;        ///< the key light casts shadows
  int shadow_size = 1024;     ///< shadow map size (px)
};

/// A pinhole camera: optical frame x right, y down, z forward.
struct CameraSpec {
  std::string name;           ///< "stereo_left", "stereo_right", "hand_camera"
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< optical frame in base (hand: in the URDF link)
  double fovy_rad = 0.8;      ///< vertical field of view
  int width = 640;
  int height = 480;
  double noise_stddev = 0;    ///< additive Gaussian noise, grey levels (0..255)
  double exposure = 1;        ///< brightness gain applied to the rendered image
};

/// Physics parameters of the simulation.
struct Physics {
  double timestep_s = 0.002;
  double impratio = 10;
  int noslip_iterations = 0;        ///< MuJoCo's no-slip solver passes (0 = off): no creep of held books
  double settle_time_s = 0.5;       ///< physics run at build so books come to rest
  std::vector<double> arm_kp;       ///< position gain per arm joint (Nm/rad)
  std::vector<double> arm_damping;  ///< joint damping per arm joint (Nm s/rad)
  double arm_armature = 0.1;        ///< reflected rotor inertia per arm joint (kg m^2)
  double gripper_kp = 2000;         ///< N/m on the plate gap
  double gripper_damping = 20;      ///< N s/m per finger
  double gripper_max_force_n = 100; ///< default force limit of the gripper actuator
  /// MuJoCo solref (time constant s, damping ratio) of the equality that couples the fingers (the PG70's screw).
  std::vector<double> gripper_coupling_solref{0.004, 1.0};
  /// MuJoCo solref (time constant s, damping ratio) of the plates' contacts; they override the other geom's.
  std::vector<double> finger_solref{0.01, 1.0};
  /// MuJoCo solimp (dmin, dmax, width m) of the plates' contacts; they override the other geom's.
  std::vector<double> finger_solimp{0.95, 0.99, 0.001};
  double finger_friction = 1.0;
  double book_friction = 0.35;
  double shelf_friction = 0.4;
  double book_density_kg_m3 = 650;
};

/// Offscreen rendering settings written into the model.
struct RenderSettings {
  int offscreen_width = 1280;
  int offscreen_height = 960;
  int offsamples = 0;  ///< 0 keeps rendered depth exact (PLATFORM.md)
  double page_px_per_mm = 3;        ///< page-edge texture resolution
  double page_line_contrast = 0.08; ///< relative darkness of the page lines
};

/// A generated scene: the YAML file + seed, resolved into geometry.
struct Scene {
  std::string source;        ///< the YAML file it came from
  std::string name;          ///< scene name from the file
  uint64_t seed = 0;

  std::string urdf_path;     ///< robot description (absolute or relative to the working dir)
  std::vector<double> initial_joints;  ///< 7 arm joints at start (rad)
  double initial_gripper_width_m = 0.06;

  double floor_z = -0.55;    ///< floor height in base
  Eigen::Isometry3d cart_pose = Eigen::Isometry3d::Identity();  ///< cart frame in base: origin at
                             ///< the upper shelf's top surface, front edge, centre; axes as base
  double shelf_width_m = 0.8;    ///< inner width between the side panels
  double shelf_depth_m = 0.36;   ///< from the front edge to the rear board's front face
  double lower_shelf_drop_m = 0.35;  ///< lower shelf surface below the upper one
  double stripe_height_m = 0.10;     ///< stripe centre line above the upper shelf surface
  double stripe_thickness_m = 0.02;  ///< vertical extent of the stripe
  Eigen::Isometry3d holder_pose = Eigen::Isometry3d::Identity();  ///< holder frame in base (see SCENE.md)
  /// Where a book rests on the holder: frame at the bottom front of the book
  /// support, x into the back plate, y left, z up along the back plate.
  Eigen::Isometry3d holder_support_pose = Eigen::Isometry3d::Identity();

  std::vector<StaticBox> boxes;  ///< cart, stripe, holder, screen
  Marker cart_marker;
  Marker holder_marker;
  std::vector<Book> books;       ///< ordered right (-y) to left

  Lighting lighting;
  CameraSpec stereo_left;
  CameraSpec stereo_right;
  double stereo_baseline_m = 0.12;
  CameraSpec hand_camera;        ///< pose unused (the URDF link gives it)
  Physics physics;
  RenderSettings render;

  /// Upper shelf surface height in base (cart frame z = 0).
  double upper_shelf_z() const { return cart_pose.translation().z(); }
};

/// Loads `yaml_path` and generates the scene for `seed`. Relative paths in the
/// file (robot.urdf) are resolved against the file's folder. Throws ConfigError
/// naming the key for a missing or bad value.
Scene load_scene(const std::string& yaml_path, uint64_t seed);

/// Generates a scene from an already loaded configuration (the root of a scene
/// file). `base_dir` resolves relative paths. Every key is required.
Scene generate_scene(const Config& config, uint64_t seed, const std::string& base_dir);

// ---- ground-truth geometry (pure functions of a pose and dimensions) ----

/// The 8 corners of a book in base for the body pose `pose`. Index bits:
/// bit 0 = back (+x body) vs front, bit 1 = left (+y) vs right, bit 2 = top (+z)
/// vs bottom. Corner 4 (front, right, top) is the paper's P1.
std::array<Eigen::Vector3d, 8> book_corners(const Eigen::Isometry3d& pose, double width, double height,
                                            double depth);

/// Index of P1 in book_corners(): the upper-right front corner.
constexpr int kP1CornerIndex = 4;

/// Where the book occludes the stripe: the point on the stripe's centre line
/// (on the rear board's front face, at the stripe height) whose y is that of
/// the book's right front edge at the stripe height.
Eigen::Vector3d stripe_end(const Scene& scene, const Eigen::Isometry3d& book_pose, double width, double height,
                           double depth);

/// Where a book with centre `position` is: "upper_shelf", "lower_shelf",
/// "holder" or "other" (the caller decides "gripper").
std::string classify_place(const Scene& scene, const Eigen::Vector3d& position);

/// Seeded random numbers that give the same values on every platform (own
/// uniform/normal from the raw std::mt19937_64 output).
class Rng {
 public:
  explicit Rng(uint64_t seed);
  /// Uniform in [0, 1).
  double uniform01();
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi);
  /// Normal with the given mean and standard deviation (Box-Muller).
  double normal(double mean, double stddev);
  /// Integer uniform in [lo, hi].
  int uniform_int(int lo, int hi);
  /// True with probability p.
  bool bernoulli(double p);
  /// Raw 64-bit output.
  uint64_t next();

 private:
  std::mt19937_64 engine_;
};

}  // namespace bookgrasp::scene
