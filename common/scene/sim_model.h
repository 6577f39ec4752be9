#pragma once
/// @file
/// The MuJoCo model of a scene: the robot (from the URDF), the cart, holder,
/// screen, floor and books, cameras, lights and textures, built in memory.
///
/// Library `bookgrasp_sim_model` (links mujoco::mujoco). CMake: the targets
/// `bookgrasp_scene` and `bookgrasp_sim_model` are defined in
/// common/scene/CMakeLists.txt; include it with
///   if(NOT TARGET bookgrasp_sim_model)
///     add_subdirectory(${PROJECT_SOURCE_DIR}/common/scene ${PROJECT_BINARY_DIR}/common/scene)
///   endif()
///
/// Model facts other code relies on:
/// - MuJoCo's world frame IS `base`. Units: metres, radians, seconds.
/// - Cameras "stereo_left", "stereo_right" (world-fixed) and "hand_camera"
///   (on the hand_camera body). A MuJoCo camera looks along its -z with y up;
///   the model rotates them so that the OPTICAL frame (x right, y down,
///   z forward) equals the scene's / URDF's camera frame. fovy from the scene.
///   Offscreen buffer and shadow size from the scene's render section.
/// - Joints "arm_1_joint" .. "arm_7_joint", "gripper_finger_left_joint",
///   "gripper_finger_right_joint" (coupled by an equality constraint);
///   actuators "arm_1" .. "arm_7" (position, rad) and "gripper" (position,
///   the plate gap in metres, gear 2 on the left finger).
/// - Site "gripper" = the URDF's TCP frame (use it with mj_jacSite).
/// - Books are free bodies named "book_<id>"; their main geom is "book_<id>",
///   the textured fore-edge is "book_<id>_pages" (visual only).
/// - Static geoms carry the names of scene::StaticBox ("cart_upper_shelf",
///   "stripe", "holder_back", "screen", ...), "floor", "cart_marker",
///   "holder_marker"; robot geoms are "robot/<link name>[/<n>]".

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "bookgrasp/ground_truth_t.hpp"
#include "bookgrasp/sim_state_t.hpp"
#include "common/scene/scene.h"

namespace bookgrasp::scene {

/// Who a geom belongs to, for segmentation masks: geom_owner_id() returns a
/// book id (>= 0) or one of these negative codes.
enum GeomOwner : int {
  kOwnerOther = -1,          ///< anything not listed (unnamed geoms)
  kOwnerCart = -2,           ///< cart boards and panels
  kOwnerStripe = -3,         ///< the black stripe
  kOwnerHolder = -4,         ///< book holder
  kOwnerCartMarker = -5,     ///< AprilTag on the cart
  kOwnerHolderMarker = -6,   ///< AprilTag on the holder
  kOwnerScreen = -7,         ///< the user's screen
  kOwnerFloor = -8,          ///< floor
  kOwnerRobotArm = -9,       ///< arm links and palm
  kOwnerGripperFinger = -10, ///< gripper finger plates
  kOwnerNone = -100,         ///< no geom (geom id out of range, e.g. background -1)
};

/// Name of an owner code or book id: "book_<id>", "cart", "stripe", "holder",
/// "cart_marker", "holder_marker", "screen", "floor", "robot", "gripper_finger",
/// "other", "none".
std::string geom_owner_name(int owner);

/// The arm joint names, base to wrist.
const std::vector<std::string>& arm_joint_names();

/// A scene in MuJoCo. Owns mjModel/mjData; move-only. Not thread-safe.
class SimModel {
 public:
  /// Builds the model from `scene` (URDF + scene geometry + per-seed textures,
  /// in a MuJoCo virtual file system), sets the initial arm/gripper pose and
  /// runs the scene's settle time so the books come to rest. Throws
  /// std::runtime_error with MuJoCo's message (and the MJCF line) on failure.
  static SimModel build(const Scene& scene);

  SimModel(SimModel&& other) noexcept;
  SimModel& operator=(SimModel&& other) noexcept;
  SimModel(const SimModel&) = delete;
  SimModel& operator=(const SimModel&) = delete;
  ~SimModel();

  const mjModel* model() const { return m_; }
  mjModel* model() { return m_; }
  mjData* data() { return d_; }
  const mjData* data() const { return d_; }
  /// The scene this model was built from.
  const Scene& scene() const { return *scene_; }

  /// Sets joints (by name; unknown names are ignored), gripper width (split
  /// equally on the fingers) and free-body poses (books, by name) from a
  /// SIM_STATE, zeroes velocities, moves the actuator setpoints to the given
  /// joints, then mj_forward. Throws std::invalid_argument for NaN values.
  void apply(const sim_state_t& state);
  /// The current state: 7 arm joints (names arm_joint_names()), gripper width
  /// and contact, poses of all books in base, stamped `utime`.
  sim_state_t state(int64_t utime) const;
  /// Ground truth from the current body poses (see ground_truth_t and docs/SCENE.md).
  ground_truth_t ground_truth(int64_t utime) const;

  /// Puts book `book_id` at `pose` (base) at rest and nothing else (time, arm, gripper and the other books are
  /// left as they are): a person moving a book, e.g. the librarian taking one off the holder. Throws
  /// std::invalid_argument for an unknown id or a non-finite pose.
  void move_book(int book_id, const Eigen::Isometry3d& pose);
  /// Runs `n` physics steps (with the arm's gravity compensation).
  void step(int n);
  /// Arm position setpoints (7 values, rad). Throws std::invalid_argument for a
  /// wrong count, NaN or a value outside the joint limits.
  void set_arm_setpoint(const std::vector<double>& q);
  /// Gripper plate gap setpoint (m), clamped to [0, 0.0602].
  void set_gripper_width(double w);
  /// Gripper force limit (N) of the gap actuator.
  void set_gripper_max_force(double f);

  /// Book id (>= 0) owning geom `geom_id`, or a negative GeomOwner code.
  int geom_owner_id(int geom_id) const;

  /// Plate gap: sum of the two finger joint positions (m).
  double gripper_width() const;
  /// True if a finger plate touches anything that is not the robot.
  bool gripper_contact() const;
  /// Id of the book held by the gripper (both plates touching it), or -1.
  int held_book() const;
  /// Simulation time of mjData (s) since build (the settle time is not counted).
  double sim_time() const;
  /// Joint limits of the arm (rad), lower and upper.
  std::vector<double> arm_lower_limits() const;
  std::vector<double> arm_upper_limits() const;
  /// Current arm joint positions (rad).
  std::vector<double> arm_positions() const;
  /// The generated MJCF text (for debugging: write it out and load it in `simulate`).
  const std::string& mjcf() const { return mjcf_; }

 private:
  SimModel() = default;
  void release();

  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  std::unique_ptr<Scene> scene_;
  std::string mjcf_;
  std::vector<int> arm_qpos_, arm_dof_, arm_act_;
  int finger_left_qpos_ = -1, finger_right_qpos_ = -1, gripper_act_ = -1;
  std::vector<int> finger_geoms_;
  std::vector<int> book_body_;   // by book index
  std::vector<int> owner_;       // by geom id
  std::vector<int> book_qpos_;   // qpos address of each book's free joint
  double gripper_target_ = 0;    // gap the gripper moves towards (m)
};

}  // namespace bookgrasp::scene
