// Tests of the bwh_detector and bswh_detector components on an in-process bus:
// outputs against the synthetic truth, utime, rank requests, bad images, shipped configs.
#include <cmath>
#include <cstdlib>
#include <map>
#include <regex>
#include <vector>

#include <gtest/gtest.h>

#include "common/composition.h"
#include "common/image_conversion.h"
#include "common/service_host.h"
#include "services/bswh_detector/bswh_detector_node.h"
#include "services/bwh_detector/bwh_detector_node.h"
#include "synthetic_hand_image.h"

namespace bookgrasp {
namespace {

const std::string kConfigDir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";

struct Collector {
  std::vector<book_features_hand_t> books;
  std::vector<stripe_features_t> stripes;
  void on_books(const lcm::ReceiveBuffer*, const std::string&, const book_features_hand_t* m) { books.push_back(*m); }
  void on_stripe(const lcm::ReceiveBuffer*, const std::string&, const stripe_features_t* m) { stripes.push_back(*m); }
};

hand_image_t hand_image(const cv::Mat& rgb, int64_t utime) {
  hand_image_t h;
  h.utime = utime;
  h.sequence = 1;
  h.image = encode_png(rgb, utime, "hand_camera");
  h.calibration.utime = utime;
  h.calibration.frame = "hand_camera";
  h.calibration.width = rgb.cols;
  h.calibration.height = rgb.rows;
  h.calibration.fx = h.calibration.fy = 550;
  h.calibration.cx = 319.5;
  h.calibration.cy = 239.5;
  h.calibration.distortion_model = "none";
  h.calibration.num_distortion = 0;
  h.calibration.camera_in_base.orientation[0] = 1.0;
  return h;
}

class HandNodes : public ::testing::Test {
 protected:
  static BwhDetectorSettings synthetic_settings() {
    // The synthetic images are frontal views: the region detector (canny_regions) is tested here;
    // page_faces is tested on rendered views (tests/visual_servo/test_servo_closed_loop).
    BwhDetectorSettings s = BwhDetectorSettings::from_config(Config::load_file(kConfigDir + "bwh_detector.yaml"));
    s.method = "canny_regions";
    return s;
  }
  HandNodes() {
    bwh = &comp.add(std::make_unique<BwhDetectorNode>(synthetic_settings()));
    bswh = &comp.add(std::make_unique<BswhDetectorNode>(
        BswhDetectorSettings::from_config(Config::load_file(kConfigDir + "bswh_detector.yaml"))));
    comp.bus().subscribe("BOOK_FEATURES_HAND", &Collector::on_books, &col);
    comp.bus().subscribe("STRIPE_FEATURES_HAND", &Collector::on_stripe, &col);
    image = test::render_scene(test::default_scene(), &truth);
  }
  Composition comp;
  BwhDetectorNode* bwh = nullptr;
  BswhDetectorNode* bswh = nullptr;
  Collector col;
  test::SynthTruth truth;
  cv::Mat image;
};

TEST_F(HandNodes, PublishFeaturesOfTheRightMostBookAndTheStripeEnd) {
  const hand_image_t msg = hand_image(image, 777);
  comp.bus().publish("HAND_IMAGE", &msg);
  comp.spin();
  ASSERT_EQ(col.books.size(), 1u);
  ASSERT_EQ(col.stripes.size(), 1u);
  const book_features_hand_t& b = col.books[0];
  EXPECT_EQ(b.utime, 777);
  ASSERT_TRUE(b.found) << b.failure_reason;
  EXPECT_EQ(b.rank_from_right, 0);
  EXPECT_LT(std::hypot(b.r_px[0] - truth.r.x, b.r_px[1] - truth.r.y), 3.0);
  EXPECT_NEAR(b.slope_rad, truth.slope_rad, 1.5 * CV_PI / 180);
  EXPECT_EQ(b.num_candidates, static_cast<int>(b.candidates.size()));
  for (const auto& c : b.candidates) EXPECT_EQ(c.accepted, c.reject_reason.empty());
  const stripe_features_t& s = col.stripes[0];
  EXPECT_EQ(s.utime, 777);
  ASSERT_TRUE(s.found && s.end_found) << s.failure_reason;
  EXPECT_LT(std::hypot(s.end_px[0] - truth.stripe_end.x, s.end_px[1] - truth.stripe_end.y), 2.0);
}

TEST_F(HandNodes, ServoRequestSelectsTheNextBookFromTheRight) {
  servo_request_t req{};
  req.utime = 10;
  req.mode = servo_request_t::BOOK_CORNER;
  req.rank_from_right = 1;
  req.start_pose.orientation[0] = 1.0;
  comp.bus().publish("SERVO_REQUEST", &req);
  const hand_image_t msg = hand_image(image, 20);
  comp.bus().publish("HAND_IMAGE", &msg);
  comp.spin();
  EXPECT_EQ(bwh->rank_from_right(), 1);
  ASSERT_EQ(col.books.size(), 1u);
  ASSERT_TRUE(col.books[0].found);
  EXPECT_EQ(col.books[0].rank_from_right, 1);
  const cv::Point2d r2 = truth.quads[truth.quads.size() - 2][2];
  EXPECT_LT(std::hypot(col.books[0].r_px[0] - r2.x, col.books[0].r_px[1] - r2.y), 6.0);
  // A rank beyond the books found: published, found = false, with the reason.
  req.rank_from_right = 40;
  comp.bus().publish("SERVO_REQUEST", &req);
  comp.bus().publish("HAND_IMAGE", &msg);
  comp.spin();
  ASSERT_EQ(col.books.size(), 2u);
  EXPECT_FALSE(col.books[1].found);
  EXPECT_NE(col.books[1].failure_reason.find("rank 40"), std::string::npos);
}

TEST_F(HandNodes, BadImagesAreRejectedByBoth) {
  hand_image_t wrong_size = hand_image(image, 1);
  wrong_size.calibration.width = 320;
  hand_image_t depth = hand_image(image, 2);
  depth.image = mat_to_image(cv::Mat(480, 640, CV_32FC1, cv::Scalar(1.0f)), image_t::DEPTH_F32, 2, "hand_camera");
  hand_image_t broken = hand_image(image, 3);
  broken.image.data.resize(50);
  broken.image.size = 50;
  for (const hand_image_t* m : {&wrong_size, &depth, &broken}) comp.bus().publish("HAND_IMAGE", m);
  comp.spin();
  EXPECT_TRUE(col.books.empty());
  EXPECT_TRUE(col.stripes.empty());
  EXPECT_EQ(bwh->rejected_total(), 3);
  EXPECT_EQ(bswh->rejected_total(), 3);
  // Still working afterwards.
  const hand_image_t good = hand_image(image, 4);
  comp.bus().publish("HAND_IMAGE", &good);
  comp.spin();
  EXPECT_EQ(col.books.size(), 1u);
  EXPECT_EQ(col.stripes.size(), 1u);
}

TEST_F(HandNodes, NoStripeIsPublishedAsNotFound) {
  test::SynthScene s = test::default_scene();
  s.stripe = false;
  test::SynthTruth t;
  const hand_image_t msg = hand_image(test::render_scene(s, &t), 5);
  comp.bus().publish("HAND_IMAGE", &msg);
  comp.spin();
  ASSERT_EQ(col.stripes.size(), 1u);
  EXPECT_FALSE(col.stripes[0].found);
  EXPECT_FALSE(col.stripes[0].failure_reason.empty());
}

TEST(HandNodesDebug, DebugImagesShowRAndTheStripeEndOnlyWhenEnabled) {
  Composition comp;
  BwhDetectorSettings bs = BwhDetectorSettings::from_config(Config::load_file(kConfigDir + "bwh_detector.yaml"));
  bs.method = "canny_regions";
  BswhDetectorSettings ss = BswhDetectorSettings::from_config(Config::load_file(kConfigDir + "bswh_detector.yaml"));
  EXPECT_FALSE(bs.publish_debug_image);  // off by default: ~0.3 MB per frame
  EXPECT_FALSE(ss.publish_debug_image);
  bs.publish_debug_image = ss.publish_debug_image = true;
  comp.add(std::make_unique<BwhDetectorNode>(bs));
  comp.add(std::make_unique<BswhDetectorNode>(ss));
  std::map<std::string, std::vector<image_t>> got;
  struct Sink {
    std::map<std::string, std::vector<image_t>>* got;
    void on(const lcm::ReceiveBuffer*, const std::string& ch, const image_t* m) { (*got)[ch].push_back(*m); }
  } sink{&got};
  comp.bus().subscribe("BWH_DEBUG_IMAGE", &Sink::on, &sink);
  comp.bus().subscribe("BSWH_DEBUG_IMAGE", &Sink::on, &sink);
  test::SynthTruth truth;
  const cv::Mat rgb = test::render_scene(test::default_scene(), &truth);
  const hand_image_t msg = hand_image(rgb, 4242);
  comp.bus().publish("HAND_IMAGE", &msg);
  comp.spin();
  ASSERT_EQ(got["BWH_DEBUG_IMAGE"].size(), 1u);
  ASSERT_EQ(got["BSWH_DEBUG_IMAGE"].size(), 1u);
  for (const auto& [channel, images] : got) {
    const image_t& im = images[0];
    if (const char* dir = std::getenv("BOOKGRASP_DEBUG_IMAGES")) write_png(std::string(dir) + "/" + channel + ".png", image_to_mat(im));
    EXPECT_EQ(im.utime, 4242) << channel;
    EXPECT_EQ(im.pixel_format, image_t::PNG) << channel;
    EXPECT_EQ(im.frame, "hand_camera") << channel;
  }
  // The true corner R and the true stripe end: each overlay has changed the picture there (the cross).
  const auto changed_near = [&](const image_t& im, cv::Point2d p) {
    const cv::Mat o = image_to_mat(im);
    EXPECT_EQ(o.size(), rgb.size());
    cv::Mat diff;
    const cv::Rect box = cv::Rect(cv::Point(int(p.x) - 4, int(p.y) - 4), cv::Size(9, 9)) & cv::Rect({}, rgb.size());
    cv::absdiff(o(box), rgb(box), diff);
    return cv::countNonZero(diff.reshape(1) > 60);
  };
  EXPECT_GT(changed_near(got["BWH_DEBUG_IMAGE"][0], truth.r), 5);
  EXPECT_GT(changed_near(got["BSWH_DEBUG_IMAGE"][0], truth.stripe_end), 5);
}

TEST(HandConfigs, AnEmptyDebugChannelIsABadKey) {
  for (const char* name : {"bwh_detector.yaml", "bswh_detector.yaml"}) {
    const Config root =
        Config::from_string(std::regex_replace(Config::load_file(kConfigDir + name).dump(),
                                               std::regex("debug_image: BS?WH_DEBUG_IMAGE"), "debug_image: \"\""),
                            name);
    try {
      if (std::string(name) == "bwh_detector.yaml")
        BwhDetectorSettings::from_config(root);
      else
        BswhDetectorSettings::from_config(root);
      ADD_FAILURE() << name << ": an empty channels.debug_image was accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("channels.debug_image"), std::string::npos) << e.what();
    }
  }
}

TEST(HandConfigs, ShippedFilesAreCompleteAndValid) {
  for (const char* name : {"bwh_detector.yaml", "bswh_detector.yaml"}) {
    const Config root = Config::load_file(kConfigDir + name);
    ServiceSettings::from_config(root);
    if (std::string(name) == "bwh_detector.yaml") {
      BwhDetectorSettings::from_config(root);
    } else {
      BswhDetectorSettings::from_config(root);
    }
    EXPECT_NO_THROW(root.require_all_read()) << name;
  }
}

TEST(HandConfigs, TheStatusNamesTheMethodInUse) {
  // SERVICE_STATUS.implementation (the monitor's table, lcm-spy) is the detection method the node runs.
  BwhDetectorSettings s = BwhDetectorSettings::from_config(Config::load_file(kConfigDir + "bwh_detector.yaml"));
  EXPECT_EQ(BwhDetectorNode(s).implementation(), "page_faces");
  s.method = "canny_regions";
  EXPECT_EQ(BwhDetectorNode(s).implementation(), "canny_regions");
}

}  // namespace
}  // namespace bookgrasp
