#include "common/scene/mjcf_builder.h"

#include <cmath>
#include <functional>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <urdf_parser/urdf_parser.h>

#include "common/scene/textures.h"

namespace bookgrasp::scene {

namespace {

std::string num(double v) {
  std::ostringstream os;
  os << std::setprecision(10) << (std::abs(v) < 1e-15 ? 0.0 : v);
  return os.str();
}
std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }
std::string nums(const std::vector<double>& v) {
  std::string s;
  for (double x : v) s += (s.empty() ? "" : " ") + num(x);
  return s;
}
std::string quat(const Eigen::Matrix3d& r) {
  Eigen::Quaterniond q(r);
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;
  return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z());
}
std::string pose_attr(const Eigen::Isometry3d& p) {
  return "pos=\"" + vec(p.translation()) + "\" quat=\"" + quat(p.linear()) + "\"";
}
std::string rgba(const Eigen::Vector3d& c, double a = 1.0) {
  return num(c.x()) + " " + num(c.y()) + " " + num(c.z()) + " " + num(a);
}
Eigen::Isometry3d urdf_pose(const urdf::Pose& p) {
  double x, y, z, w;
  p.rotation.getQuaternion(x, y, z, w);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(w, x, y, z).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(p.position.x, p.position.y, p.position.z);
  return t;
}

std::vector<uint8_t> png(const cv::Mat& rgb) {
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> out;
  if (!cv::imencode(".png", bgr, out)) throw std::runtime_error("cannot encode a texture as PNG");
  return out;
}

// Robot geoms collide with the scene (contype 2 vs conaffinity 1) but not with each other.
constexpr const char* kRobotContact = "contype=\"2\" conaffinity=\"1\"";
// Books and static geoms collide with books and the robot.
constexpr const char* kSceneContact = "contype=\"1\" conaffinity=\"3\"";
constexpr const char* kVisualOnly = "contype=\"0\" conaffinity=\"0\"";
/// A marker plate's depth from its face back into its mount (the mounts are 15-20 mm thick).
constexpr double kMarkerPlateDepth = 0.011;

class RobotWriter {
 public:
  RobotWriter(const Scene& scene, std::ostringstream& xml) : scene_(scene), xml_(xml) {}

  void write() {
    model_ = urdf::parseURDFFile(scene_.urdf_path);
    if (!model_)
      throw std::runtime_error("cannot parse the robot URDF '" + scene_.urdf_path +
                               "' (check robot.urdf in the scene file)");
    urdf::LinkConstSharedPtr root = model_->getRoot();
    if (!root) throw std::runtime_error("URDF '" + scene_.urdf_path + "' has no root link");
    for (const char* need : {"gripper", "hand_camera", "gripper_finger_left", "gripper_finger_right"})
      if (!model_->getLink(need))
        throw std::runtime_error("URDF '" + scene_.urdf_path + "' has no link '" + std::string(need) + "'");
    link(root, Eigen::Isometry3d::Identity(), 1);
  }

  std::vector<std::pair<std::string, std::pair<double, double>>> limits;  // joint -> range

