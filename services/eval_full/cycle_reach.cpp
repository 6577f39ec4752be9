#include "services/eval_full/cycle_reach.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace bookgrasp {

namespace {

/// Position of `link`'s origin in base at the zero posture.
Eigen::Vector3d link_origin(const ArmKinematics& kin, const std::string& link) {
  return kin.frame_pose(Eigen::VectorXd::Zero(kin.num_joints()), link).translation();
}

}  // namespace

double elbow_bend_for_tcp(const ArmKinematics& kin, const Eigen::Isometry3d& tcp) {
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(kin.num_joints());
  const Eigen::Vector3d shoulder = link_origin(kin, "arm_2_link");
  const Eigen::Vector3d elbow = link_origin(kin, "arm_4_link");
  const Eigen::Vector3d wrist = link_origin(kin, "arm_6_link");
  const double a = (elbow - shoulder).norm(), b = (wrist - elbow).norm();
  // The wrist centre is fixed in the TCP frame (arm_7 turns about an axis through it).
  const Eigen::Vector3d wrist_in_tcp = kin.tip_pose(q0).inverse() * wrist;
  const double d = (tcp * wrist_in_tcp - shoulder).norm();
  const double c = (d * d - a * a - b * b) / (2 * a * b);
  if (c > 1 || c < -1) return std::numeric_limits<double>::quiet_NaN();
  return std::acos(c);
}

Eigen::Isometry3d true_grasp_frame(const scene::Scene& scene) {
  const Eigen::Matrix3d c = scene.cart_pose.linear();
  Eigen::Isometry3d g = Eigen::Isometry3d::Identity();
  g.linear().col(0) = c.col(2);   // X up
  g.linear().col(1) = -c.col(1);  // Y right
  g.linear().col(2) = c.col(0);   // Z into the shelf
  g.translation() = scene.cart_pose.translation();
  return g;
}

std::vector<StageReach> cycle_reach(const scene::Scene& scene, const CycleGeometry& g, const InverseKinematics& ik,
                                    const Eigen::VectorXd& seed_q, size_t book_index) {
  if (scene.books.empty()) throw std::runtime_error("cycle_reach: the scene has no book on the upper shelf");
  if (book_index >= scene.books.size())
    throw std::runtime_error("cycle_reach: the scene has " + std::to_string(scene.books.size()) +
                             " books on the upper shelf, no book " + std::to_string(book_index));
  const scene::Book& book = scene.books[book_index];  // 0 = right-most at generation
  double lower_right_y = g.lower_first_right_y;
  for (size_t i = 0; i < book_index; ++i) lower_right_y = next_lower_right_y(lower_right_y, scene.books[i].width_m, g);
  const Eigen::Isometry3d grasp = true_grasp_frame(scene);
  const Eigen::Isometry3d to_grasp = grasp.inverse();
  const Eigen::Vector3d p1 =
      to_grasp * scene::book_corners(book.pose, book.width_m, book.height_m, book.depth_m)[scene::kP1CornerIndex];
  const Eigen::Vector3d se = to_grasp * scene::stripe_end(scene, book.pose, book.width_m, book.height_m, book.depth_m);

  std::vector<std::pair<std::string, Eigen::Isometry3d>> poses;
  const Eigen::Isometry3d a = stripe_start_pose(grasp, g);
  poses.emplace_back("stripe_start", a);
  poses.emplace_back("stripe_end",
                     pose_in_grasp_frame(grasp, Eigen::Vector3d(g.stripe_start.x(), se.y(), g.stripe_start.z())));
  poses.emplace_back("bwh_start", bwh_start_pose(grasp, p1, g));
  const Eigen::Isometry3d gp = pose_in_grasp_frame(grasp, p1);
  poses.emplace_back("pre_grasp", pre_grasp_pose(gp, p1.z(), g));
  const Eigen::Isometry3d gr = grasp_pose(gp, g);
  poses.emplace_back("grasp", gr);
  const double h = tcp_height_on_book(p1, g);
  const auto extract = extract_moves(gr, grasp, h, moves_front_z(p1.z(), g) + g.insertion_depth, g);
  poses.emplace_back("extract_lift", extract[0]);
  poses.emplace_back("extract_end", extract[1]);
  const Eigen::Isometry3d& support = scene.holder_support_pose;
  poses.emplace_back("holder_pre_place", holder_pre_place_pose(support, h, g));
  const Eigen::Isometry3d hp = holder_place_pose(support, h, g);
  poses.emplace_back("holder_place", hp);
  poses.emplace_back("holder_retreat", move_along_own_axes(hp, Eigen::Vector3d(0, 0, -g.holder_retreat)));
  poses.emplace_back("holder_regrasp", holder_place_pose(support, holder_regrasp_height(h, g), g));
  const double held = height_held_from_holder(h, g);
  poses.emplace_back("lower_pre_place",
                     lower_pre_place_pose(grasp, lower_right_y, book.width_m, held, std::max(0.0, p1.x()), g));
  const Eigen::Isometry3d lp = lower_place_pose(grasp, lower_right_y, book.width_m, held, g);
  poses.emplace_back("lower_place", lp);
  poses.emplace_back("lower_retreat", move_along_own_axes(lp, Eigen::Vector3d(0, 0, -g.lower_retreat)));

  std::vector<StageReach> out;
  for (const auto& [name, pose] : poses) {
    StageReach r;
    r.stage = name;
    r.tcp = pose;
    const IkResult res = ik.solve(pose, seed_q);
    r.reachable = res.success;
    r.reason = res.reason;
    r.elbow_needed_rad = elbow_bend_for_tcp(ik.kinematics(), pose);
    out.push_back(r);
  }
  return out;
}

}  // namespace bookgrasp
