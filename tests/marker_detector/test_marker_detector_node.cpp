// Tests of the marker_detector component on an in-process bus: poses in camera
// and base, roles, utime, configuration, and rejection of bad frames.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <apriltag/tag36h11.h>

#include "common/composition.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/service_host.h"
#include "services/marker_detector/marker_detector_node.h"
#include "synthetic_tag.h"

namespace bookgrasp {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Collector {
  std::vector<marker_detections_t> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const marker_detections_t* m) { got.push_back(*m); }
};

MarkerDetectorSettings settings() {
  const Config root = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml");
  MarkerDetectorSettings s = MarkerDetectorSettings::from_config(root);
  s.cart_ids = {3};
  s.cart_tag_size_m = 0.10;
  s.holder_ids = {4};
  s.holder_tag_size_m = 0.06;
  // These synthetic tags face the tilted camera, not upright: no mounting prior here (tests/.../test_tag_pose).
  s.cart_max_tilt_rad = s.holder_max_tilt_rad = kPi;
  s.pose_ambiguity_px = 0.0;
  return s;
}

camera_calibration_t calibration(const Eigen::Isometry3d& camera_in_base) {
  camera_calibration_t c;
  c.utime = 0;
  c.frame = "stereo_left";
  c.width = 640;
  c.height = 480;
  c.fx = c.fy = 600.0;
  c.cx = 319.5;
  c.cy = 239.5;
  c.distortion_model = "none";
  c.num_distortion = 0;
  c.camera_in_base = isometry_to_pose(camera_in_base, "base", "stereo_left", 0);
  return c;
}

