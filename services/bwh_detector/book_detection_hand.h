#pragma once
/// @file
/// BwH core (paper Section 2.2): the books in a hand-camera image, seen from
/// their page edges. Pre-processing against noise and uneven light
/// (illumination normalisation by division with a large-scale background),
/// Canny, regions enclosed by edges, pieces merged when their boundary edges
/// agree in position and slope (a book split by a shadow, a stamp or print),
/// book candidates filtered by shape, size and position relative to the black
/// stripe, a ranking from the right, and for each book its upper-right corner
/// R (on the outer cover edges, sub-pixel) and slope. Pure: cv::Mat in, struct out.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config.h"
#include "services/bswh_detector/stripe_detection.h"

namespace bookgrasp {

/// Parameters of the book detector (every one from configuration).
struct BookDetectionParams {
  double illumination_sigma_px = 40.0;  ///< large-scale background (light) estimate, full-resolution px
  int illumination_scale = 8;           ///< the background is computed on an image this many times smaller
  double blur_sigma_px = 1.5;           ///< smoothing against noise and page-edge texture
  double canny_low = 20.0;              ///< Canny thresholds on the normalised image (mean level 128)
  double canny_high = 50.0;
  int edge_dilate_px = 1;               ///< edges thickened by this radius to close gaps
  int min_piece_area_px = 200;          ///< regions smaller than this are not book pieces
  double min_width_px = 15.0;           ///< book thickness range in the image
  double max_width_px = 250.0;
  double min_height_px = 60.0;          ///< visible height of a book
  double min_fill_ratio = 0.75;         ///< area / (width x height) of a book region
  double max_lean_deg = 15.0;           ///< largest lean of a book side from the image vertical
  double merge_max_offset_px = 6.0;     ///< pieces merge when their side edges meet within this ...
  double merge_max_angle_deg = 4.0;     ///< ... and their slopes agree within this ...
  double merge_max_gap_px = 12.0;       ///< ... and the gap between them is at most this
  double refine_band_px = 10.0;         ///< outward search for the outer (cover) edge from the region's edge
  double refine_sigma_px = 0.7;         ///< smoothing for the sub-pixel edge refinement
  double refine_canny_low = 15.0;       ///< Canny thresholds of the refinement
  double refine_canny_high = 40.0;
  int border_margin_px = 2;             ///< an upper or right edge this close to the border is cut off
  bool use_stripe = true;               ///< reject regions lying above the black stripe when it is seen
  StripeDetectionParams stripe;         ///< how the stripe is found (shared with BSwH)

  /// Reads every field from `cfg` (keys as the field names; the stripe
  /// parameters from `cfg.stripe`). Throws ConfigError naming a bad key.
  static BookDetectionParams from_config(const Config& cfg);
};

/// One book candidate (a merged region) and what was decided about it.
struct BookCandidate {
  int id = 0;                    ///< index in BookDetection::candidates
  cv::Rect bbox;                 ///< bounding box of the region, pixels
  cv::Point2d corner_r;          ///< upper-right corner (outer edges), pixels
  cv::Point2d corner_l;          ///< upper-left corner (outer edges), pixels
  double slope_rad = 0.0;        ///< slope of the upper edge: atan2(dy, dx), positive = descending to the right
  double width_px = 0.0;         ///< thickness of the book perpendicular to its sides
  double height_px = 0.0;        ///< visible height
  double fill_ratio = 0.0;       ///< region area / (width x height)
  int num_merged = 1;            ///< regions merged into it
  bool refined = false;          ///< corner from sub-pixel edge refinement (else from the region outline)
  bool accepted = false;         ///< passes every book criterion
  std::string reject_reason;     ///< why not ("" if accepted)
};

/// Result of book detection in one image.
struct BookDetection {
  bool found = false;                    ///< at least one accepted book
  std::string failure_reason;            ///< why not found ("" if found)
  std::vector<BookCandidate> candidates; ///< every merged candidate, accepted or not
  std::vector<int> ranking;              ///< ids of accepted candidates, right-most (largest R.x) first
  StripeDetection stripe;                ///< the stripe used for the position criterion
};

/// Detects books in a CV_8UC3 (RGB) or CV_8UC1 image. Throws
/// std::invalid_argument for an empty image or another type.
BookDetection detect_books_hand(const cv::Mat& image, const BookDetectionParams& params);

}  // namespace bookgrasp