 private:
  void link(const urdf::LinkConstSharedPtr& l, const Eigen::Isometry3d& pose, int depth) {
    const std::string pad(2 * depth, ' ');
    xml_ << pad << "<body name=\"" << l->name << "\" " << pose_attr(pose) << ">\n";
    const urdf::JointConstSharedPtr j = l->parent_joint;
    const bool finger = l->name.rfind("gripper_finger", 0) == 0;
    if (j && (j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::PRISMATIC ||
              j->type == urdf::Joint::CONTINUOUS)) {
      const bool arm = j->type != urdf::Joint::PRISMATIC;
      xml_ << pad << "  <joint name=\"" << j->name << "\" type=\"" << (arm ? "hinge" : "slide") << "\" axis=\""
           << num(j->axis.x) << " " << num(j->axis.y) << " " << num(j->axis.z) << "\"";
      if (j->limits && j->type != urdf::Joint::CONTINUOUS) {
        xml_ << " limited=\"true\" range=\"" << num(j->limits->lower) << " " << num(j->limits->upper) << "\"";
        limits.push_back({j->name, {j->limits->lower, j->limits->upper}});
      }
      if (arm)
        xml_ << " armature=\"" << num(scene_.physics.arm_armature) << "\" damping=\""
             << num(arm_damping(j->name)) << "\"";
      else
        xml_ << " armature=\"0.01\" damping=\"" << num(scene_.physics.gripper_damping) << "\"";
      xml_ << "/>\n";
    }
    if (l->inertial && l->inertial->mass > 0) {
      const auto& in = *l->inertial;
      // MuJoCo takes fullinertia without an orientation: rotate the tensor into the body frame.
      const Eigen::Isometry3d o = urdf_pose(in.origin);
      Eigen::Matrix3d inertia;
      inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
      inertia = o.linear() * inertia * o.linear().transpose();
      xml_ << pad << "  <inertial pos=\"" << vec(o.translation()) << "\" mass=\"" << num(in.mass)
           << "\" fullinertia=\"" << num(inertia(0, 0)) << " " << num(inertia(1, 1)) << " " << num(inertia(2, 2))
           << " " << num(inertia(0, 1)) << " " << num(inertia(0, 2)) << " " << num(inertia(1, 2)) << "\"/>\n";
    }
    // Geoms from the collision elements, coloured like the matching visual.
    Eigen::Vector3d colour(0.6, 0.6, 0.62);
    if (l->visual && l->visual->material)
      colour = {l->visual->material->color.r, l->visual->material->color.g, l->visual->material->color.b};
    int k = 0;
    for (const auto& c : l->collision_array) {
      if (!c || !c->geometry) continue;
      std::string name = "robot/" + l->name + (k > 0 ? "/" + std::to_string(k) : "");
      ++k;
      Eigen::Isometry3d gp = urdf_pose(c->origin);
      std::string type, size;
      switch (c->geometry->type) {
        case urdf::Geometry::SPHERE:
          type = "sphere";
          size = num(static_cast<const urdf::Sphere&>(*c->geometry).radius);
          break;
        case urdf::Geometry::BOX: {
          const auto& b = static_cast<const urdf::Box&>(*c->geometry);
          type = "box";
          size = num(b.dim.x / 2) + " " + num(b.dim.y / 2) + " " + num(b.dim.z / 2);
          break;
        }
        case urdf::Geometry::CYLINDER: {
          const auto& cy = static_cast<const urdf::Cylinder&>(*c->geometry);
          type = "cylinder";
          size = num(cy.radius) + " " + num(cy.length / 2);
          break;
        }
        default:
          throw std::runtime_error("URDF '" + scene_.urdf_path + "' link '" + l->name +
                                   "': only sphere, box and cylinder collision shapes are supported");
      }
      xml_ << pad << "  <geom name=\"" << name << "\" type=\"" << type << "\" size=\"" << size << "\" "
           << pose_attr(gp) << " rgba=\"" << rgba(colour) << "\" " << kRobotContact;
      if (finger)
        xml_ << " condim=\"4\" friction=\"" << num(scene_.physics.finger_friction) << " 0.02 0.0001\" solref=\""
             << nums(scene_.physics.finger_solref) << "\" solimp=\"" << nums(scene_.physics.finger_solimp)
             << "\" solmix=\"1000\"";  // the contact takes the plate's solref/solimp, not a mix with the book's
      xml_ << " group=\"2\"/>\n";
    }
    if (l->name == "gripper") xml_ << pad << "  <site name=\"gripper\" size=\"0.005\" rgba=\"1 0 0 0\"/>\n";
    if (l->name == "hand_camera")
      xml_ << pad << "  <camera name=\"hand_camera\" pos=\"0 0 0\" quat=\"0 1 0 0\" fovy=\""
           << num(scene_.hand_camera.fovy_rad * 180.0 / M_PI) << "\"/>\n";
    for (const auto& cj : l->child_joints) {
      urdf::LinkConstSharedPtr child = model_->getLink(cj->child_link_name);
      link(child, urdf_pose(cj->parent_to_joint_origin_transform), depth + 1);
    }
    xml_ << pad << "</body>\n";
  }