Eigen::Isometry3d camera_in_base() {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(0.2, -0.1, 1.4);
  t.linear() = (Eigen::AngleAxisd(-kPi / 2, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-kPi / 2 - 0.5, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return t;
}

Eigen::Isometry3d tag_pose(double x, double y, double z, double yaw_deg) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(x, y, z);
  t.linear() = Eigen::AngleAxisd(yaw_deg * kPi / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return t;
}

struct Scene {
  stereo_frame_t frame;
  Eigen::Isometry3d cart_in_camera, holder_in_camera;
};

Scene make_scene(int64_t utime) {
  Scene s;
  s.cart_in_camera = tag_pose(-0.12, 0.02, 0.9, 15);
  s.holder_in_camera = tag_pose(0.15, -0.03, 0.8, -20);
  cv::Mat gray(480, 640, CV_8UC1, cv::Scalar(150));
  apriltag_family_t* fam = tag36h11_create();
  test::draw_tag(gray, fam, 3, 0.10, s.cart_in_camera, 600, 600, 319.5, 239.5);
  test::draw_tag(gray, fam, 4, 0.06, s.holder_in_camera, 600, 600, 319.5, 239.5);
  tag36h11_destroy(fam);
  cv::Mat rgb;
  cv::cvtColor(gray, rgb, cv::COLOR_GRAY2RGB);
  s.frame.utime = utime;
  s.frame.sequence = 1;
  s.frame.left = mat_to_image(rgb, image_t::RGB8, utime, "stereo_left");
  s.frame.right = s.frame.left;
  s.frame.left_calibration = calibration(camera_in_base());
  s.frame.right_calibration = s.frame.left_calibration;
  s.frame.baseline_m = 0.12;
  return s;
}

class NodeOnBus : public ::testing::Test {
 protected:
  NodeOnBus() {
    node = &comp.add(std::make_unique<MarkerDetectorNode>(settings()));
    comp.bus().subscribe("MARKERS", &Collector::on, &col);
  }
  Composition comp;
  MarkerDetectorNode* node = nullptr;
  Collector col;
};

double translation_error(const pose_t& p, const Eigen::Isometry3d& truth) {
  return (pose_to_isometry(p).translation() - truth.translation()).norm();
}

// The right image drawn as the right camera (0.12 m along the left's +x) sees the tags: each tag's depth comes
// from its disparity. The right image equal to the left (disparity 0, no pair at all) keeps the monocular poses
// and says why in the status.
TEST_F(NodeOnBus, TagsAreRangedInTheRightImageAndAFalsePairKeepsTheMonocularPoses) {
  Scene s = make_scene(1000000);
  cv::Mat right(480, 640, CV_8UC1, cv::Scalar(150));
  apriltag_family_t* fam = tag36h11_create();
  const Eigen::Translation3d left_to_right(-0.12, 0, 0);
  test::draw_tag(right, fam, 3, 0.10, left_to_right * s.cart_in_camera, 600, 600, 319.5, 239.5);
  test::draw_tag(right, fam, 4, 0.06, left_to_right * s.holder_in_camera, 600, 600, 319.5, 239.5);
  tag36h11_destroy(fam);
  cv::Mat right_rgb;
  cv::cvtColor(right, right_rgb, cv::COLOR_GRAY2RGB);
  const stereo_frame_t same = s.frame;  // right == left
  s.frame.right = mat_to_image(right_rgb, image_t::RGB8, 1000000, "stereo_right");
  comp.bus().publish("STEREO_IMAGES", &s.frame);
  comp.spin();
  ASSERT_EQ(col.got.size(), 1u);
  ASSERT_EQ(col.got[0].markers.size(), 2u);
  EXPECT_EQ(node->last_error(), "");
  EXPECT_NEAR(pose_to_isometry(col.got[0].markers[0].pose_in_camera).translation().z(), 0.9, 0.9 * 0.005);
  EXPECT_NEAR(pose_to_isometry(col.got[0].markers[1].pose_in_camera).translation().z(), 0.8, 0.8 * 0.005);

  stereo_frame_t later = same;
  later.utime = later.left.utime = 1100000;
  comp.bus().publish("STEREO_IMAGES", &later);
  comp.spin();
  ASSERT_EQ(col.got.size(), 2u);
  ASSERT_EQ(col.got[1].markers.size(), 2u) << "a false pair must not lose the tags";
  EXPECT_NE(node->last_error().find("not positive"), std::string::npos) << node->last_error();
  EXPECT_NE(node->last_error().find("monocular pose"), std::string::npos) << node->last_error();
  EXPECT_LT(translation_error(col.got[1].markers[0].pose_in_camera, s.cart_in_camera), 0.02);
}

TEST_F(NodeOnBus, PublishesCartAndHolderPosesInCameraAndBase) {
  const Scene s = make_scene(1234567);
  comp.bus().publish("STEREO_IMAGES", &s.frame);
  comp.spin();
  ASSERT_EQ(col.got.size(), 1u);
  const marker_detections_t& m = col.got[0];
  EXPECT_EQ(m.utime, 1234567);
  EXPECT_EQ(m.camera_frame, "stereo_left");
  ASSERT_EQ(m.num_markers, 2);
  ASSERT_EQ(m.markers.size(), 2u);
  const marker_t& cart = m.markers[0];
  const marker_t& holder = m.markers[1];
  EXPECT_EQ(cart.id, 3);
  EXPECT_EQ(cart.role, "cart");
  EXPECT_EQ(holder.id, 4);
  EXPECT_EQ(holder.role, "holder");
  EXPECT_EQ(cart.family, "tag36h11");
  EXPECT_EQ(cart.pose_in_camera.frame, "stereo_left");
  EXPECT_EQ(cart.pose_in_base.frame, "base");
  EXPECT_EQ(cart.pose_in_base.child, "cart");
  EXPECT_LT(translation_error(cart.pose_in_camera, s.cart_in_camera), 0.005);
  EXPECT_LT(translation_error(holder.pose_in_camera, s.holder_in_camera), 0.005);
  EXPECT_LT(translation_error(cart.pose_in_base, camera_in_base() * s.cart_in_camera), 0.005);
  EXPECT_LT(translation_error(holder.pose_in_base, camera_in_base() * s.holder_in_camera), 0.005);
  const Eigen::Matrix3d r = pose_to_isometry(cart.pose_in_base).linear();
  const Eigen::Matrix3d rt = (camera_in_base() * s.cart_in_camera).linear();
  EXPECT_LT(Eigen::AngleAxisd(r.transpose() * rt).angle() * 180 / kPi, 1.0);
  EXPECT_LT(cart.reprojection_error_px, 0.5);
  EXPECT_GT(cart.decision_margin, 20.0);
  EXPECT_EQ(cart.hamming, 0);
  EXPECT_EQ(cart.utime, 1234567);
  EXPECT_EQ(node->rejected_total(), 0);
}

// Determinism: the same frames in the same order give the same MARKERS bit for bit, whichever node
// (here one on the bus and a fresh one called directly; the 2nd and 3rd frames are region searches).
TEST_F(NodeOnBus, SameFramesInTheSameOrderGiveTheSameDetectionsBitForBit) {
  std::vector<Scene> scenes{make_scene(42), make_scene(100042), make_scene(200042)};
  for (const Scene& s : scenes) comp.bus().publish("STEREO_IMAGES", &s.frame);
  comp.spin();
  ASSERT_EQ(col.got.size(), scenes.size());
  MarkerDetectorNode fresh(settings());
  for (size_t i = 0; i < scenes.size(); ++i) {
    marker_detections_t again;
    std::string why;
    ASSERT_TRUE(fresh.process(scenes[i].frame, &again, &why)) << why;
    EXPECT_EQ(again.num_markers, 2);
    col.got[i].processing_ms = again.processing_ms = 0.0;  // wall time, the one non-reproducible field
    std::vector<uint8_t> a(static_cast<size_t>(col.got[i].getEncodedSize())),
        b(static_cast<size_t>(again.getEncodedSize()));
    col.got[i].encode(a.data(), 0, static_cast<int>(a.size()));
    again.encode(b.data(), 0, static_cast<int>(b.size()));
    EXPECT_EQ(a, b) << "frame " << i;
  }
}

TEST_F(NodeOnBus, UnassignedTagsCanBeHidden) {
  MarkerDetectorSettings st = settings();
  st.cart_ids = {100};
  st.holder_ids = {101};
  st.report_unassigned = false;
  MarkerDetectorNode hidden(st);
  marker_detections_t out;
  std::string reason;
  ASSERT_TRUE(hidden.process(make_scene(1).frame, &out, &reason)) << reason;
  EXPECT_EQ(out.num_markers, 0);
  st.report_unassigned = true;
  MarkerDetectorNode shown(st);
  ASSERT_TRUE(shown.process(make_scene(1).frame, &out, &reason)) << reason;
  ASSERT_EQ(out.num_markers, 2);
  EXPECT_EQ(out.markers[0].role, "");
  EXPECT_EQ(out.markers[0].pose_in_base.child, "tag36h11_3");
}

struct BadFrame {
  const char* what;
  void (*spoil)(stereo_frame_t&);
  const char* reason_part;
};

class BadFrames : public NodeOnBus, public ::testing::WithParamInterface<BadFrame> {};

TEST_P(BadFrames, AreRejectedWithAReasonAndTheNodeCarriesOn) {
  Scene s = make_scene(10);
  GetParam().spoil(s.frame);
  comp.bus().publish("STEREO_IMAGES", &s.frame);
  comp.spin();
  EXPECT_TRUE(col.got.empty());
  EXPECT_EQ(node->rejected_total(), 1);
  EXPECT_NE(node->last_error().find(GetParam().reason_part), std::string::npos) << node->last_error();
  // A good frame afterwards is still processed.
  const Scene good = make_scene(11);
  comp.bus().publish("STEREO_IMAGES", &good.frame);
  comp.spin();
  ASSERT_EQ(col.got.size(), 1u);
  EXPECT_EQ(col.got[0].num_markers, 2);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BadFrames,
    ::testing::Values(
        BadFrame{"size", [](stereo_frame_t& f) { f.left_calibration.width = 1280; }, "calibration is for 1280x480"},
        BadFrame{"format",
                 [](stereo_frame_t& f) {
                   f.left = mat_to_image(cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f)), image_t::DEPTH_F32, 10,
                                         "stereo_left");
                 },
                 "not an intensity image"},
        BadFrame{"unknown format", [](stereo_frame_t& f) { f.left.pixel_format = 99; }, "cannot be decoded"},
        BadFrame{"truncated",
                 [](stereo_frame_t& f) {
                   f.left.data.resize(100);
                   f.left.size = 100;
                 },
                 "cannot be decoded"},
        BadFrame{"nan fx", [](stereo_frame_t& f) { f.left_calibration.fx = std::nan(""); }, "non-finite"},
        BadFrame{"model", [](stereo_frame_t& f) { f.left_calibration.distortion_model = "fisheye"; },
                 "unknown distortion_model"},
        BadFrame{"coeffs",
                 [](stereo_frame_t& f) {
                   f.left_calibration.distortion_model = "plumb_bob";
                   f.left_calibration.num_distortion = 2;
                   f.left_calibration.distortion = {0.1, 0.0};
                 },
                 "5 coefficients"},
        BadFrame{"pose", [](stereo_frame_t& f) { f.left_calibration.camera_in_base.position[1] = std::nan(""); },
                 "camera_in_base"}),
    [](const ::testing::TestParamInfo<BadFrame>& info) {
      std::string n = info.param.what;
      for (char& c : n)
        if (c == ' ') c = '_';
      return n;
    });

