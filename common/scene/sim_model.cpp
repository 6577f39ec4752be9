#include "common/scene/sim_model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "common/pose_conversion.h"
#include "common/scene/mjcf_builder.h"

namespace bookgrasp::scene {

namespace {

constexpr double kGripperMax = 0.0602;
constexpr double kGripperSpeed = 0.082;  // plate gap change per second (2 x 0.041 m/s per finger)

struct VfsDeleter {
  void operator()(mjVFS* v) const {
    mj_deleteVFS(v);
    delete v;
  }
};

void add_file(mjVFS* vfs, const std::string& name, const void* data, size_t size) {
  if (mj_makeEmptyFileVFS(vfs, name.c_str(), static_cast<int>(size)) != 0)
    throw std::runtime_error("MuJoCo VFS: cannot add '" + name + "' (full or duplicate name)");
  const int i = mj_findFileVFS(vfs, name.c_str());
  std::memcpy(vfs->filedata[i], data, size);
}

Eigen::Isometry3d body_pose(const mjData* d, int body) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const mjtNum* q = d->xquat + 4 * body;
  t.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
  t.translation() = Eigen::Vector3d(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
  return t;
}

int owner_of_name(const std::string& n) {
  auto starts = [&](const char* p) { return n.rfind(p, 0) == 0; };
  if (starts("book_")) {
    size_t end = 5;
    while (end < n.size() && std::isdigit(static_cast<unsigned char>(n[end]))) ++end;
    if (end > 5) return std::stoi(n.substr(5, end - 5));
  }
  if (n == "cart_marker") return kOwnerCartMarker;
  if (n == "holder_marker") return kOwnerHolderMarker;
  if (starts("cart")) return kOwnerCart;
  if (n == "stripe") return kOwnerStripe;
  if (starts("holder")) return kOwnerHolder;
  if (n == "screen") return kOwnerScreen;
  if (n == "floor") return kOwnerFloor;
  if (starts("robot/gripper_finger")) return kOwnerGripperFinger;
  if (starts("robot/")) return kOwnerRobotArm;
  return kOwnerOther;
}

void check_finite(double v, const std::string& what) {
  if (!std::isfinite(v)) throw std::invalid_argument(what + " is not a finite number");
}

}  // namespace

std::string geom_owner_name(int owner) {
  if (owner >= 0) return "book_" + std::to_string(owner);
  switch (owner) {
    case kOwnerCart: return "cart";
    case kOwnerStripe: return "stripe";
    case kOwnerHolder: return "holder";
    case kOwnerCartMarker: return "cart_marker";
    case kOwnerHolderMarker: return "holder_marker";
    case kOwnerScreen: return "screen";
    case kOwnerFloor: return "floor";
    case kOwnerRobotArm: return "robot";
    case kOwnerGripperFinger: return "gripper_finger";
    case kOwnerNone: return "none";
    default: return "other";
  }
}

const std::vector<std::string>& arm_joint_names() {
  static const std::vector<std::string> names = {"arm_1_joint", "arm_2_joint", "arm_3_joint", "arm_4_joint",
                                                 "arm_5_joint", "arm_6_joint", "arm_7_joint"};
  return names;
}

SimModel SimModel::build(const Scene& scene) {
  const MjcfDocument doc = build_mjcf(scene);
  std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
  mj_defaultVFS(vfs.get());
  add_file(vfs.get(), "scene.xml", doc.xml.data(), doc.xml.size());
  for (const auto& [name, bytes] : doc.files) add_file(vfs.get(), name, bytes.data(), bytes.size());
  char err[1000] = {0};
  mjModel* m = mj_loadXML("scene.xml", vfs.get(), err, sizeof(err));
  if (!m)
    throw std::runtime_error("MuJoCo rejected the generated model of scene '" + scene.source + "' seed " +
                             std::to_string(scene.seed) + ": " + err);
  SimModel sm;
  sm.m_ = m;
  sm.d_ = mj_makeData(m);
  sm.scene_ = std::make_unique<Scene>(scene);
  sm.mjcf_ = doc.xml;

  for (const std::string& j : arm_joint_names()) {
    const int id = mj_name2id(m, mjOBJ_JOINT, j.c_str());
    if (id < 0) throw std::runtime_error("robot model has no joint '" + j + "' (check the URDF)");
    sm.arm_qpos_.push_back(m->jnt_qposadr[id]);
    sm.arm_dof_.push_back(m->jnt_dofadr[id]);
    const std::string act = "arm_" + j.substr(4, 1);
    const int a = mj_name2id(m, mjOBJ_ACTUATOR, act.c_str());
    if (a < 0) throw std::runtime_error("robot joint '" + j + "' has no limits in the URDF (no actuator made)");
    sm.arm_act_.push_back(a);
  }
  sm.finger_left_qpos_ = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "gripper_finger_left_joint")];
  sm.finger_right_qpos_ = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "gripper_finger_right_joint")];
  sm.gripper_act_ = mj_name2id(m, mjOBJ_ACTUATOR, "gripper");
  sm.owner_.resize(m->ngeom);
  for (int g = 0; g < m->ngeom; ++g) {
    const char* n = mj_id2name(m, mjOBJ_GEOM, g);
    sm.owner_[g] = n ? owner_of_name(n) : kOwnerOther;
    if (sm.owner_[g] == kOwnerGripperFinger) sm.finger_geoms_.push_back(g);
  }
  for (const Book& b : scene.books) {
    const std::string n = "book_" + std::to_string(b.id);
    const int body = mj_name2id(m, mjOBJ_BODY, n.c_str());
    sm.book_body_.push_back(body);
    sm.book_qpos_.push_back(m->jnt_qposadr[m->body_jntadr[body]]);
  }

  // Initial pose, then let the books settle.
  for (int i = 0; i < 7; ++i) {
    sm.d_->qpos[sm.arm_qpos_[i]] = scene.initial_joints[i];
    sm.d_->ctrl[sm.arm_act_[i]] = scene.initial_joints[i];
  }
  const double w = std::clamp(scene.initial_gripper_width_m, 0.0, kGripperMax);
  sm.d_->qpos[sm.finger_left_qpos_] = w / 2;
  sm.d_->qpos[sm.finger_right_qpos_] = w / 2;
  sm.d_->ctrl[sm.gripper_act_] = w;
  sm.gripper_target_ = w;
  mj_forward(m, sm.d_);
  sm.step(static_cast<int>(std::lround(scene.physics.settle_time_s / m->opt.timestep)));
  sm.d_->time = 0;
  return sm;
}

