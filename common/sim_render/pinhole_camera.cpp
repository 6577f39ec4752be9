#include "common/sim_render/pinhole_camera.h"

#include <cmath>

#include "common/pose_conversion.h"

namespace bookgrasp::sim_render {

Eigen::Vector3d PinholeCamera::to_camera(const Eigen::Vector3d& p_base) const {
  return camera_in_base.inverse() * p_base;
}

Eigen::Vector2d PinholeCamera::project(const Eigen::Vector3d& p_base) const {
  const Eigen::Vector3d p = to_camera(p_base);
  return {fx * p.x() / p.z() + cx, fy * p.y() / p.z() + cy};
}

Eigen::Vector3d PinholeCamera::ray(double u, double v) const { return {(u - cx) / fx, (v - cy) / fy, 1.0}; }

camera_calibration_t PinholeCamera::to_message(int64_t utime) const {
  camera_calibration_t msg;
  msg.utime = utime;
  msg.frame = frame;
  msg.width = width;
  msg.height = height;
  msg.fx = fx;
  msg.fy = fy;
  msg.cx = cx;
  msg.cy = cy;
  msg.distortion_model = "none";
  msg.num_distortion = 0;
  msg.camera_in_base = isometry_to_pose(camera_in_base, "base", frame, utime);
  return msg;
}

double focal_from_fovy(double fovy_deg, int height) {
  return (0.5 * height) / std::tan(0.5 * fovy_deg * M_PI / 180.0);
}

PinholeCamera pinhole_from_model(const mjModel* m, const mjData* d, int cam_id, int width, int height,
                                 const Eigen::Isometry3d& base_in_world) {
  PinholeCamera cam;
  const char* name = mj_id2name(m, mjOBJ_CAMERA, cam_id);
  cam.frame = name ? name : ("camera" + std::to_string(cam_id));
  cam.width = width;
  cam.height = height;
  cam.fx = cam.fy = focal_from_fovy(m->cam_fovy[cam_id], height);
  cam.cx = 0.5 * (width - 1);
  cam.cy = 0.5 * (height - 1);
  // MuJoCo's camera frame looks along -z with y up; the optical frame is
  // x right, y down, z forward: flip y and z.
  Eigen::Matrix3d r_world_mjcam;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r_world_mjcam(i, j) = d->cam_xmat[9 * cam_id + 3 * i + j];
  Eigen::Isometry3d optical_in_world = Eigen::Isometry3d::Identity();
  optical_in_world.linear() = r_world_mjcam * Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  optical_in_world.translation() =
      Eigen::Vector3d(d->cam_xpos[3 * cam_id], d->cam_xpos[3 * cam_id + 1], d->cam_xpos[3 * cam_id + 2]);
  cam.camera_in_base = base_in_world.inverse() * optical_in_world;
  return cam;
}

}  // namespace bookgrasp::sim_render
