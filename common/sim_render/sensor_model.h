#pragma once
/// @file
/// A simple camera sensor: exposure gain, black level and Gaussian pixel noise,
/// drawn from a seeded generator so the same scene, seed, time and camera give
/// the same pixels.

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace bookgrasp::sim_render {

/// Sensor parameters of one camera (values in 8-bit grey levels).
struct SensorModel {
  double exposure_gain = 1.0;  ///< multiplies the rendered intensity (1 = as rendered)
  double black_level = 0.0;    ///< added after the gain, grey levels
  double noise_stddev = 0.0;   ///< standard deviation of the per-pixel, per-channel Gaussian noise, grey levels
};

/// A 64-bit seed for one frame of one camera, mixed from the scene seed, the
/// frame's time and the camera name (so cameras and frames get independent noise).
uint64_t frame_seed(int64_t scene_seed, int64_t utime, const std::string& camera);

/// `rgb` (CV_8UC3) seen through `sensor`: out = clamp(round(gain * in + black + noise)); the noise
/// is zero-mean with stddev noise_stddev (a sum of four uniforms, close to Gaussian).
/// Deterministic for a given `seed`. Returns a new image; `rgb` is unchanged.
cv::Mat apply_sensor_model(const cv::Mat& rgb, const SensorModel& sensor, uint64_t seed);

}  // namespace bookgrasp::sim_render
