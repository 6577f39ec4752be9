// The shipped configuration files load completely (every key read, none unknown) and bad values name the key.
#include <string>

#include <gtest/gtest.h>

#include "common/config.h"
#include "services/bws_detector/book_front_selection.h"
#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "services/bws_detector/pcl_plane_segmentation.h"

namespace bookgrasp::bws {
namespace {

const std::string kDir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";

TEST(BwsConfig, GodFileLoadsCompletely) {
  const Config c = Config::load_file(kDir + "bws_detector.yaml");
  c.mark_read("service");
  c.mark_read("channels");
  DisparityParams::from_config(c.child("disparity"));
  const GodParams g = GodParams::from_config(c.child("god"));
  EXPECT_EQ(g.merge_space, MergeSpace::kImage);
  EXPECT_DOUBLE_EQ(g.merge_distance, 0.75);
  SelectionParams::from_config(c.child("selection"));
  EXPECT_NO_THROW(c.require_all_read());
}

TEST(BwsConfig, PclFileLoadsCompletely) {
  const Config c = Config::load_file(kDir + "bws_detector_pcl.yaml");
  c.mark_read("service");
  c.mark_read("channels");
  DisparityParams::from_config(c.child("disparity"));
  PclPlaneParams::from_config(c.child("pcl"));
  SelectionParams::from_config(c.child("selection"));
  EXPECT_NO_THROW(c.require_all_read());
}

TEST(BwsConfig, BadValuesNameTheKey) {
  const auto err = [](const std::string& yaml) {
    try {
      GodParams::from_config(Config::from_string(yaml, "test.yaml").child("god"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string ok =
      "god: {gradient_step: 1, direction_bins: 16, flat_mgod_max: 0.0, window_size: 5, jump_mgod_min: 0.6, "
      "merge_distance: 0.75, merge_space: image, merge_max_angle_deg: 30, merge_angle_min_px: 100, "
      "adjacency_radius_px: 2, boundary_growth_px: 2, boundary_growth_distance: 0.25, min_region_px: 30}";
  EXPECT_EQ(err(ok), "");
  std::string bad = ok;
  bad.replace(bad.find("merge_space: image"), 18, "merge_space: metres");
  EXPECT_NE(err(bad).find("merge_space"), std::string::npos);
  bad = ok;
  bad.replace(bad.find("window_size: 5"), 14, "window_size: 4");
  EXPECT_NE(err(bad).find("window_size"), std::string::npos);
  bad = ok;
  bad.replace(bad.find(", min_region_px: 30"), 19, "");
  EXPECT_NE(err(bad).find("min_region_px"), std::string::npos);
}

}  // namespace
}  // namespace bookgrasp::bws
