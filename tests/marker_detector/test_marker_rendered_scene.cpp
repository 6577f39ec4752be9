// The marker detector on rendered stereo frames of the simulated library, against the simulation's truth:
// the first pass finds the cart tag in every scene; a noisy one it misses is found by the blurred second pass,
// upright and where the truth puts it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include <opencv2/core.hpp>

#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "services/marker_detector/marker_detector_node.h"

namespace bookgrasp {
namespace {

struct Rendered {
  stereo_frame_t frame;
  ground_truth_t truth;
};

// Left image and calibration of far_cart.yaml's scene `seed` (right = left: only the left is used).
Rendered render(uint64_t seed) {
  sim_render::SimCameraRig rig(std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/far_cart.yaml", seed);
  const sim_render::CameraImage left = rig.capture("stereo_left", 1000000);
  Rendered r;
  r.frame.utime = 1000000;
  r.frame.left = mat_to_image(left.rgb, image_t::RGB8, 1000000, left.camera.frame);
  r.frame.right = r.frame.left;
  r.frame.left_calibration = left.camera.to_message(1000000);
  r.frame.right_calibration = r.frame.left_calibration;
  r.frame.baseline_m = 0.12;
  r.truth = rig.model().ground_truth(1000000);
  return r;
}

std::optional<marker_t> cart_marker(const MarkerDetectorSettings& s, const stereo_frame_t& frame) {
  MarkerDetectorNode node(s);
  marker_detections_t out;
  std::string why;
  EXPECT_TRUE(node.process(frame, &out, &why)) << why;
  for (const marker_t& m : out.markers)
    if (m.role == "cart") return m;
  return std::nullopt;
}

// Until 2026-12-04 the tag plates were 1 mm thick and shadowed themselves: the white cells rendered as a 1-px dark
// checker, which the first pass missed (seed 7 among others) and which put the monocular pose ~2 cm off. The plate
// now reaches 11 mm into its mount (common/scene/mjcf_builder.cpp) and the first pass finds every cart tag here.
TEST(MarkerRenderedScene, TheFirstPassFindsTheCartTagInEveryScene) {
  MarkerDetectorSettings first_pass_only = MarkerDetectorSettings::from_config(
      Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml"));
  first_pass_only.fallback_quad_sigma = 0.0;
  for (uint64_t seed = 1; seed <= 10; ++seed)
    EXPECT_TRUE(cart_marker(first_pass_only, render(seed).frame).has_value()) << "far_cart seed " << seed;
}

TEST(MarkerRenderedScene, TheFallbackPassFindsTheCartTagTheFirstPassMisses) {
  const MarkerDetectorSettings shipped = MarkerDetectorSettings::from_config(
      Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml"));
  ASSERT_GT(shipped.fallback_quad_sigma, 0.0);
  MarkerDetectorSettings first_pass_only = shipped;
  first_pass_only.fallback_quad_sigma = 0.0;
  // far_cart seed 8 under strong sensor noise (Gaussian, 50 grey levels): the first pass misses the cart tag.
  Rendered r = render(8);
  cv::Mat rgb = image_to_mat(r.frame.left), noise(rgb.size(), CV_32FC3), noisy;
  cv::RNG rng(8);
  rng.fill(noise, cv::RNG::NORMAL, 0, 50.0);
  rgb.convertTo(noisy, CV_32FC3);
  noisy += noise;
  noisy.convertTo(rgb, CV_8UC3);
  r.frame.left = mat_to_image(rgb, image_t::RGB8, r.frame.left.utime, r.frame.left.frame);
  EXPECT_FALSE(cart_marker(first_pass_only, r.frame).has_value());
  const std::optional<marker_t> m = cart_marker(shipped, r.frame);
  ASSERT_TRUE(m.has_value());
  // The scene's marker frame has y up, z towards the robot; AprilTag's y down, z into the tag.
  Eigen::Isometry3d truth = pose_to_isometry(r.truth.cart_marker);
  truth.linear() = truth.linear() * Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Isometry3d found = pose_to_isometry(m->pose_in_base);
  EXPECT_LT(Eigen::AngleAxisd(found.linear().transpose() * truth.linear()).angle(), 3.0 * M_PI / 180.0);
  EXPECT_LT((found.translation() - truth.translation()).norm(), 0.02);
}

// Both images of far_cart.yaml's scene `seed`, as the stereo camera publishes them.
Rendered render_pair(uint64_t seed) {
  sim_render::SimCameraRig rig(std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/far_cart.yaml", seed);
  const sim_render::CameraImage left = rig.capture("stereo_left", 1000000);
  const sim_render::CameraImage right = rig.capture("stereo_right", 1000000);
  Rendered r;
  r.frame.utime = 1000000;
  r.frame.left = mat_to_image(left.rgb, image_t::RGB8, 1000000, left.camera.frame);
  r.frame.right = mat_to_image(right.rgb, image_t::RGB8, 1000000, right.camera.frame);
  r.frame.left_calibration = left.camera.to_message(1000000);
  r.frame.right_calibration = right.camera.to_message(1000000);
  r.frame.baseline_m = (left.camera.camera_in_base.translation() - right.camera.camera_in_base.translation()).norm();
  r.truth = rig.model().ground_truth(1000000);
  return r;
}

// The cart tag is ~30 px at 1.6 m. On the self-shadowed plates of before 2026-12-04 its monocular pose was a few cm
// off along the view (far_cart seed 1: 21 mm, which every grasp point inherited through the cart frame,
// docs/EVALUATION.md), and the disparity's range fixed that. On the clean plates both are within 8 mm of the truth
// in every scene; the monocular pose is now the closer one (seeds 1-6: 1.6-2.2 mm against 3.1-3.9 mm), printed here.
TEST(MarkerRenderedScene, TheStereoRangedCartTagIsWithinEightMillimetresOfTheTruth) {
  const MarkerDetectorSettings shipped = MarkerDetectorSettings::from_config(
      Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml"));
  ASSERT_TRUE(shipped.stereo_range.enabled);
  MarkerDetectorSettings mono = shipped;
  mono.stereo_range.enabled = false;
  int found = 0;
  double worst_mono = 0, worst_stereo = 0;
  for (uint64_t seed = 1; seed <= 6; ++seed) {
    const Rendered r = render_pair(seed);
    const std::optional<marker_t> s = cart_marker(shipped, r.frame), m = cart_marker(mono, r.frame);
    if (!s || !m) continue;  // the tag is not found in every rendered scene (TheFallbackPass... above)
    ++found;
    const Eigen::Vector3d truth = pose_to_isometry(r.truth.cart_marker).translation();
    const double es = (pose_to_isometry(s->pose_in_base).translation() - truth).norm();
    const double em = (pose_to_isometry(m->pose_in_base).translation() - truth).norm();
    std::printf("far_cart seed %d: cart tag %.1f mm off with the stereo range, %.1f mm monocular\n",
                static_cast<int>(seed), es * 1e3, em * 1e3);
    EXPECT_LT(es, 0.008) << "seed " << seed << " (monocular: " << em * 1e3 << " mm)";
    EXPECT_LT(em, 0.008) << "seed " << seed << " monocular";
    worst_mono = std::max(worst_mono, em);
    worst_stereo = std::max(worst_stereo, es);
  }
  EXPECT_EQ(found, 6) << "the cart tag is found in every one of these scenes (TheFirstPassFinds...)";
  std::printf("worst: %.1f mm with the stereo range, %.1f mm monocular\n", worst_stereo * 1e3, worst_mono * 1e3);
}

// The next frames (same view, 10 Hz) are searched only in regions around the tags found: the cart tag
// is found there again at the same pose.
TEST(MarkerRenderedScene, TheCartTagIsFoundAgainInItsRegionOnTheNextFrames) {
  const MarkerDetectorSettings shipped = MarkerDetectorSettings::from_config(
      Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml"));
  ASSERT_TRUE(shipped.tracking.enabled);
  Rendered r = render(7);
  MarkerDetectorNode node(shipped);
  std::vector<pose_t> cart_poses;
  for (int k = 0; k < 3; ++k) {
    r.frame.utime = r.frame.left.utime = 1000000 + k * 100000;
    marker_detections_t out;
    std::string why;
    ASSERT_TRUE(node.process(r.frame, &out, &why)) << why;
    for (const marker_t& m : out.markers)
      if (m.role == "cart") cart_poses.push_back(m.pose_in_base);
    ASSERT_EQ(cart_poses.size(), size_t(k + 1)) << "frame " << k << ": no cart tag";
  }
  for (size_t k = 1; k < cart_poses.size(); ++k) {
    const Eigen::Isometry3d a = pose_to_isometry(cart_poses[0]), b = pose_to_isometry(cart_poses[k]);
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-4) << "frame " << k;
    EXPECT_LT(Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle(), 1e-3) << "frame " << k;
  }
}

}  // namespace
}  // namespace bookgrasp