SimModel::SimModel(SimModel&& o) noexcept { *this = std::move(o); }

SimModel& SimModel::operator=(SimModel&& o) noexcept {
  if (this == &o) return *this;
  release();
  m_ = o.m_;
  d_ = o.d_;
  o.m_ = nullptr;
  o.d_ = nullptr;
  scene_ = std::move(o.scene_);
  mjcf_ = std::move(o.mjcf_);
  arm_qpos_ = std::move(o.arm_qpos_);
  arm_dof_ = std::move(o.arm_dof_);
  arm_act_ = std::move(o.arm_act_);
  finger_left_qpos_ = o.finger_left_qpos_;
  finger_right_qpos_ = o.finger_right_qpos_;
  gripper_act_ = o.gripper_act_;
  gripper_target_ = o.gripper_target_;
  finger_geoms_ = std::move(o.finger_geoms_);
  book_body_ = std::move(o.book_body_);
  owner_ = std::move(o.owner_);
  book_qpos_ = std::move(o.book_qpos_);
  return *this;
}

SimModel::~SimModel() { release(); }

void SimModel::release() {
  if (d_) mj_deleteData(d_);
  if (m_) mj_deleteModel(m_);
  d_ = nullptr;
  m_ = nullptr;
}

void SimModel::step(int n) {
  const double max_delta = kGripperSpeed * m_->opt.timestep;
  for (int k = 0; k < n; ++k) {
    // Gravity and Coriolis compensation of the arm (the real arm's controller does this), from the
    // bias forces of the previous step; the gripper setpoint moves at the PG70's finger speed.
    for (int dof : arm_dof_) d_->qfrc_applied[dof] = d_->qfrc_bias[dof];
    double& c = d_->ctrl[gripper_act_];
    c += std::clamp(gripper_target_ - c, -max_delta, max_delta);
    mj_step(m_, d_);
  }
}

