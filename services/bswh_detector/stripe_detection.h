#pragma once
/// @file
/// BSwH core (paper Section 2.3): the black stripe on the cart's rear board in
/// a hand-camera image, found by threshold segmentation against the local
/// background, and its end where the right-most book hides it, located on
/// Canny edges with sub-pixel refinement. Pure: cv::Mat in, struct out.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config.h"

namespace bookgrasp {

/// Parameters of the stripe detector (every one from configuration).
struct StripeDetectionParams {
  double blur_sigma_px = 1.2;     ///< Gaussian pre-smoothing against noise
  int background_scale = 8;       ///< background estimated on an image this many times smaller
  int background_kernel_px = 64;  ///< closing size (full-resolution px) removing dark structures for the background
  /// Width of that closing (full-resolution px; 0 = background_kernel_px, a square). Narrow: only dark structures
  /// thinner than background_kernel_px vertically (the stripe, a cover's top) leave the background; tall ones (a
  /// standing book's shadow on the rear board, a dark cover) stay in it and are not taken for the stripe.
  int background_kernel_width_px = 0;
  double dark_ratio = 0.5;        ///< a pixel is stripe if value < dark_ratio * local background ...
  int max_dark_value = 90;        ///< ... and value (max of R, G, B) < this ...
  /// ... and, in a colour image, not in a dark area (>= 5 px across) where max(R, G, B) - min(R, G, B), smoothed
  /// as the value, exceeds this: the stripe is a neutral black, so a coloured dark cover's top beside it (a navy
  /// book's, 20 grey levels apart) is not stripe. 255 = no colour check (grey images always).
  int max_dark_spread = 255;
  int min_length_px = 40;         ///< shortest visible stripe segment
  double min_thickness_px = 4.0;  ///< stripe thickness range (perpendicular), pixels
  double max_thickness_px = 80.0;
  double max_angle_deg = 20.0;  ///< largest angle of the stripe to the image x axis
  double edge_sigma_px = 0.7;   ///< lighter smoothing for locating the end edge (keeps a thin cover apart)
  double canny_low = 30.0;      ///< Canny hysteresis thresholds for the end edge
  double canny_high = 80.0;
  int border_margin_px = 3;       ///< an end this close to the image border is not the stripe's end
  std::string end_side = "left";  ///< side of the visible segment where the books hide the stripe
  int ignore_bottom_rows = 0;     ///< rows at the image bottom ignored (the gripper fingers, fixed in the hand image)
  bool reject_touching_bottom = false;  ///< a dark region reaching the (unignored) bottom is not the stripe
                                        ///< (shadows on the shelf, the fingers' shadow)
  double min_band_fill = 0.0;      ///< band columns (count within 0.5..1.5 x median) / bounding-box width, at least
  double expected_row_px = -1.0;   ///< the stripe's centre row when the TCP is at stripe height (servo); < 0: anywhere
  double max_row_offset_px = 1e9;  ///< with expected_row_px: segments whose centre row (at the image centre
                                   ///< column) is farther than this are not the stripe

  /// Reads every field from `cfg` (keys as the field names). Throws ConfigError naming a bad key.
  static StripeDetectionParams from_config(const Config& cfg);
};

/// Result of stripe detection in one image. Coordinates are pixels, x right,
/// y down, pixel centres at integer coordinates.
struct StripeDetection {
  bool found = false;          ///< a stripe segment was found
  bool end_found = false;      ///< its end (on end_side) lies inside the image
  std::string failure_reason;  ///< why found or end_found is false ("" otherwise)
  cv::Point2d end;             ///< the stripe end on its centre line (valid if end_found)
  cv::Point2d line_start;      ///< centre line at the visible segment's left end
  cv::Point2d line_end;        ///< centre line at the visible segment's right end
  double angle_rad = 0.0;      ///< angle of the centre line to the x axis (positive = descending to the right)
  double thickness_px = 0.0;   ///< perpendicular thickness
  int end_edge_support = 0;    ///< rows of Canny edge that located the end (0 = threshold estimate only)
  /// The centre line's y at image column x.
  double centre_y_at(double x) const;
};

/// Finds the stripe in a CV_8UC3 (RGB or BGR: the max channel is used) or
/// CV_8UC1 image. Throws std::invalid_argument for an empty image or another type.
StripeDetection detect_stripe(const cv::Mat& image, const StripeDetectionParams& params);

/// Value image used by the detectors: max of the colour channels (CV_8UC1),
/// or the image itself if it is grey. Black stays dark, coloured covers do not.
cv::Mat max_channel(const cv::Mat& image);

}  // namespace bookgrasp
