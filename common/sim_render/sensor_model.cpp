#include "common/sim_render/sensor_model.h"

namespace bookgrasp::sim_render {
namespace {

uint64_t splitmix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

}  // namespace

uint64_t frame_seed(int64_t scene_seed, int64_t utime, const std::string& camera) {
  uint64_t h = 0xCBF29CE484222325ull;  // FNV-1a of the camera name
  for (unsigned char ch : camera) {
    h ^= ch;
    h *= 0x100000001B3ull;
  }
  uint64_t s = splitmix64(static_cast<uint64_t>(scene_seed));
  s = splitmix64(s ^ static_cast<uint64_t>(utime));
  s = splitmix64(s ^ h);
  return s == 0 ? 1 : s;  // cv::RNG treats 0 specially
}

cv::Mat apply_sensor_model(const cv::Mat& rgb, const SensorModel& sensor, uint64_t seed) {
  CV_Assert(rgb.type() == CV_8UC3);
  cv::Mat out;
  if (sensor.noise_stddev <= 0.0) {
    rgb.convertTo(out, CV_8UC3, sensor.exposure_gain, sensor.black_level);
    return out;
  }
  cv::Mat noise(rgb.size(), CV_32FC3);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::NORMAL, cv::Scalar::all(sensor.black_level), cv::Scalar::all(sensor.noise_stddev));
  cv::Mat value;
  rgb.convertTo(value, CV_32FC3, sensor.exposure_gain);
  value += noise;
  value.convertTo(out, CV_8UC3);  // rounds and saturates to 0..255
  return out;
}

}  // namespace bookgrasp::sim_render
