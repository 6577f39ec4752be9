// The bws_detector component on an in-process bus: a rendered synthetic shelf pair + the cart marker
// in, BOOK_CORNER_STEREO out (utime, implementation, P1 on a book's true corner, grasp frame), both
// implementations on the same channel; bad input (image sizes, NaN calibration, missing/stale/invalid
// markers, garbage) rejected with reasons and no output.
#include "services/bws_detector/bws_detector_node.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "common/composition.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "services/bws_detector/cart_geometry.h"
#include "synthetic_shelf.h"

namespace bookgrasp {
namespace {

const std::string kConfigDir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";

struct Collector {
  std::vector<book_corner_stereo_t> corners;
  std::vector<image_t> debug;
  void on_corner(const lcm::ReceiveBuffer*, const std::string&, const book_corner_stereo_t* m) {
    corners.push_back(*m);
  }
  void on_debug(const lcm::ReceiveBuffer*, const std::string&, const image_t* m) { debug.push_back(*m); }
};

// The scene, its stereo frame and the cart marker pose the marker detector would report.
struct Fixture {
  bws::test::ShelfScene scene = bws::test::make_shelf_scene(1);
  stereo_frame_t frame;
  marker_detections_t markers;
  BwsDetectorSettings settings(const std::string& file) const {
    BwsDetectorSettings s = BwsDetectorSettings::from_config(Config::load_file(kConfigDir + file));
    // The synthetic cart's upper-shelf volume, in its cart frame (the test knows its geometry), drawn as
    // the shipped config draws the simulated cart's: fronts up to 0.20 m deep, the rear board (0.32 m)
    // outside. A volume that takes in the rear board makes it the densest layer when no region passes
    // (selection.layer_without_front_m).
    const Eigen::Isometry3d box_in_cart = scene.cart_in_base.inverse() * scene.shelf_box_in_base;
    s.params.cart.shelf_min_cart = box_in_cart.translation() - scene.shelf_half_extent;
    s.params.cart.shelf_max_cart = box_in_cart.translation() + scene.shelf_half_extent;
    s.params.cart.shelf_max_cart.x() = 0.20;
    s.publish_debug_image = true;
    s.measure_processing_time = false;
    // These tests send one frame (one utime) several times; the frame-rate limit has its own test.
    s.min_frame_interval_s = 0.0;
    return s;
  }
  Fixture() {
    const cv::Mat left = bws::test::render_boxes(scene.boxes, scene.left, true).intensity;
    const cv::Mat right = bws::test::render_boxes(scene.boxes, scene.right, true).intensity;
    const int64_t utime = 5000000;
    frame.utime = utime;
    frame.left = mat_to_image(left, image_t::GRAY8, utime, "stereo_left");
    frame.right = mat_to_image(right, image_t::GRAY8, utime, "stereo_right");
    for (auto* c : {&frame.left_calibration, &frame.right_calibration}) {
      const auto& cam = c == &frame.left_calibration ? scene.left : scene.right;
      c->utime = utime;
      c->frame = "stereo";
      c->width = cam.width;
      c->height = cam.height;
      c->fx = cam.fx;
      c->fy = cam.fy;
      c->cx = cam.cx;
      c->cy = cam.cy;
      c->distortion_model = "none";
      c->num_distortion = 0;
      c->camera_in_base = isometry_to_pose(cam.in_base, "base", c->frame, utime);
    }
    frame.baseline_m = scene.baseline_m;
    // Cart marker (AprilTag axes) where the configuration says it is on the cart.
    const BwsDetectorSettings s = settings("bws_detector.yaml");
    Eigen::Isometry3d marker_in_cart = Eigen::Isometry3d::Identity();
    marker_in_cart.linear().col(0) = -Eigen::Vector3d::UnitY();
    marker_in_cart.linear().col(1) = -Eigen::Vector3d::UnitZ();
    marker_in_cart.linear().col(2) = Eigen::Vector3d::UnitX();
    marker_in_cart.translation() = s.params.cart.marker_in_cart;
    marker_t m;
    m.utime = utime;
    m.family = "tag36h11";
    m.role = "cart";
    m.pose_in_base = isometry_to_pose(scene.cart_in_base * marker_in_cart, "base", "cart_marker", utime);
    m.pose_in_camera = m.pose_in_base;
    markers.utime = utime;
    markers.implementation = "test";
    markers.markers.push_back(m);
    markers.num_markers = 1;
  }
  // True upper-right front corners of every book.
  std::vector<Eigen::Vector3d> book_corners() const {
    std::vector<Eigen::Vector3d> c;
    for (int i = 0; i < scene.num_books; ++i) {
      const auto& b = scene.boxes[size_t(scene.first_book + i)];
      c.push_back(b.pose * Eigen::Vector3d(-b.half.x(), -b.half.y(), b.half.z()));
    }
    return c;
  }
};

Fixture& fixture() {
  static Fixture f;
  return f;
}

class BwsNode : public ::testing::TestWithParam<std::string> {
 protected:
  void start(const std::string& file) {
    node = &comp.add(std::make_unique<BwsDetectorNode>(fixture().settings(file)));
    comp.bus().subscribe("BOOK_CORNER_STEREO", &Collector::on_corner, &col);
    comp.bus().subscribe("BWS_DEBUG_IMAGE", &Collector::on_debug, &col);
  }
  Composition comp;
  BwsDetectorNode* node = nullptr;
  Collector col;
};

TEST_P(BwsNode, PublishesP1OnABookCornerWithTheFrameUtime) {
  start(GetParam());
  Fixture& f = fixture();
  comp.bus().publish("MARKERS", &f.markers);
  comp.bus().publish("STEREO_IMAGES", &f.frame);
  comp.spin();
  ASSERT_EQ(col.corners.size(), 1u) << node->last_error();
  const book_corner_stereo_t& m = col.corners[0];
  EXPECT_EQ(m.utime, f.frame.utime);
  EXPECT_EQ(m.implementation, GetParam() == "bws_detector.yaml" ? "god" : "pcl");
  EXPECT_EQ(m.num_regions, int32_t(m.regions.size()));
  EXPECT_GT(m.num_regions, 0);
  EXPECT_GT(m.num_valid_disparity, 100000);
  if (GetParam() != "bws_detector.yaml") {
    // PCL (parameters not tuned for StereoBM noise) may find no front here; the contract still holds.
    if (!m.found) {
      EXPECT_FALSE(m.failure_reason.empty());
      EXPECT_TRUE(std::isnan(m.p1_base[0]) && std::isnan(m.p1_grasp[2]));
      return;
    }
  }
  ASSERT_TRUE(m.found) << m.failure_reason;
  EXPECT_TRUE(m.failure_reason.empty());
  int candidates = 0;
  for (const auto& r : m.regions) {
    candidates += r.candidate;
    EXPECT_EQ(r.candidate, r.reject_reason.empty());
    EXPECT_EQ(r.utime, f.frame.utime);
  }
  // A P1 without a selected region comes from the fronts' layer placed where the volume's points are
  // densest (selection.layer_without_front_m): only when no region passed.
  if (m.selected_label == 0)
    EXPECT_EQ(candidates, 0);
  else
    EXPECT_GE(candidates, 1);
  // P1 lies on the true upper-right front corner of one of the books (StereoBM on this scene does not
  // always give the right-most one, see docs/BWS.md), within 25 mm (as book_front_selection_test).
  const Eigen::Vector3d p1(m.p1_base[0], m.p1_base[1], m.p1_base[2]);
  double best = 1e9;
  for (const auto& c : f.book_corners()) best = std::min(best, (c - p1).norm());
  EXPECT_LT(best, 0.025) << "P1 " << p1.transpose();
  // Grasp frame: Z = the synthetic cart's x (into the shelf), X = up, origin at the cart origin.
  const Eigen::Vector3d g(m.p1_grasp[0], m.p1_grasp[1], m.p1_grasp[2]);
  const Eigen::Isometry3d& cart = f.scene.cart_in_base;
  EXPECT_NEAR(g.z(), cart.linear().col(0).dot(p1 - cart.translation()), 2e-3);  // cart yaw is small
  EXPECT_NEAR(g.x(), p1.z() - cart.translation().z(), 1e-9);
  EXPECT_NEAR(g.y(), -cart.linear().col(1).dot(p1 - cart.translation()), 2e-3);
  EXPECT_NEAR(m.pi_px[0], std::round(m.pi_px[0]), 0.0);
  // Timings off in this configuration (bit-reproducible output).
  EXPECT_EQ(m.total_ms, 0.0);
  // Debug picture: a PNG of the image size, same utime.
  ASSERT_EQ(col.debug.size(), 1u);
  EXPECT_EQ(col.debug[0].pixel_format, image_t::PNG);
  EXPECT_EQ(col.debug[0].utime, f.frame.utime);
  const cv::Mat dbg = image_to_mat(col.debug[0]);
  EXPECT_EQ(dbg.cols, 640);
  EXPECT_EQ(dbg.rows, 480);
}

TEST_P(BwsNode, SameInputGivesTheSameOutputBitForBit) {
  start(GetParam());
  Fixture& f = fixture();
  comp.bus().publish("MARKERS", &f.markers);
  comp.bus().publish("STEREO_IMAGES", &f.frame);
  comp.bus().publish("STEREO_IMAGES", &f.frame);
  comp.spin();
  ASSERT_EQ(col.corners.size(), 2u);
  std::vector<uint8_t> a(size_t(col.corners[0].getEncodedSize())), b(size_t(col.corners[1].getEncodedSize()));
  col.corners[0].encode(a.data(), 0, int(a.size()));
  col.corners[1].encode(b.data(), 0, int(b.size()));
  EXPECT_EQ(a, b);
}

INSTANTIATE_TEST_SUITE_P(Implementations, BwsNode, ::testing::Values("bws_detector.yaml", "bws_detector_pcl.yaml"));

class BwsNodeBadInput : public BwsNode {
 protected:
  void SetUp() override { start("bws_detector.yaml"); }
  // Publishes markers (if given) and a frame; expects no output and a rejection naming `what`.
  void expect_rejected(const stereo_frame_t& frame, const marker_detections_t* markers, const std::string& what) {
    const int64_t before = node->rejected_total();
    if (markers) comp.bus().publish("MARKERS", markers);
    comp.bus().publish("STEREO_IMAGES", &frame);
    comp.spin();
    EXPECT_TRUE(col.corners.empty());
    EXPECT_GT(node->rejected_total(), before);
    EXPECT_NE(node->last_error().find(what), std::string::npos) << node->last_error();
  }
  // Before any cart marker: no output, the reason in last_error, but not a rejection (start-up, not bad input).
  // Without MARKERS covering the frame it is held (pairing.max_pending_frames): send one more than that.
  void expect_waiting(const stereo_frame_t& frame, const marker_detections_t* markers) {
    const int64_t before = node->rejected_total();
    if (markers) comp.bus().publish("MARKERS", markers);
    for (int i = 0; i <= fixture().settings("bws_detector.yaml").max_pending_frames; ++i)
      comp.bus().publish("STEREO_IMAGES", &frame);
    comp.spin();
    EXPECT_TRUE(col.corners.empty());
    EXPECT_EQ(node->rejected_total(), before);
    EXPECT_NE(node->last_error().find("waiting: no cart marker"), std::string::npos) << node->last_error();
  }
};

TEST_F(BwsNodeBadInput, MissingCartMarker) {
  expect_waiting(fixture().frame, nullptr);
  // A MARKERS message without the cart marker does not help.
  marker_detections_t other = fixture().markers;
  other.markers[0].role = "holder";
  expect_waiting(fixture().frame, &other);
}

TEST_F(BwsNodeBadInput, StaleCartMarker) {
  marker_detections_t old = fixture().markers;
  old.utime = fixture().frame.utime - 60000000;  // 60 s before the frame, limit 30 s
  comp.bus().publish("MARKERS", &old);
  marker_detections_t none_now = fixture().markers;  // the detector's answer for the frame: no cart marker
  none_now.markers.clear();
  none_now.num_markers = 0;
  expect_rejected(fixture().frame, &none_now, "max_marker_age_s");
}

// The marker detector's answer for a frame can arrive after the frame (it works on the same image):
// the frame waits for it and is answered with the cart pose of its own utime, exactly as if the
// MARKERS message had come first (the same output live, in a replay and in a chain replay).
TEST_F(BwsNodeBadInput, AFrameIsPairedWithTheMarkerOfItsUtimeWhicheverArrivesFirst) {
  const Fixture& f = fixture();
  marker_detections_t earlier = f.markers;  // a frame before, the cart measured 3 cm off
  earlier.utime = f.frame.utime - 100000;
  earlier.markers[0].pose_in_base.position[1] += 0.03;
  comp.bus().publish("MARKERS", &earlier);
  comp.bus().publish("STEREO_IMAGES", &f.frame);
  comp.spin();
  EXPECT_TRUE(col.corners.empty());  // held for its MARKERS
  comp.bus().publish("MARKERS", &f.markers);
  comp.spin();
  ASSERT_EQ(col.corners.size(), 1u) << node->last_error();
  // Reference: the marker first, then the frame, on a fresh node.
  Composition ref;
  ref.add(std::make_unique<BwsDetectorNode>(f.settings("bws_detector.yaml")));
  Collector ref_col;
  ref.bus().subscribe("BOOK_CORNER_STEREO", &Collector::on_corner, &ref_col);
  ref.bus().publish("MARKERS", &f.markers);
  ref.bus().publish("STEREO_IMAGES", &f.frame);
  ref.spin();
  ASSERT_EQ(ref_col.corners.size(), 1u);
  std::vector<uint8_t> a(size_t(col.corners[0].getEncodedSize())), b(size_t(ref_col.corners[0].getEncodedSize()));
  col.corners[0].encode(a.data(), 0, int(a.size()));
  ref_col.corners[0].encode(b.data(), 0, int(b.size()));
  EXPECT_EQ(a, b);
}

TEST_F(BwsNodeBadInput, WithTheMarkerDetectorSilentFramesAreHeldAtMostMaxPendingThenAnswered) {
  const Fixture& f = fixture();
  const int max_pending = f.settings("bws_detector.yaml").max_pending_frames;
  ASSERT_GT(max_pending, 0);
  comp.bus().publish("MARKERS", &f.markers);
  stereo_frame_t later = f.frame;
  for (int i = 1; i <= max_pending; ++i) {
    later.utime = f.frame.utime + i * 100000;
    comp.bus().publish("STEREO_IMAGES", &later);
  }
  comp.spin();
  EXPECT_TRUE(col.corners.empty());
  later.utime = f.frame.utime + (max_pending + 1) * 100000;
  comp.bus().publish("STEREO_IMAGES", &later);
  comp.spin();
  ASSERT_EQ(col.corners.size(), 1u) << node->last_error();
  EXPECT_EQ(col.corners[0].utime, f.frame.utime + 100000);  // the oldest, with the nearest marker
  EXPECT_EQ(node->rejected_total(), 0);
}

// The shipped processing.min_frame_interval_s: frames within it of the last answered frame (message
// time) are skipped, the first one at or after it is answered; a rejected frame holds nothing back, and
// a frame from before the last answer (a restarted source) is answered at once.
TEST_F(BwsNodeBadInput, FramesWithinTheMinimumIntervalOfTheLastAnswerAreSkipped) {
  const Fixture& f = fixture();
  BwsDetectorSettings st = f.settings("bws_detector.yaml");
  st.min_frame_interval_s =
      BwsDetectorSettings::from_config(Config::load_file(kConfigDir + "bws_detector.yaml")).min_frame_interval_s;
  ASSERT_GT(st.min_frame_interval_s, 0.15);
  Composition c;
  BwsDetectorNode& n = c.add(std::make_unique<BwsDetectorNode>(st));
  Collector got;
  c.bus().subscribe("BOOK_CORNER_STEREO", &Collector::on_corner, &got);
  const int64_t step = 100000;  // a 10 Hz camera
  const int64_t interval = static_cast<int64_t>(st.min_frame_interval_s * 1e6);
  const auto send = [&](int64_t utime, bool bad) {
    stereo_frame_t fr = f.frame;
    fr.utime = utime;
    if (bad) fr.baseline_m = 0.0;
    marker_detections_t m = f.markers;
    m.utime = utime;
    c.bus().publish("MARKERS", &m);
    c.bus().publish("STEREO_IMAGES", &fr);
    c.spin();
  };
  send(f.frame.utime, /*bad=*/true);  // rejected: does not count as an answer
  send(f.frame.utime + step, false);  // answered
  std::vector<int64_t> expected{f.frame.utime + step};
  for (int64_t t = f.frame.utime + 2 * step; t <= f.frame.utime + step + interval + step; t += step) {
    send(t, false);
    if (t - expected.back() >= interval) expected.push_back(t);
  }
  ASSERT_EQ(expected.size(), 2u);
  send(f.frame.utime - 20 * step, false);  // the source restarted: answered at once
  expected.push_back(f.frame.utime - 20 * step);
  ASSERT_EQ(got.corners.size(), expected.size()) << n.last_error();
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(got.corners[i].utime, expected[i]) << i;
  EXPECT_EQ(n.skipped_frames(), interval / step);
  EXPECT_EQ(n.rejected_total(), 1);
}

TEST_F(BwsNodeBadInput, AMarkerFromBeforeTheStereoSourceRestartedIsDroppedNotARejection) {
  // A restarted simulation's clock starts over: the kept marker is 30 s "after" the new frames.
  marker_detections_t old_timeline = fixture().markers;
  old_timeline.utime = fixture().frame.utime + 30000000;
  comp.bus().publish("MARKERS", &old_timeline);
  comp.spin();
  const int64_t before = node->rejected_total();
  comp.bus().publish("STEREO_IMAGES", &fixture().frame);
  comp.spin();
  EXPECT_TRUE(col.corners.empty());
  EXPECT_EQ(node->rejected_total(), before);
  EXPECT_NE(node->last_error().find("since the stereo source restarted"), std::string::npos) << node->last_error();
  // The first marker of the new timeline is used again.
  comp.bus().publish("MARKERS", &fixture().markers);
  comp.bus().publish("STEREO_IMAGES", &fixture().frame);
  comp.spin();
  EXPECT_EQ(col.corners.size(), 1u);
  EXPECT_EQ(node->rejected_total(), before);
}

TEST_F(BwsNodeBadInput, InvalidMarkerPose) {
  marker_detections_t bad = fixture().markers;
  bad.markers[0].pose_in_base.position[1] = std::numeric_limits<double>::quiet_NaN();
  comp.bus().publish("MARKERS", &bad);
  comp.spin();
  EXPECT_NE(node->last_error().find("invalid pose_in_base"), std::string::npos) << node->last_error();
  EXPECT_GT(node->rejected_total(), 0);  // the bad MARKERS message itself
  expect_waiting(fixture().frame, nullptr);
}

TEST_F(BwsNodeBadInput, WrongImageSizes) {
  stereo_frame_t f = fixture().frame;
  f.right = mat_to_image(cv::Mat(240, 320, CV_8U, cv::Scalar(100)), image_t::GRAY8, f.utime, "stereo_right");
  expect_rejected(f, &fixture().markers, "right is 320x240");
  f = fixture().frame;
  f.left_calibration.width = 1280;
  expect_rejected(f, &fixture().markers, "calibration is for 1280x480");
}

TEST_F(BwsNodeBadInput, NanCalibrationAndBaseline) {
  stereo_frame_t f = fixture().frame;
  f.left_calibration.fx = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(f, &fixture().markers, "non-finite fx");
  f = fixture().frame;
  f.baseline_m = 0.0;
  expect_rejected(f, &fixture().markers, "baseline_m");
  f = fixture().frame;
  f.left_calibration.camera_in_base.orientation[0] = std::numeric_limits<double>::quiet_NaN();
  expect_rejected(f, &fixture().markers, "camera_in_base");
}

TEST_F(BwsNodeBadInput, UndecodableImageAndGarbage) {
  stereo_frame_t f = fixture().frame;
  f.left.size = 10;
  f.left.data.resize(10);
  expect_rejected(f, &fixture().markers, "left image cannot be decoded");
  const uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
  comp.bus().publish("STEREO_IMAGES", junk, sizeof junk);
  comp.spin();
  EXPECT_NE(node->last_error().find("cannot decode"), std::string::npos);
  // The node carries on: a good frame after the bad ones is answered.
  comp.bus().publish("MARKERS", &fixture().markers);
  comp.bus().publish("STEREO_IMAGES", &fixture().frame);
  comp.spin();
  EXPECT_EQ(col.corners.size(), 1u);
}

}  // namespace
}  // namespace bookgrasp