TEST_F(NodeOnBus, GarbageOnTheChannelIsRejected) {
  const std::vector<uint8_t> junk(64, 0xAB);
  comp.bus().publish("STEREO_IMAGES", junk.data(), static_cast<unsigned>(junk.size()));
  comp.spin();
  EXPECT_TRUE(col.got.empty());
  EXPECT_EQ(node->rejected_total(), 1);
}

TEST(MarkerDetectorConfig, ShippedFileIsCompleteAndValid) {
  const Config root = Config::load_file(std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/marker_detector.yaml");
  ServiceSettings::from_config(root);
  const MarkerDetectorSettings s = MarkerDetectorSettings::from_config(root);
  EXPECT_NO_THROW(root.require_all_read());
  EXPECT_EQ(s.detector.family, "tag36h11");
  EXPECT_EQ(s.input_channel, "STEREO_IMAGES");
  EXPECT_EQ(s.output_channel, "MARKERS");
}

TEST(MarkerDetectorConfig, SharedIdIsRefusedNamingTheKey) {
  std::string yaml =
      "channels: {input: A, output: B}\n"
      "apriltag: {family: tag36h11, quad_decimate: 2, quad_sigma: 0, refine_edges: true, decode_sharpening: 0.25,"
      " threads: 1, max_hamming: 1, min_decision_margin: 20, fallback_quad_sigma: 0}\n"
      "tracking: {enabled: true, roi_margin: 1.0, roi_min_px: 64, full_search_period_s: 1.0}\n"
      "tags: {default_size_m: 0.08, report_unassigned: true, cart: {ids: [0, 2], size_m: 0.08, max_tilt_deg: 20},"
      " holder: {ids: [2], size_m: 0.08, max_tilt_deg: 35}, pose_ambiguity_px: 1.0}\n"
      "stereo_range: {enabled: true, margin: 0.25, min_depth_m: 0.3, min_score: 0.8, max_disagreement: 0.15}\n"
      "diagnostics: {measure_processing_time: false}\n";
  try {
    MarkerDetectorSettings::from_config(Config::from_string(yaml));
    FAIL() << "an id with two roles was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("tags.holder.ids"), std::string::npos) << e.what();
  }
}

TEST(MarkerDetectorConfig, AMissingOrBadStereoRangeKeyIsNamed) {
  const std::string base =
      "channels: {input: A, output: B}\n"
      "apriltag: {family: tag36h11, quad_decimate: 2, quad_sigma: 0, refine_edges: true, decode_sharpening: 0.25,"
      " threads: 1, max_hamming: 1, min_decision_margin: 20, fallback_quad_sigma: 0}\n"
      "tracking: {enabled: true, roi_margin: 1.0, roi_min_px: 64, full_search_period_s: 1.0}\n"
      "tags: {default_size_m: 0.08, report_unassigned: true, cart: {ids: [0], size_m: 0.08, max_tilt_deg: 20},"
      " holder: {ids: [1], size_m: 0.08, max_tilt_deg: 35}, pose_ambiguity_px: 1.0}\n"
      "diagnostics: {measure_processing_time: false}\n";
  const auto error_of = [](const std::string& yaml) -> std::string {
    try {
      MarkerDetectorSettings::from_config(Config::from_string(yaml));
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(error_of(base).find("stereo_range"), std::string::npos) << error_of(base);
  const std::string bad_score =
      base + "stereo_range: {enabled: true, margin: 0.25, min_depth_m: 0.3, min_score: 1.5, max_disagreement: 0.15}\n";
  EXPECT_NE(error_of(bad_score).find("stereo_range.min_score"), std::string::npos) << error_of(bad_score);
  const std::string no_margin =
      base + "stereo_range: {enabled: true, min_depth_m: 0.3, min_score: 0.8, max_disagreement: 0.15}\n";
  EXPECT_NE(error_of(no_margin).find("margin"), std::string::npos) << error_of(no_margin);
  EXPECT_EQ(error_of(base + "stereo_range: {enabled: false, margin: 0.25, min_depth_m: 0.3, min_score: 0.8,"
                            " max_disagreement: 0.15}\n"),
            "");
}

}  // namespace
}  // namespace bookgrasp
