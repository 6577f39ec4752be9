#pragma once
/// @file
/// The pinhole model of a MuJoCo camera: intrinsics from the camera's vertical
/// field of view and the image size, extrinsics as the optical frame in `base`.

#include <string>

#include <Eigen/Geometry>
#include <mujoco/mujoco.h>

#include "bookgrasp/camera_calibration_t.hpp"

namespace bookgrasp::sim_render {

/// An ideal (distortion-free) pinhole camera. Pixel coordinates follow the
/// OpenCV convention: pixel (c, r) has its centre at (c, r), so the image
/// centre is ((width-1)/2, (height-1)/2). The optical frame has x right,
/// y down, z forward (along the optical axis).
struct PinholeCamera {
  std::string frame;                 ///< camera frame name, e.g. "stereo_left"
  int width = 0;                     ///< pixels
  int height = 0;                    ///< pixels
  double fx = 0.0;                   ///< focal length in pixels (x)
  double fy = 0.0;                   ///< focal length in pixels (y)
  double cx = 0.0;                   ///< principal point, pixels
  double cy = 0.0;                   ///< principal point, pixels
  Eigen::Isometry3d camera_in_base = Eigen::Isometry3d::Identity();  ///< optical frame in `base`

  /// `p_base` expressed in the optical frame (metres).
  Eigen::Vector3d to_camera(const Eigen::Vector3d& p_base) const;
  /// Pixel of `p_base` (OpenCV convention). Undefined for points with z <= 0.
  Eigen::Vector2d project(const Eigen::Vector3d& p_base) const;
  /// Unit-z ray direction (x, y, 1) in the optical frame through pixel (u, v).
  Eigen::Vector3d ray(double u, double v) const;
  /// The calibration message (no distortion, camera pose in `base`).
  camera_calibration_t to_message(int64_t utime) const;
};

/// Focal length in pixels of a camera with vertical field of view `fovy_deg`
/// rendering images `height` pixels tall: (height/2) / tan(fovy/2).
double focal_from_fovy(double fovy_deg, int height);

/// The pinhole model of camera `cam_id` of `m` in the state `d` (after
/// mj_forward / mj_kinematics), for images of `width` x `height`.
/// `base_in_world` places the `base` frame in MuJoCo's world frame.
PinholeCamera pinhole_from_model(const mjModel* m, const mjData* d, int cam_id, int width, int height,
                                 const Eigen::Isometry3d& base_in_world);

}  // namespace bookgrasp::sim_render