std::vector<double> SimModel::arm_lower_limits() const {
  std::vector<double> v;
  for (int a : arm_act_) v.push_back(m_->actuator_ctrlrange[2 * a]);
  return v;
}
std::vector<double> SimModel::arm_upper_limits() const {
  std::vector<double> v;
  for (int a : arm_act_) v.push_back(m_->actuator_ctrlrange[2 * a + 1]);
  return v;
}
std::vector<double> SimModel::arm_positions() const {
  std::vector<double> v;
  for (int q : arm_qpos_) v.push_back(d_->qpos[q]);
  return v;
}

void SimModel::set_arm_setpoint(const std::vector<double>& q) {
  if (q.size() != arm_act_.size())
    throw std::invalid_argument("arm setpoint has " + std::to_string(q.size()) + " joints, the arm has " +
                                std::to_string(arm_act_.size()));
  const auto lo = arm_lower_limits(), hi = arm_upper_limits();
  for (size_t i = 0; i < q.size(); ++i) {
    check_finite(q[i], "arm setpoint joint " + std::to_string(i + 1));
    if (q[i] < lo[i] || q[i] > hi[i])
      throw std::invalid_argument("arm setpoint joint " + std::to_string(i + 1) + " = " + std::to_string(q[i]) +
                                  " rad is outside the limits [" + std::to_string(lo[i]) + ", " +
                                  std::to_string(hi[i]) + "]");
  }
  for (size_t i = 0; i < q.size(); ++i) d_->ctrl[arm_act_[i]] = q[i];
}

void SimModel::move_book(int book_id, const Eigen::Isometry3d& pose) {
  if (!pose.matrix().allFinite()) throw std::invalid_argument("move_book: the pose is not finite");
  for (size_t k = 0; k < scene_->books.size(); ++k) {
    if (scene_->books[k].id != book_id) continue;
    mjtNum* q = d_->qpos + book_qpos_[k];
    const Eigen::Quaterniond qu(pose.linear());
    for (int j = 0; j < 3; ++j) q[j] = pose.translation()[j];
    q[3] = qu.w();
    q[4] = qu.x();
    q[5] = qu.y();
    q[6] = qu.z();
    const int dof = m_->jnt_dofadr[m_->body_jntadr[book_body_[k]]];
    std::fill(d_->qvel + dof, d_->qvel + dof + 6, 0.0);
    mj_forward(m_, d_);
    return;
  }
  throw std::invalid_argument("move_book: no book " + std::to_string(book_id) + " in the scene");
}

void SimModel::set_gripper_width(double w) {
  check_finite(w, "gripper width");
  gripper_target_ = std::clamp(w, 0.0, kGripperMax);
}

void SimModel::set_gripper_max_force(double f) {
  check_finite(f, "gripper force");
  if (f <= 0) throw std::invalid_argument("gripper force limit must be > 0 N");
  m_->actuator_forcerange[2 * gripper_act_] = -f;
  m_->actuator_forcerange[2 * gripper_act_ + 1] = f;
}

double SimModel::gripper_width() const { return d_->qpos[finger_left_qpos_] + d_->qpos[finger_right_qpos_]; }

