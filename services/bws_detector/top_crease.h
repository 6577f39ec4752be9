#pragma once
/// The height of a book front's top edge from the disparity around it.
///
/// The stereo camera looks down onto the shelf, so above the right-most front's top edge it sees the
/// same book's top face: a horizontal surface whose disparity near the edge equals the front's. The
/// edge is a crease (the surface turns), not a depth jump, and growing PI up "while the disparity
/// agrees with the front's plane" climbs onto the top face by a few rows (P1 4-6 mm too high in X on
/// most scenes) or stops short of it at a hole. fit_top_crease fits the box model instead: below the
/// edge height h the pixel sees the front's plane, above it the horizontal plane at h. The best h over
/// a window of pixels around PI (a truncated squared disparity residual, so a farther background costs
/// a constant) is the top edge's height (docs/BWS.md "The top's crease").

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "services/bws_detector/disparity.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Window, search range and acceptance of fit_top_crease (config keys `selection.top_crease_*`; the defaults
/// are the shipped values).
struct TopCreaseParams {
  /// Off: P1 keeps the height of PI's ray.
  bool enabled = false;
  /// Columns of the window: this many ending `right_margin_px` left of PI's column ...
  int columns = 10;
  /// ... (the front's right border, fattened by block matching, stays out).
  int right_margin_px = 2;
  /// Rows of the window: from this many above the row of the highest height searched ...
  int rows_above = 12;
  /// ... to this many below the row of the lowest.
  int rows_below = 12;
  /// Heights searched: from this far below the start (PI's P1) ...
  double search_down_m = 0.03;
  /// ... to this far above it, metres ...
  double search_up_m = 0.05;
  /// ... in steps of this, metres.
  double step_m = 0.0005;
  /// A pixel's squared disparity residual is capped at this squared (disparity px): a farther
  /// background, a neighbour or an outlier costs a constant.
  double residual_cap_px = 0.5;
  /// The fit is used only when at least this many window pixels agree (residual below the cap) on
  /// each side of the edge: on the front below it and on the top face above it.
  int min_pixels_each_side = 8;
  /// ... and only when the right-most this many of the window's columns of the front, fitted alone, find a
  /// height within max_right_difference_m of the columns left of them, fitted alone ...
  int right_columns = 3;
  /// ... (metres; 0 = not checked; a single column is not checked): a thin front's window reaches into a
  /// taller neighbour, whose top the right-most columns do not share.
  double max_right_difference_m = 0.01;

  /// Reads the `top_crease_*` keys of the `selection` section.
  static TopCreaseParams from_config(const Config& selection);
};

/// The crease found (or why none).
struct TopCrease {
  /// True if both sides held enough agreeing pixels.
  bool found = false;
  /// Height of the edge, `up . p` in the left camera frame, metres.
  double height = 0.0;
  /// Agreeing pixels below the edge (on the front) and above it (on the top face) at the best height.
  int front_pixels = 0;
  /// See front_pixels.
  int top_pixels = 0;
  /// The best heights of the window's columns of the front left of the right-most right_columns, and of
  /// those right-most columns, each fitted alone (the lowest height searched for a part without pixels).
  double left_height = 0.0;
  /// See left_height.
  double right_height = 0.0;
};

/// The direction up the front's plane { normal . p = offset }: `up` without its part along the (unit)
/// `normal`, not normalised (up . v = 1 - (up . normal)^2; zero when the front lies flat).
Eigen::Vector3d up_within_plane(const Eigen::Vector3d& up, const Eigen::Vector3d& normal);

/// Fits the front's top edge near PI. The front is the plane { normal . p = offset } and the top face
/// the plane { up . p = h } (left camera frame; `up` is the shelf's normal, pointing up, unit). The
/// window is TopCreaseParams' columns left of `pi` and the rows around the heights searched, which
/// start at `start_height` (up . p of PI's P1); pixels of `points_camera` (CV_32FC3, NaN = no depth)
/// outside `columns_mask` (CV_8U, non-zero = a column of the front; empty = every column) stay out.
/// Throws std::invalid_argument for a points image of the wrong type.
TopCrease fit_top_crease(const cv::Mat& points_camera, const StereoGeometry& g, const Eigen::Vector3d& normal,
                         double offset, const Eigen::Vector3d& up, cv::Point pi, double start_height,
                         const cv::Mat& columns_mask, const TopCreaseParams& p);

}  // namespace bookgrasp::bws