  double arm_damping(const std::string& joint) const {
    for (int i = 0; i < 7; ++i)
      if (joint == "arm_" + std::to_string(i + 1) + "_joint") return scene_.physics.arm_damping[i];
    return scene_.physics.arm_damping.back();
  }

  const Scene& scene_;
  std::ostringstream& xml_;
  urdf::ModelInterfaceSharedPtr model_;
};

}  // namespace

MjcfDocument build_mjcf(const Scene& s) {
  MjcfDocument doc;
  std::ostringstream x;
  const Physics& ph = s.physics;
  x << "<mujoco model=\"bookgrasp_" << s.name << "_" << s.seed << "\">\n";
  x << "  <compiler angle=\"radian\" inertiafromgeom=\"auto\"/>\n";
  x << "  <option timestep=\"" << num(ph.timestep_s) << "\" cone=\"elliptic\" impratio=\"" << num(ph.impratio)
    << "\" integrator=\"implicit\" noslip_iterations=\"" << ph.noslip_iterations << "\"/>\n";
  // njmax sizes dense njmax x njmax buffers in mjData (8000 would memset 0.5 GB): ~40 contacts need ~200 rows.
  x << "  <size nconmax=\"600\" njmax=\"2000\"/>\n";
  // Fixed statistic: znear/zfar and shadow clipping scale with the extent; keep them independent of the books.
  {
    const Eigen::Vector3d c = s.cart_pose * Eigen::Vector3d(0, 0, 0);
    x << "  <statistic extent=\"2\" center=\"" << vec(Eigen::Vector3d(c.x() / 2, c.y() / 2, 0.2)) << "\"/>\n";
  }
  x << "  <visual>\n"
    << "    <global offwidth=\"" << s.render.offscreen_width << "\" offheight=\"" << s.render.offscreen_height
    << "\"/>\n"
    << "    <quality shadowsize=\"" << s.lighting.shadow_size << "\" offsamples=\"" << s.render.offsamples << "\"/>\n"
    << "    <headlight ambient=\"" << vec(Eigen::Vector3d::Constant(s.lighting.ambient))
    << "\" diffuse=\"0.08 0.08 0.08\" specular=\"0 0 0\"/>\n"
    << "    <map znear=\"0.005\" zfar=\"10\" shadowscale=\"0.8\"/>\n"
    << "  </visual>\n";

  // ---- assets ----
  x << "  <asset>\n";
  x << "    <texture name=\"floor_tex\" type=\"2d\" builtin=\"checker\" rgb1=\"0.52 0.50 0.46\" rgb2=\"0.47 0.45 0.42\" "
       "width=\"512\" height=\"512\"/>\n";
  x << "    <material name=\"floor_mat\" texture=\"floor_tex\" texrepeat=\"3 3\" texuniform=\"true\" "
       "specular=\"0.1\"/>\n";
  x << "    <material name=\"wall_mat\" rgba=\"0.86 0.84 0.78 1\" specular=\"0\"/>\n";
  for (const Marker* mk : {&s.cart_marker, &s.holder_marker}) {
    const std::string file = mk->name + ".png";
    doc.files.push_back({file, png(apriltag_texture(mk->id, 32))});
    x << "    <texture name=\"" << mk->name << "_tex\" type=\"2d\" file=\"" << file << "\"/>\n";
    x << "    <material name=\"" << mk->name << "_mat\" texture=\"" << mk->name
      << "_tex\" texrepeat=\"1 1\" specular=\"0\" shininess=\"0\"/>\n";
  }
  for (const Book& b : s.books) {
    const std::string n = "book_" + std::to_string(b.id);
    doc.files.push_back({n + "_pages.png", png(page_edge_texture(b, s.render))});
    x << "    <texture name=\"" << n << "_pages_tex\" type=\"2d\" file=\"" << n << "_pages.png\"/>\n";
    x << "    <material name=\"" << n << "_pages_mat\" texture=\"" << n
      << "_pages_tex\" texrepeat=\"1 1\" specular=\"0.05\" shininess=\"0.1\"/>\n";
    x << "    <material name=\"" << n << "_cover_mat\" rgba=\"" << rgba(b.cover_rgb)
      << "\" specular=\"0.25\" shininess=\"0.3\"/>\n";
  }
  x << "  </asset>\n";

  // ---- world ----
  x << "  <worldbody>\n";
  const Eigen::Vector3d centre = s.cart_pose * Eigen::Vector3d(s.shelf_depth_m / 2, 0, 0);
  const Eigen::Vector3d& dir = s.lighting.direction;
  // Key light: a spot light 3 m away, narrow enough that its shadow map covers the cart finely
  // (a directional light's shadow map spans the whole model and shows acne on thin books).
  x << "    <light name=\"key\" directional=\"false\" castshadow=\"" << (s.lighting.shadows ? "true" : "false")
    << "\" pos=\"" << vec(centre - 3.0 * dir) << "\" dir=\"" << vec(dir) << "\" diffuse=\""
    << vec(Eigen::Vector3d::Constant(s.lighting.intensity))
    << "\" specular=\"0.15 0.15 0.15\" cutoff=\"40\" exponent=\"1\" attenuation=\"1 0 0\"/>\n";
  x << "    <geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\" pos=\"0 0 " << num(s.floor_z)
    << "\" material=\"floor_mat\" " << kSceneContact << " friction=\"" << num(ph.shelf_friction) << " 0.005 0.0001\"/>\n";
  // Room walls (visual only): behind the cart and to the right.
  {
    const Eigen::Isometry3d wall_back =
        s.cart_pose * Eigen::Translation3d(s.shelf_depth_m + 1.2, 0, s.floor_z - s.cart_pose.translation().z() + 1.5);
    x << "    <geom name=\"room_wall_back\" type=\"box\" size=\"0.05 4 1.5\" " << pose_attr(wall_back)
      << " material=\"wall_mat\" " << kVisualOnly << "/>\n";
    const Eigen::Isometry3d wall_right =
        s.cart_pose * Eigen::Translation3d(0.2, -s.shelf_width_m / 2 - 1.3, s.floor_z - s.cart_pose.translation().z() + 1.5);
    x << "    <geom name=\"room_wall_right\" type=\"box\" size=\"3 0.05 1.5\" " << pose_attr(wall_right)
      << " material=\"wall_mat\" " << kVisualOnly << "/>\n";
  }
  for (const StaticBox& b : s.boxes) {
    x << "    <geom name=\"" << b.name << "\" type=\"box\" size=\"" << vec(b.half_size) << "\" " << pose_attr(b.pose)
      << " rgba=\"" << rgba(b.rgb) << "\" " << kSceneContact << " friction=\"" << num(ph.shelf_friction)
      << " 0.005 0.0001\"/>\n";
  }
  for (const Marker* mk : {&s.cart_marker, &s.holder_marker}) {
    // Plate with the white border (10 cells for 8 black cells): its face 1 mm proud of the mount, its back
    // kMarkerPlateDepth behind that face, inside the mount (visual only). A 1 mm plate shadowed itself: the
    // shadow map's depth of its back face was within a texel's depth slope of the face, and the white cells
    // rendered as a 1-px dark checker that AprilTag misses (far_cart seed 5250's cart tag).
    const double half = mk->size_m * 10.0 / 8.0 / 2.0;
    x << "    <geom name=\"" << mk->name << "\" type=\"box\" size=\"" << num(half) << " " << num(half) << " "
      << num(kMarkerPlateDepth / 2) << "\" " << pose_attr(mk->pose * Eigen::Translation3d(0, 0, -kMarkerPlateDepth / 2))
      << " material=\"" << mk->name << "_mat\" " << kVisualOnly << "/>\n";
  }
  // Stereo cameras: MuJoCo camera axes = optical (x right, y down, z forward) turned by pi about x.
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  for (const CameraSpec* c : {&s.stereo_left, &s.stereo_right}) {
    Eigen::Isometry3d p = c->pose;
    p.linear() = c->pose.linear() * flip;
    x << "    <camera name=\"" << c->name << "\" mode=\"fixed\" " << pose_attr(p) << " fovy=\""
      << num(c->fovy_rad * 180.0 / M_PI) << "\"/>\n";
  }
  // Books.
  for (const Book& b : s.books) {
    const std::string n = "book_" + std::to_string(b.id);
    const double m = b.mass_kg, w = b.width_m, h = b.height_m, d = b.depth_m;
    x << "    <body name=\"" << n << "\" " << pose_attr(b.pose) << ">\n";
    x << "      <freejoint name=\"" << n << "\"/>\n";
    x << "      <inertial pos=\"0 0 0\" mass=\"" << num(m) << "\" diaginertia=\"" << num(m / 12 * (w * w + h * h)) << " "
      << num(m / 12 * (d * d + h * h)) << " " << num(m / 12 * (d * d + w * w)) << "\"/>\n";
    // Main box 1 mm short at the front, where the textured fore-edge plate sits (no z-fighting).
    x << "      <geom name=\"" << n << "\" type=\"box\" size=\"" << num(d / 2 - 0.0005) << " " << num(w / 2) << " "
      << num(h / 2) << "\" pos=\"0.0005 0 0\" material=\"" << n << "_cover_mat\" " << kSceneContact
      << " friction=\"" << num(ph.book_friction) << " 0.005 0.0001\"/>\n";
    // Fore-edge plate: local z towards the robot (-x), local x = right (-y), local y = up (+z).
    Eigen::Matrix3d r;
    r.col(0) = -Eigen::Vector3d::UnitY();
    r.col(1) = Eigen::Vector3d::UnitZ();
    r.col(2) = -Eigen::Vector3d::UnitX();
    Eigen::Isometry3d pp = Eigen::Isometry3d::Identity();
    pp.linear() = r;
    pp.translation() = Eigen::Vector3d(-d / 2 + 0.0005, 0, 0);
    x << "      <geom name=\"" << n << "_pages\" type=\"box\" size=\"" << num(w / 2) << " " << num(h / 2)
      << " 0.0005\" " << pose_attr(pp) << " material=\"" << n << "_pages_mat\" " << kVisualOnly << "/>\n";
    x << "    </body>\n";
  }
  // Robot.
  RobotWriter robot(s, x);
  robot.write();
  x << "  </worldbody>\n";

  x << "  <equality>\n"
    << "    <joint name=\"finger_coupling\" joint1=\"gripper_finger_right_joint\" joint2=\"gripper_finger_left_joint\" "
       "polycoef=\"0 1 0 0 0\" solref=\""
    << nums(ph.gripper_coupling_solref) << "\"/>\n"
    << "  </equality>\n";
  x << "  <actuator>\n";
  for (const auto& [joint, range] : robot.limits) {
    for (int i = 0; i < 7; ++i) {
      if (joint != "arm_" + std::to_string(i + 1) + "_joint") continue;
      x << "    <position name=\"arm_" << i + 1 << "\" joint=\"" << joint << "\" kp=\"" << num(ph.arm_kp[i])
        << "\" ctrllimited=\"true\" ctrlrange=\"" << num(range.first) << " " << num(range.second) << "\"/>\n";
    }
  }
  x << "    <position name=\"gripper\" joint=\"gripper_finger_left_joint\" gear=\"2\" kp=\"" << num(ph.gripper_kp)
    << "\" ctrllimited=\"true\" ctrlrange=\"-0.002 0.0602\" forcelimited=\"true\" forcerange=\""
    << num(-ph.gripper_max_force_n) << " " << num(ph.gripper_max_force_n) << "\"/>\n";
  x << "  </actuator>\n";
  x << "</mujoco>\n";
  doc.xml = x.str();
  return doc;
}

}  // namespace bookgrasp::scene
