#include "services/visual_servo/hand_eye_geometry.h"

#include <stdexcept>

namespace bookgrasp {

HandEyeGeometry::HandEyeGeometry(const CameraIntrinsics& intrinsics, const Eigen::Isometry3d& camera_in_gripper)
    : k_(intrinsics), t_gc_(camera_in_gripper) {
  if (!(k_.fx > 0 && k_.fy > 0) || k_.width <= 0 || k_.height <= 0)
    throw std::invalid_argument("HandEyeGeometry: focal lengths and image size must be positive");
  if (!t_gc_.matrix().allFinite()) throw std::invalid_argument("HandEyeGeometry: camera_in_gripper is not finite");
}

bool HandEyeGeometry::project_gripper_point(const Eigen::Vector3d& p_gripper, Eigen::Vector2d* pixel) const {
  const Eigen::Vector3d pc = t_gc_.inverse() * p_gripper;
  if (!(pc.z() > 1e-9)) return false;
  *pixel = Eigen::Vector2d(k_.cx + k_.fx * pc.x() / pc.z(), k_.cy + k_.fy * pc.y() / pc.z());
  return true;
}

Eigen::Vector2d HandEyeGeometry::target_pixel(double standoff_m, double above_m) const {
  Eigen::Vector2d px(k_.cx, k_.cy);
  project_gripper_point(Eigen::Vector3d(above_m, 0, standoff_m), &px);
  return px;
}

bool HandEyeGeometry::pixel_on_plane(const Eigen::Vector2d& pixel, double standoff_m, Eigen::Vector3d* p_gripper,
                                     double* depth_camera) const {
  const Eigen::Vector3d ray_c((pixel.x() - k_.cx) / k_.fx, (pixel.y() - k_.cy) / k_.fy, 1.0);
  const Eigen::Vector3d o = t_gc_.translation();
  const Eigen::Vector3d d = t_gc_.linear() * ray_c;
  if (std::abs(d.z()) < 1e-9) return false;
  const double s = (standoff_m - o.z()) / d.z();  // s = depth along the camera z (ray_c.z = 1)
  if (!(s > 1e-6)) return false;
  *p_gripper = o + s * d;
  if (depth_camera) *depth_camera = s;
  return true;
}

GripperTwist HandEyeGeometry::camera_twist_to_gripper(const Eigen::Vector3d& v_camera,
                                                      const Eigen::Vector3d& w_camera) const {
  const Eigen::Matrix3d r = t_gc_.linear();
  const Eigen::Vector3d w_g = r * w_camera;
  const Eigen::Vector3d v_cam_g = r * v_camera;  // velocity of the camera origin, gripper axes
  // v_tcp = v_cam + w x (p_tcp - p_cam) with p_tcp = 0 in the gripper frame.
  const Eigen::Vector3d v_tcp = v_cam_g + w_g.cross(-t_gc_.translation());
  GripperTwist t;
  t << v_tcp, w_g;
  return t;
}

Eigen::Matrix<double, 6, 1> HandEyeGeometry::gripper_twist_to_camera(const GripperTwist& twist) const {
  const Eigen::Matrix3d rt = t_gc_.linear().transpose();
  const Eigen::Vector3d w_g = twist.tail<3>();
  const Eigen::Vector3d v_cam_g = twist.head<3>() + w_g.cross(t_gc_.translation());
  Eigen::Matrix<double, 6, 1> out;
  out << rt * v_cam_g, rt * w_g;
  return out;
}

Eigen::Matrix<double, 2, 6> point_interaction_matrix(double x, double y, double z) {
  Eigen::Matrix<double, 2, 6> l;
  l << -1.0 / z, 0.0, x / z, x * y, -(1.0 + x * x), y,  //
      0.0, -1.0 / z, y / z, 1.0 + y * y, -x * y, -x;
  return l;
}

}  // namespace bookgrasp