bool SimModel::gripper_contact() const {
  for (int i = 0; i < d_->ncon; ++i) {
    const mjContact& c = d_->contact[i];
    const int o1 = owner_[c.geom1], o2 = owner_[c.geom2];
    const bool f1 = o1 == kOwnerGripperFinger, f2 = o2 == kOwnerGripperFinger;
    if ((f1 && o2 != kOwnerGripperFinger && o2 != kOwnerRobotArm) ||
        (f2 && o1 != kOwnerGripperFinger && o1 != kOwnerRobotArm))
      return true;
  }
  return false;
}

int SimModel::held_book() const {
  if (finger_geoms_.size() < 2) return -1;
  // book id -> bitmask of fingers touching it
  std::vector<int> mask(scene_->books.size() + 1, 0);
  for (int i = 0; i < d_->ncon; ++i) {
    const mjContact& c = d_->contact[i];
    for (int side = 0; side < 2; ++side) {
      const int g = side ? c.geom2 : c.geom1, other = side ? c.geom1 : c.geom2;
      if (owner_[g] != kOwnerGripperFinger || owner_[other] < 0) continue;
      const int fi = g == finger_geoms_[0] ? 1 : 2;
      const int book = owner_[other];
      for (size_t b = 0; b < scene_->books.size(); ++b)
        if (scene_->books[b].id == book) mask[b] |= fi;
    }
  }
  for (size_t b = 0; b < scene_->books.size(); ++b)
    if (mask[b] == 3) return scene_->books[b].id;
  return -1;
}

double SimModel::sim_time() const { return d_->time; }

int SimModel::geom_owner_id(int geom_id) const {
  if (geom_id < 0 || geom_id >= static_cast<int>(owner_.size())) return kOwnerNone;
  return owner_[geom_id];
}

void SimModel::apply(const sim_state_t& st) {
  for (int i = 0; i < st.num_joints && i < static_cast<int>(st.joint_names.size()) &&
                  i < static_cast<int>(st.joint_positions.size());
       ++i)
    check_finite(st.joint_positions[i], "SIM_STATE joint '" + st.joint_names[i] + "'");
  check_finite(st.gripper_width_m, "SIM_STATE gripper width");
  for (const body_pose_t& b : st.bodies) {
    for (double v : b.position) check_finite(v, "SIM_STATE body '" + b.name + "' position");
    for (double v : b.orientation) check_finite(v, "SIM_STATE body '" + b.name + "' orientation");
  }
  const auto& names = arm_joint_names();
  for (int i = 0; i < st.num_joints && i < static_cast<int>(st.joint_names.size()) &&
                  i < static_cast<int>(st.joint_positions.size());
       ++i) {
    for (size_t k = 0; k < names.size(); ++k)
      if (st.joint_names[i] == names[k]) {
        d_->qpos[arm_qpos_[k]] = st.joint_positions[i];
        d_->ctrl[arm_act_[k]] = st.joint_positions[i];
      }
  }
  const double w = std::clamp(st.gripper_width_m, 0.0, kGripperMax);
  d_->qpos[finger_left_qpos_] = w / 2;
  d_->qpos[finger_right_qpos_] = w / 2;
  d_->ctrl[gripper_act_] = w;
  gripper_target_ = w;
  for (const body_pose_t& b : st.bodies) {
    for (size_t k = 0; k < scene_->books.size(); ++k) {
      if (b.name != "book_" + std::to_string(scene_->books[k].id)) continue;
      mjtNum* q = d_->qpos + book_qpos_[k];
      Eigen::Quaterniond qu(b.orientation[0], b.orientation[1], b.orientation[2], b.orientation[3]);
      if (qu.norm() < 1e-6) throw std::invalid_argument("SIM_STATE body '" + b.name + "' has a zero quaternion");
      qu.normalize();
      for (int j = 0; j < 3; ++j) q[j] = b.position[j];
      q[3] = qu.w();
      q[4] = qu.x();
      q[5] = qu.y();
      q[6] = qu.z();
    }
  }
  std::fill(d_->qvel, d_->qvel + m_->nv, 0.0);
  d_->time = 0;
  mj_forward(m_, d_);
}

