#include "common/sim_render/calibration_file.h"

#include <cmath>

#include <Eigen/Geometry>

#include "common/pose_conversion.h"

namespace bookgrasp::sim_render {

camera_calibration_t read_camera_calibration(const Config& node) {
  camera_calibration_t c;
  c.utime = 0;
  c.frame = node.get<std::string>("frame");
  if (c.frame.empty()) throw ConfigError(node.source() + ": " + node.path_of("frame") + " must not be empty");
  c.width = node.get_int("width", 1, 8192);
  c.height = node.get_int("height", 1, 8192);
  c.fx = node.get_double("fx", 1e-3, 1e6);
  c.fy = node.get_double("fy", 1e-3, 1e6);
  c.cx = node.get_double("cx", -1e4, 1e4);
  c.cy = node.get_double("cy", -1e4, 1e4);
  c.distortion_model = node.get_choice("distortion_model", {"none", "plumb_bob"});
  const size_t n_expected = c.distortion_model == "none" ? 0 : 5;
  c.distortion = node.get<std::vector<double>>("distortion");
  if (c.distortion.size() != n_expected) {
    throw ConfigError(node.source() + ": " + node.path_of("distortion") + " needs " + std::to_string(n_expected) +
                      " values for distortion_model " + c.distortion_model + ", got " +
                      std::to_string(c.distortion.size()));
  }
  c.num_distortion = static_cast<int32_t>(c.distortion.size());
  const std::vector<double> p = node.get_vector("position_in_base", 3);
  const std::vector<double> q = node.get_vector("orientation_in_base_wxyz", 4);
  const double qn = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (!(std::abs(qn - 1.0) < 1e-3)) {
    throw ConfigError(node.source() + ": " + node.path_of("orientation_in_base_wxyz") +
                      " must be a unit quaternion w, x, y, z (norm is " + std::to_string(qn) + ")");
  }
  c.camera_in_base.utime = 0;
  c.camera_in_base.frame = "base";
  c.camera_in_base.child = c.frame;
  for (int i = 0; i < 3; ++i) c.camera_in_base.position[i] = p[i];
  for (int i = 0; i < 4; ++i) c.camera_in_base.orientation[i] = q[i] / qn;
  return c;
}

StereoCalibration load_stereo_calibration(const std::string& path) {
  const Config root = Config::load_file(path);
  StereoCalibration s;
  s.left = read_camera_calibration(root.child("left"));
  s.right = read_camera_calibration(root.child("right"));
  s.baseline_m = root.get_double("baseline_m", 1e-4, 10.0);
  root.require_all_read();
  if (s.left.width != s.right.width || s.left.height != s.right.height) {
    throw ConfigError(path + ": left and right image sizes differ (a rectified pair has one size)");
  }
  const Eigen::Map<const Eigen::Vector3d> pl(s.left.camera_in_base.position), pr(s.right.camera_in_base.position);
  const double d = (pl - pr).norm();
  if (std::abs(d - s.baseline_m) > 1e-3) {
    throw ConfigError(path + ": baseline_m is " + std::to_string(s.baseline_m) +
                      " but the optical centres (left.position_in_base, right.position_in_base) are " +
                      std::to_string(d) + " m apart");
  }
  return s;
}

camera_calibration_t load_camera_calibration(const std::string& path) {
  const Config root = Config::load_file(path);
  camera_calibration_t c = read_camera_calibration(root.child("camera"));
  root.require_all_read();
  return c;
}

}  // namespace bookgrasp::sim_render
