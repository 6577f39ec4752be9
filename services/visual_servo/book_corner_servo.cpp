#include "services/visual_servo/book_corner_servo.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

namespace bookgrasp {

GripperTwist saturate_twist(const GripperTwist& twist, double max_linear, double max_angular) {
  double scale = 1.0;
  const double v = twist.head<3>().norm(), w = twist.tail<3>().norm();
  if (v > max_linear && v > 0) scale = std::min(scale, max_linear / v);
  if (w > max_angular && w > 0) scale = std::min(scale, max_angular / w);
  return twist * scale;
}

BookCornerServo::BookCornerServo(const HandEyeGeometry& geometry, const BookCornerServoParams& params)
    : geo_(geometry), p_(params) {}

CornerServoStep BookCornerServo::step(const Eigen::Vector2d& r_px, double slope_rad, double standoff_m,
                                      const Eigen::Vector3d& moved_since_capture) {
  CornerServoStep out;
  const CameraIntrinsics& k = geo_.intrinsics();
  out.target_px = geo_.target_pixel(standoff_m, p_.target_above_tcp_m);
  out.error_px = r_px - out.target_px;
  out.slope_error_rad = p_.align_slope ? slope_rad : 0.0;

  // Depth of the corner: its viewing ray meets the plane z_gripper = standoff.
  Eigen::Vector3d p_g;
  double z = 0;
  if (!geo_.pixel_on_plane(r_px, standoff_m, &p_g, &z)) {
    geo_.pixel_on_plane(out.target_px, standoff_m, &p_g, &z);
  }
  const double x = (r_px.x() - k.cx) / k.fx, y = (r_px.y() - k.cy) / k.fy;
  const Eigen::Matrix<double, 2, 6> l = point_interaction_matrix(x, y, z);
  // Columns of the controlled TCP dofs (vx, vy, wz in the gripper frame) mapped to the camera twist.
  const int dofs[3] = {0, 1, 5};
  Eigen::Matrix3d j = Eigen::Matrix3d::Zero();
  for (int c = 0; c < 3; ++c) {
    GripperTwist unit = GripperTwist::Zero();
    unit(dofs[c]) = 1.0;
    const Eigen::Matrix<double, 6, 1> cam = geo_.gripper_twist_to_camera(unit);
    const Eigen::Vector2d ds = l * cam;  // normalised image rate
    j(0, c) = k.fx * ds.x();
    j(1, c) = k.fy * ds.y();
    j(2, c) = -cam(5);  // the image rotates opposite to the camera about its z
  }
  Eigen::Vector3d e(out.error_px.x(), out.error_px.y(), out.slope_error_rad);
  // R is fixed in the world: the TCP's motion since capture has moved it in the image by about j * motion.
  if (p_.compensate_capture_delay && moved_since_capture.allFinite()) {
    Eigen::Vector3d m = moved_since_capture;
    if (!p_.align_slope) m(2) = 0;
    e += j * m;
  }
  Eigen::Vector3d lambda(p_.gain, p_.gain, p_.slope_gain);
  Eigen::Vector3d u;
  if (p_.align_slope) {
    u = -j.fullPivLu().solve(lambda.cwiseProduct(e));
  } else {
    const Eigen::Matrix2d j2 = j.topLeftCorner<2, 2>();
    const Eigen::Vector2d u2 = -j2.fullPivLu().solve(lambda.head<2>().cwiseProduct(e.head<2>()));
    u << u2, 0.0;
  }
  if (!u.allFinite()) u.setZero();
  GripperTwist t = GripperTwist::Zero();
  t(0) = u(0);
  t(1) = u(1);
  t(5) = u(2);
  out.twist = saturate_twist(t, p_.max_linear_speed, p_.max_angular_speed);

  const bool ok = out.error_px.norm() <= p_.converged_px && std::abs(out.slope_error_rad) <= p_.converged_slope_rad;
  in_tolerance_ = ok ? in_tolerance_ + 1 : 0;
  out.converged = in_tolerance_ >= p_.converged_frames;
  return out;
}

}  // namespace bookgrasp