sim_state_t SimModel::state(int64_t utime) const {
  sim_state_t s;
  s.utime = utime;
  s.scene = scene_->name;
  s.seed = static_cast<int64_t>(scene_->seed);
  const auto& names = arm_joint_names();
  s.num_joints = static_cast<int32_t>(names.size());
  s.joint_names = names;
  for (size_t i = 0; i < names.size(); ++i) {
    s.joint_positions.push_back(d_->qpos[arm_qpos_[i]]);
    s.joint_velocities.push_back(d_->qvel[arm_dof_[i]]);
  }
  s.gripper_width_m = gripper_width();
  s.gripper_contact = gripper_contact();
  for (size_t k = 0; k < scene_->books.size(); ++k) {
    body_pose_t b;
    b.utime = utime;
    b.name = "book_" + std::to_string(scene_->books[k].id);
    const int body = book_body_[k];
    for (int j = 0; j < 3; ++j) b.position[j] = d_->xpos[3 * body + j];
    for (int j = 0; j < 4; ++j) b.orientation[j] = d_->xquat[4 * body + j];
    s.bodies.push_back(b);
  }
  s.num_bodies = static_cast<int32_t>(s.bodies.size());
  return s;
}

ground_truth_t SimModel::ground_truth(int64_t utime) const {
  const Scene& sc = *scene_;
  ground_truth_t g;
  g.utime = utime;
  g.scene = sc.name;
  g.seed = static_cast<int64_t>(sc.seed);
  g.cart = isometry_to_pose(sc.cart_pose, "base", "cart", utime);
  g.holder = isometry_to_pose(sc.holder_pose, "base", "holder", utime);
  g.cart_marker = isometry_to_pose(sc.cart_marker.pose, "base", "cart_marker", utime);
  g.holder_marker = isometry_to_pose(sc.holder_marker.pose, "base", "holder_marker", utime);
  const int held = held_book();
  int rightmost = -1;
  double rightmost_y = 1e9;
  const Eigen::Isometry3d cart_inv = sc.cart_pose.inverse();
  for (size_t k = 0; k < sc.books.size(); ++k) {
    const Book& b = sc.books[k];
    const Eigen::Isometry3d pose = body_pose(d_, book_body_[k]);
    book_truth_t t;
    t.utime = utime;
    t.id = b.id;
    t.name = "book_" + std::to_string(b.id);
    t.place = b.id == held ? "gripper" : classify_place(sc, pose.translation());
    t.rightmost = false;
    t.portrait = b.portrait;
    t.width_m = b.width_m;
    t.height_m = b.height_m;
    t.depth_m = b.depth_m;
    const auto corners = book_corners(pose, b.width_m, b.height_m, b.depth_m);
    for (int i = 0; i < 8; ++i)
      for (int j = 0; j < 3; ++j) t.corners_base[i][j] = corners[i][j];
    for (int j = 0; j < 3; ++j) t.p1_base[j] = corners[kP1CornerIndex][j];
    t.pose = isometry_to_pose(pose, "base", t.name, utime);
    if (t.place == "upper_shelf") {
      const double y = (cart_inv * corners[kP1CornerIndex]).y();
      if (y < rightmost_y) {
        rightmost_y = y;
        rightmost = static_cast<int>(k);
      }
    }
    g.books.push_back(t);
  }
  g.num_books = static_cast<int32_t>(g.books.size());
  Eigen::Vector3d end;
  if (rightmost >= 0) {
    g.books[rightmost].rightmost = true;
    const Book& b = sc.books[rightmost];
    end = stripe_end(sc, body_pose(d_, book_body_[rightmost]), b.width_m, b.height_m, b.depth_m);
  } else {
    // Empty upper shelf: the stripe is visible to its left end.
    end = sc.cart_pose * Eigen::Vector3d(sc.shelf_depth_m, sc.shelf_width_m / 2, sc.stripe_height_m);
  }
  for (int j = 0; j < 3; ++j) g.stripe_end_base[j] = end[j];
  return g;
}

}  // namespace bookgrasp::scene
