// The shipped configuration files load completely (every key read, none unknown) and bad values name the key.
#include <fstream>
#include <iterator>
#include <string>

#include <gtest/gtest.h>

#include "common/config.h"
#include "services/bws_detector/book_front_selection.h"
#include "services/bws_detector/bws_detector_node.h"
#include "services/bws_detector/cart_geometry.h"
#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "services/bws_detector/pcl_plane_segmentation.h"

namespace bookgrasp::bws {
namespace {

using bookgrasp::BwsDetectorSettings;

const std::string kDir = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/";

TEST(BwsConfig, GodFileLoadsCompletely) {
  const Config c = Config::load_file(kDir + "bws_detector.yaml");
  c.mark_read("service");
  const BwsDetectorSettings s = BwsDetectorSettings::from_config(c);
  EXPECT_EQ(s.params.implementation, "god");
  EXPECT_EQ(s.params.god.merge_space, MergeSpace::kImage);
  EXPECT_DOUBLE_EQ(s.params.god.merge_distance, 0.75);
  EXPECT_EQ(s.corner_channel, "BOOK_CORNER_STEREO");
  EXPECT_NO_THROW(c.require_all_read());
}

TEST(BwsConfig, PclFileLoadsCompletely) {
  const Config c = Config::load_file(kDir + "bws_detector_pcl.yaml");
  c.mark_read("service");
  const BwsDetectorSettings s = BwsDetectorSettings::from_config(c);
  EXPECT_EQ(s.params.implementation, "pcl");
  EXPECT_EQ(s.corner_channel, "BOOK_CORNER_STEREO");
  EXPECT_NO_THROW(c.require_all_read());
}

TEST(BwsConfig, BadCartGeometryNamesTheKey) {
  std::string yaml =
      "cart: {marker_role: cart, marker_in_cart_m: [0.359, 0.3, 0.37], upper_shelf_min_m: [0, -0.4, 0], "
      "upper_shelf_max_m: [0.34, 0.4, 0.33], max_marker_age_s: 1.0}";
  EXPECT_NO_THROW(CartGeometry::from_config(Config::from_string(yaml, "t.yaml").child("cart")));
  std::string bad = yaml;
  bad.replace(bad.find("[0.34, 0.4, 0.33]"), 17, "[0.34, -0.5, 0.33]");
  try {
    CartGeometry::from_config(Config::from_string(bad, "t.yaml").child("cart"));
    ADD_FAILURE() << "no error for max < min";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("upper_shelf_max_m"), std::string::npos) << e.what();
  }
}

/// The ConfigError message of Params::from_config on `section` of the YAML text; empty when it loads.
template <typename Params>
std::string config_error(const std::string& yaml, const std::string& section) {
  try {
    Params::from_config(Config::from_string(yaml, "test.yaml").child(section));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

/// The text of a shipped configuration file.
std::string shipped_text(const std::string& file) {
  std::ifstream f(kDir + file);
  return std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
}

/// `text` with the first `from` replaced by `to` (a test failure if `from` is absent).
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(BwsConfig, BadValuesNameTheKey) {
  const auto err = [](const std::string& yaml) { return config_error<GodParams>(yaml, "god"); };
  const std::string ok =
      "god: {gradient_step: 1, smoothing_radius_px: 2, smoothing_max_difference: 1.0, direction_bins: 16, "
      "flat_mgod_max: 0.0, window_size: 5, jump_mgod_min: 0.6, jump_min_curvature: 0.0, "
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
  bad = ok;
  bad.replace(bad.find("smoothing_radius_px: 2"), 22, "smoothing_radius_px: -1");
  EXPECT_NE(err(bad).find("smoothing_radius_px"), std::string::npos);
  bad = ok;
  bad.replace(bad.find(" smoothing_max_difference: 1.0,"), 31, "");
  EXPECT_NE(err(bad).find("smoothing_max_difference"), std::string::npos);
  bad = ok;
  bad.replace(bad.find("jump_min_curvature: 0.0"), 23, "jump_min_curvature: -0.6");
  EXPECT_NE(err(bad).find("jump_min_curvature"), std::string::npos);
  bad = ok;
  bad.replace(bad.find(" jump_min_curvature: 0.0,"), 25, "");
  EXPECT_NE(err(bad).find("jump_min_curvature"), std::string::npos);
}

TEST(BwsConfig, BadSelectionValuesNameTheKey) {
  const auto err = [](const std::string& text) { return config_error<SelectionParams>(text, "selection"); };
  const std::string ok = shipped_text("bws_detector.yaml");
  EXPECT_EQ(err(ok), "");
  EXPECT_NE(err(replaced(ok, "pi_rule: right_column_top", "pi_rule: leftmost")).find("pi_rule"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "top_growth_px: 80", "top_growth_px: -1")).find("top_growth_px"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "top_growth_disparity_px: 0.75", "top_growth_disparity_px: nan"))
                .find("top_growth_disparity_px"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "top_growth_columns: 3", "top_growth_columns: 0")).find("top_growth_columns"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  top_growth_columns: 3", "  # gone")).find("top_growth_columns"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "top_growth_climbed_only: true", "top_growth_climbed_only: maybe"))
                .find("top_growth_climbed_only"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  top_growth_climbed_only: true", "  # gone")).find("top_growth_climbed_only"),
            std::string::npos);
  // Whatever value ships: -2 is below the -1 that means "counted with the rows off the plane".
  EXPECT_NE(err(replaced(ok, "top_growth_max_hole_px:", "top_growth_max_hole_px: -2 #")).find("top_growth_max_hole_px"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  top_growth_max_hole_px:", "  # gone:")).find("top_growth_max_hole_px"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "layer_disparity_px:", "layer_disparity_px: -0.5 #")).find("layer_disparity_px"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  layer_disparity_px:", "  # gone:")).find("layer_disparity_px"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "layer_min_rows:", "layer_min_rows: 0 #")).find("layer_min_rows"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "layer_min_columns:", "layer_min_columns: many #")).find("layer_min_columns"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  layer_min_shift_px:", "  # gone:")).find("layer_min_shift_px"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "layer_without_front_m:", "layer_without_front_m: -0.01 #")).find("layer_without_front_m"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "  layer_without_front_m:", "  # gone:")).find("layer_without_front_m"),
            std::string::npos);
  EXPECT_NE(err(replaced(ok, "front_plane: rear_board", "front_plane: cart")).find("front_plane"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "  front_plane:", "  # gone:")).find("front_plane"), std::string::npos);
  EXPECT_EQ(err(replaced(ok, "front_plane: rear_board", "front_plane: region")), "");
}

TEST(BwsConfig, BadPclSpaceValuesNameTheKey) {
  const auto err = [](const std::string& text) { return config_error<PclPlaneParams>(text, "pcl"); };
  const std::string ok = shipped_text("bws_detector_pcl.yaml");
  EXPECT_EQ(err(ok), "");
  EXPECT_NE(err(replaced(ok, "space: image", "space: metres")).find("space"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "disparity_scale: 1.0", "disparity_scale: 0")).find("disparity_scale"), std::string::npos);
  EXPECT_NE(err(replaced(ok, "  disparity_scale: 1.0", "  # gone")).find("disparity_scale"), std::string::npos);
}

}  // namespace
}  // namespace bookgrasp::bws
