#pragma once
/// @file
/// Camera calibrations read from YAML (config/cameras/), for the `files`
/// backends of the camera services. Format (every key required):
///
///     <camera>:                 # e.g. left, right, camera
///       frame: stereo_left      # optical frame name
///       width: 640              # pixels the intrinsics refer to
///       height: 480
///       fx: 500.0               # pixels
///       fy: 500.0
///       cx: 319.5               # OpenCV convention (pixel centres at integers)
///       cy: 239.5
///       distortion_model: none  # none | plumb_bob
///       distortion: []          # 0 values for none, 5 (k1 k2 p1 p2 k3) for plumb_bob
///       position_in_base: [x, y, z]             # optical centre in base, metres
///       orientation_in_base_wxyz: [w, x, y, z]  # optical frame (x right, y down, z forward) in base

#include <string>

#include "bookgrasp/camera_calibration_t.hpp"
#include "common/config.h"

namespace bookgrasp::sim_render {

/// Reads one camera's calibration from the mapping `node` (see the file
/// comment). Throws ConfigError naming the key for a missing or bad value.
camera_calibration_t read_camera_calibration(const Config& node);

/// A rectified stereo pair's calibration.
struct StereoCalibration {
  camera_calibration_t left;   ///< left camera
  camera_calibration_t right;  ///< right camera (same intrinsics and orientation when rectified)
  double baseline_m = 0.0;     ///< distance of the optical centres
};

/// Reads `left:`, `right:` and `baseline_m:` from a stereo calibration file.
/// Checks that both images have the same size and that the optical centres
/// are baseline_m apart (within 1 mm). Throws ConfigError naming the key.
StereoCalibration load_stereo_calibration(const std::string& path);

/// Reads `camera:` from a single-camera calibration file. Throws ConfigError.
camera_calibration_t load_camera_calibration(const std::string& path);

}  // namespace bookgrasp::sim_render
