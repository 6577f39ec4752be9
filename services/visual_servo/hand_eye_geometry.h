#pragma once
/// @file
/// Geometry of the gripper camera relative to the TCP (`gripper` frame): the
/// pinhole intrinsics, the fixed camera pose in the gripper frame, projection,
/// back-projection onto a plane in front of the gripper, the target pixel that
/// puts the TCP in front of a feature, and the twist transform between the
/// camera and the TCP. Pure Eigen; no LCM.
///
/// Frames (config/robot/lwa3_pg70.urdf): gripper x = up (at a grasp pose),
/// y = right (finger travel), z = approach; hand_camera = optical frame
/// (x right, y down, z forward). In the LWA3/PG70 model the camera sits
/// 0.06 m along gripper +x (above the plates) and 0.0489 m behind the TCP,
/// looking along gripper +z.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace bookgrasp {

/// Pinhole intrinsics of the hand camera (no distortion: the sim camera has none;
/// a real camera's features would be undistorted first).
struct CameraIntrinsics {
  int width = 640;    ///< pixels
  int height = 480;   ///< pixels
  double fx = 433.0;  ///< focal length, pixels
  double fy = 433.0;  ///< focal length, pixels
  double cx = 319.5;  ///< principal point, pixels
  double cy = 239.5;  ///< principal point, pixels
};

/// A twist of the TCP expressed in the gripper frame: linear velocity of the
/// TCP origin (m/s) and angular velocity (rad/s), the arm driver's
/// CARTESIAN_VELOCITY convention with twist_frame "gripper".
using GripperTwist = Eigen::Matrix<double, 6, 1>;

/// Camera intrinsics plus the camera's fixed pose on the gripper.
class HandEyeGeometry {
 public:
  /// `camera_in_gripper`: the optical frame in the gripper (TCP) frame.
  HandEyeGeometry(const CameraIntrinsics& intrinsics, const Eigen::Isometry3d& camera_in_gripper);

  /// The intrinsics.
  const CameraIntrinsics& intrinsics() const { return k_; }
  /// The optical frame in the gripper frame.
  const Eigen::Isometry3d& camera_in_gripper() const { return t_gc_; }

  /// Pixel of a point given in the gripper frame. Returns false if the point is
  /// not in front of the camera (z <= 0 in the camera frame).
  bool project_gripper_point(const Eigen::Vector3d& p_gripper, Eigen::Vector2d* pixel) const;

  /// The pixel at which a point straight ahead of the TCP (gripper frame
  /// (0, 0, standoff_m)) appears. Driving a feature to this pixel puts the TCP's
  /// approach axis through it: the TCP is then at the feature's up/right
  /// coordinates, standoff_m in front of it. With `above_m` the point is
  /// (above_m, 0, standoff_m): the feature then ends above_m above the TCP.
  Eigen::Vector2d target_pixel(double standoff_m, double above_m = 0.0) const;

  /// Back-projects `pixel` onto the plane z_gripper = standoff_m (perpendicular
  /// to the approach axis). Returns false if the viewing ray does not hit the
  /// plane in front of the camera. `depth_camera` (optional) receives the
  /// point's z in the camera frame.
  bool pixel_on_plane(const Eigen::Vector2d& pixel, double standoff_m, Eigen::Vector3d* p_gripper,
                      double* depth_camera = nullptr) const;

  /// The TCP twist (gripper frame) that moves the camera with the camera-frame
  /// twist (v_c of the camera origin, w_c), both in camera axes.
  GripperTwist camera_twist_to_gripper(const Eigen::Vector3d& v_camera, const Eigen::Vector3d& w_camera) const;

  /// The camera-frame twist (6: v_c, w_c in camera axes) produced by a TCP twist.
  Eigen::Matrix<double, 6, 1> gripper_twist_to_camera(const GripperTwist& twist) const;

 private:
  CameraIntrinsics k_;
  Eigen::Isometry3d t_gc_;
};

/// The 2x6 interaction matrix of an image point at normalised coordinates
/// (x, y) and depth z (camera frame): d(x, y)/dt = L * (v_c, w_c).
Eigen::Matrix<double, 2, 6> point_interaction_matrix(double x, double y, double z);

}  // namespace bookgrasp
