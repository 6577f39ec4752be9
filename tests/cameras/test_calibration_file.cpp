#include "common/sim_render/calibration_file.h"

#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

namespace bookgrasp::sim_render {
namespace {

const std::string kSource = BOOKGRASP_SOURCE_DIR;

std::string write_temp(const std::string& name, const std::string& text) {
  const std::string path = std::string(BOOKGRASP_BINARY_DIR) + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(CalibrationFile, ReadsTheMiddleburyStereoCalibration) {
  const StereoCalibration c = load_stereo_calibration(kSource + "/config/cameras/middlebury_2003_quarter.yaml");
  EXPECT_EQ(c.left.width, 450);
  EXPECT_EQ(c.left.height, 375);  // the size of tests/data/middlebury images
  EXPECT_EQ(c.left.frame, "stereo_left");
  EXPECT_EQ(c.right.frame, "stereo_right");
  EXPECT_DOUBLE_EQ(c.baseline_m, 0.10);
  EXPECT_EQ(c.left.distortion_model, "none");
  EXPECT_EQ(c.left.num_distortion, 0);
  EXPECT_EQ(c.left.camera_in_base.frame, "base");
  EXPECT_DOUBLE_EQ(c.right.camera_in_base.position[0], 0.10);
}

TEST(CalibrationFile, BadValuesNameTheKey) {
  const std::string camera =
      "  frame: cam\n  width: 640\n  height: 480\n  fx: 500\n  fy: 500\n  cx: 319.5\n  cy: 239.5\n"
      "  distortion_model: plumb_bob\n  distortion: [0.1, 0.0, 0.0]\n  position_in_base: [0, 0, 0]\n"
      "  orientation_in_base_wxyz: [1, 0, 0, 0]\n";
  try {
    load_camera_calibration(write_temp("calib_bad_distortion.yaml", "camera:\n" + camera));
    FAIL() << "3 plumb_bob coefficients accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("camera.distortion"), std::string::npos) << e.what();
  }
  std::string bad_q = camera;
  bad_q.replace(bad_q.find("[0.1, 0.0, 0.0]"), 15, "[0.1, 0, 0, 0, 0]");
  bad_q.replace(bad_q.find("[1, 0, 0, 0]"), 12, "[2, 0, 0, 0]");
  try {
    load_camera_calibration(write_temp("calib_bad_q.yaml", "camera:\n" + bad_q));
    FAIL() << "non-unit quaternion accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("orientation_in_base_wxyz"), std::string::npos) << e.what();
  }
  // A baseline that disagrees with the camera positions.
  std::string left = camera, right = camera;
  left.replace(left.find("[0.1, 0.0, 0.0]"), 15, "[0.1, 0, 0, 0, 0]");
  right.replace(right.find("[0.1, 0.0, 0.0]"), 15, "[0.1, 0, 0, 0, 0]");
  right.replace(right.find("position_in_base: [0, 0, 0]"), 27, "position_in_base: [0.2, 0, 0]");
  EXPECT_THROW(load_stereo_calibration(
                   write_temp("calib_bad_baseline.yaml", "left:\n" + left + "right:\n" + right + "baseline_m: 0.12\n")),
               ConfigError);
  EXPECT_NO_THROW(load_stereo_calibration(
      write_temp("calib_good_baseline.yaml", "left:\n" + left + "right:\n" + right + "baseline_m: 0.2\n")));
}

}  // namespace
}  // namespace bookgrasp::sim_render
