// stereo_camera: files backend against the Middlebury data and its ground-truth
// disparity; sim backend on a memq bus (frame rate in sim time, stamps, bad input).
#include "services/stereo_camera/stereo_camera_node.h"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/composition.h"
#include "common/image_conversion.h"
#include "common/scene/scene.h"
#include "common/scene/sim_model.h"

namespace bookgrasp {
namespace {

const std::string kSource = BOOKGRASP_SOURCE_DIR;

StereoCameraSettings default_settings(const std::string& backend) {
  StereoCameraSettings s =
      StereoCameraSettings::from_config(Config::load_file(kSource + "/config/services/stereo_camera.yaml"));
  s.backend = backend;
  return s;
}

cv::Mat read_rgb_independently(const std::string& path) {
  cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR), rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

/// Mean absolute colour difference between left(x, y) and right(x - sign * d, y)
/// over pixels with a known, non-occluded ground-truth disparity d.
double disparity_consistency(const cv::Mat& left, const cv::Mat& right, const cv::Mat& disp_gt, const cv::Mat& nonocc,
                             int sign) {
  double sum = 0.0;
  int n = 0;
  for (int y = 0; y < left.rows; ++y) {
    for (int x = 0; x < left.cols; ++x) {
      const int v = disp_gt.at<uchar>(y, x);
      if (v == 0 || nonocc.at<uchar>(y, x) == 0) continue;
      const int xr = static_cast<int>(std::lround(x - sign * v / 4.0));  // disp2.png: value / 4 = pixels
      if (xr < 0 || xr >= right.cols) continue;
      const cv::Vec3b a = left.at<cv::Vec3b>(y, x), b = right.at<cv::Vec3b>(y, xr);
      sum += (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3.0;
      ++n;
    }
  }
  return n > 0 ? sum / n : 1e9;
}

TEST(StereoCameraFiles, PublishesTheMiddleburyPairsAsRectifiedLeftRight) {
  StereoCameraSettings s = default_settings("files");
  StereoCameraNode node(s);
  ASSERT_EQ(node.num_pairs(), 2u);  // Cones, Teddy (sorted)
  const char* scenes[] = {"Cones", "Teddy", "Cones"};
  for (int i = 0; i < 3; ++i) {
    stereo_frame_t f;
    ASSERT_TRUE(node.next_file_frame(&f));
    EXPECT_EQ(f.utime, s.start_utime + i * 500000);  // 2 Hz
    EXPECT_EQ(f.sequence, i);
    EXPECT_EQ(f.left.utime, f.utime);
    EXPECT_EQ(f.left_calibration.utime, f.utime);
    EXPECT_DOUBLE_EQ(f.baseline_m, 0.10);
    EXPECT_EQ(f.left_calibration.width, 450);
    EXPECT_EQ(f.left_calibration.frame, "stereo_left");
    EXPECT_EQ(f.right_calibration.frame, "stereo_right");
    const std::string dir = kSource + "/tests/data/middlebury/" + scenes[i] + "/";
    const cv::Mat left = image_to_mat(f.left), right = image_to_mat(f.right);
    EXPECT_EQ(cv::norm(left, read_rgb_independently(dir + "im2.png"), cv::NORM_INF), 0.0) << scenes[i];
    EXPECT_EQ(cv::norm(right, read_rgb_independently(dir + "im6.png"), cv::NORM_INF), 0.0) << scenes[i];
    // The published pair is left/right in the order the ground-truth disparity expects.
    const cv::Mat disp = cv::imread(dir + "disp2.png", cv::IMREAD_GRAYSCALE);
    const cv::Mat nonocc = cv::imread(dir + "occl.png", cv::IMREAD_GRAYSCALE);
    const double matched = disparity_consistency(left, right, disp, nonocc, +1);
    const double swapped = disparity_consistency(left, right, disp, nonocc, -1);
    EXPECT_LT(matched, 12.0) << scenes[i];
    EXPECT_GT(swapped, 2.0 * matched) << scenes[i];
  }
}

TEST(StereoCameraFiles, StopsAtTheEndWithoutLoopAndEncodesPng) {
  StereoCameraSettings s = default_settings("files");
  s.loop = false;
  s.image_encoding = "png";
  StereoCameraNode node(s);
  stereo_frame_t f;
  ASSERT_TRUE(node.next_file_frame(&f));
  EXPECT_EQ(f.left.pixel_format, image_t::PNG);
  EXPECT_EQ(cv::norm(image_to_mat(f.left),
                     read_rgb_independently(kSource + "/tests/data/middlebury/Cones/im2.png"), cv::NORM_INF),
            0.0);
  ASSERT_TRUE(node.next_file_frame(&f));
  EXPECT_FALSE(node.next_file_frame(&f));
}

TEST(StereoCameraFiles, BadFolderOrCalibrationFailsAtStart) {
  StereoCameraSettings s = default_settings("files");
  s.folder = kSource + "/tests/data/no_such_folder";
  EXPECT_THROW(StereoCameraNode{s}, std::runtime_error);
  s = default_settings("files");
  s.right_suffix = "im9.png";
  EXPECT_THROW(StereoCameraNode{s}, std::runtime_error);
  s = default_settings("files");
  s.calibration_file = kSource + "/config/cameras/middlebury_2003_quarter_single.yaml";
  EXPECT_THROW(StereoCameraNode{s}, ConfigError);
}

struct Collector {
  std::vector<stereo_frame_t> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const stereo_frame_t* m) { got.push_back(*m); }
};

TEST(StereoCameraSim, RendersAtTheFrameRateInSimTimeAndRejectsBadStates) {
  StereoCameraSettings s = default_settings("sim");
  s.seed = 2;
  s.sim_frame_rate_hz = 10;  // the rate mechanism at 10 Hz (the shipped rate is 2)
  // The simulation's own model of the same scene and seed gives the states.
  scene::SimModel sim = scene::SimModel::build(scene::load_scene(s.scene_file, 2));
  Composition comp;
  StereoCameraNode& node = comp.add(std::make_unique<StereoCameraNode>(s));
  Collector col;
  comp.bus().subscribe("STEREO_IMAGES", &Collector::on, &col);
  for (int64_t t = 0; t <= 250000; t += 10000) {  // 100 Hz of sim time for 0.25 s
    sim.step(5);
    const sim_state_t st = sim.state(t);
    comp.bus().publish("SIM_STATE", &st);
    comp.spin();
  }
  ASSERT_EQ(col.got.size(), 3u);  // 10 Hz: t = 0, 0.1, 0.2 s
  for (size_t i = 0; i < col.got.size(); ++i) {
    const stereo_frame_t& f = col.got[i];
    EXPECT_EQ(f.utime, static_cast<int64_t>(i) * 100000);
    EXPECT_EQ(f.sequence, static_cast<int64_t>(i));
    EXPECT_EQ(f.left.utime, f.utime);
    EXPECT_EQ(f.left_calibration.camera_in_base.utime, f.utime);
    EXPECT_NEAR(f.baseline_m, 0.12, 1e-9);
    EXPECT_EQ(f.left.pixel_format, image_t::RGB8);
    const cv::Mat left = image_to_mat(f.left);
    EXPECT_EQ(left.cols, 640);
    EXPECT_EQ(left.rows, 480);
    EXPECT_EQ(f.left_calibration.width, 640);
    EXPECT_NEAR(f.left_calibration.fx, 240.0 / std::tan(21.0 * M_PI / 180.0), 1e-6);  // fovy 42 deg
  }
  EXPECT_EQ(node.rejected_total(), 0);

  // Bad inputs: each rejected with a reason, nothing published, the node carries on.
  const int64_t rejected_before = node.rejected_total();
  sim_state_t bad = sim.state(300000);
  bad.num_joints = 3;  // wrong joint count
  bad.joint_names.resize(3);
  bad.joint_positions.resize(3);
  bad.joint_velocities.resize(3);
  comp.bus().publish("SIM_STATE", &bad);
  bad = sim.state(310000);
  bad.joint_positions[0] = std::nan("");
  comp.bus().publish("SIM_STATE", &bad);
  bad = sim.state(320000);
  bad.seed = 7;
  comp.bus().publish("SIM_STATE", &bad);
  bad = sim.state(100000);  // older than the last one
  comp.bus().publish("SIM_STATE", &bad);
  const char garbage[] = "not an LCM message at all";
  comp.bus().publish("SIM_STATE", garbage, sizeof(garbage));
  comp.spin();
  EXPECT_EQ(node.rejected_total() - rejected_before, 5);
  EXPECT_NE(node.last_error().find("SIM_STATE"), std::string::npos);
  EXPECT_EQ(col.got.size(), 3u);
  // Still working after bad input.
  const sim_state_t good = sim.state(400000);
  comp.bus().publish("SIM_STATE", &good);
  comp.spin();
  EXPECT_EQ(col.got.size(), 4u);
}

TEST(StereoCameraSim, SameStatesGiveBitIdenticalFrames) {
  StereoCameraSettings s = default_settings("sim");
  s.seed = 3;
  scene::SimModel sim = scene::SimModel::build(scene::load_scene(s.scene_file, 3));
  const sim_state_t st = sim.state(500000);
  StereoCameraNode a(s), b(s);
  stereo_frame_t fa, fb;
  std::string reason;
  ASSERT_TRUE(a.capture_sim(st, &fa, &reason)) << reason;
  ASSERT_TRUE(b.capture_sim(st, &fb, &reason)) << reason;
  EXPECT_EQ(fa.left.data, fb.left.data);
  EXPECT_EQ(fa.right.data, fb.right.data);
  EXPECT_NE(fa.left.data, fa.right.data);
}

}  // namespace
}  // namespace bookgrasp
