#pragma once
/// @file
/// BwH on rendered (and real) hand images seen from the grasp approach: the
/// books' fore-edges (page edges) are the only bright, unsaturated surfaces
/// between the cart's wooden boards and the covers, and every fore-edge runs
/// down to the shelf, below the image. So:
///  1. a page mask: HSV saturation below max_saturation and value above
///     min_value (after a small blur against noise); shadows keep the low
///     saturation, stamps and print make holes that the line fits ignore;
///  2. connected components of the mask (4-connected, so cover strips between
///     neighbouring fore-edges separate them) below the ignored bottom band (the
///     gripper plates);
///  3. book criteria with reasons: reaches the bottom band (a fore-edge stands
///     on the shelf: removes the marker's white cells and the backdrop), does
///     not touch the top border, height and width ranges, fill ratio;
///  4. R from trimmed line fits of the top edge (top-most mask pixel per column)
///     and the right side (right-most mask pixel per row just below the top)
///     intersected: a stamp or shadow cutting the corner does not move R; the
///     slope from the top-edge fit;
///  5. ranking by R.x, right-most first.
/// Pure: cv::Mat in, BookDetection out.

#include <opencv2/core.hpp>

#include "common/config.h"
#include "services/bwh_detector/book_detection_hand.h"

namespace bookgrasp {

/// Parameters of the page-face detector (every one from configuration).
struct PageFaceParams {
  double blur_sigma_px = 1.0;      ///< smoothing before the colour test
  int max_saturation = 60;         ///< page pixel: HSV S (0..255) below this ...
  int min_value = 45;              ///< ... and V (0..255) above this
  int open_px = 1;                 ///< morphological opening radius (noise specks)
  int close_vertical_px = 45;      ///< vertical closing: bridges stamps and print across a fore-edge
  double split_step_px = 4.0;      ///< a jump of the top edge between neighbouring columns larger than
                                   ///< this splits touching fore-edges of different heights
  int ignore_bottom_px = 24;       ///< bottom rows ignored (gripper plates in view)
  int bottom_reach_px = 6;         ///< a fore-edge must reach this close to the ignored band
  double min_width_px = 6.0;       ///< book thickness range at the top edge
  double max_width_px = 260.0;
  double min_height_px = 40.0;     ///< visible fore-edge height
  double min_fill_ratio = 0.6;     ///< area / (width x height)
  int top_margin_px = 2;           ///< a component this close to the top border is cut off (not a book top)
  double fit_trim_px = 1.5;        ///< residual beyond which boundary points are dropped from the line fits
  double side_fit_rows_px = 60.0;  ///< rows below the top used for the right-side fit

  /// Reads every field from `cfg`. Throws ConfigError naming a bad key.
  static PageFaceParams from_config(const Config& cfg);
};

/// Detects the books' fore-edges in a CV_8UC3 RGB image. Throws
/// std::invalid_argument for an empty image or another type.
BookDetection detect_books_page_faces(const cv::Mat& rgb, const PageFaceParams& params);

}  // namespace bookgrasp
