#pragma once
/// @file
/// Candidate extraction and the corner P1 (paper Section 2.1): from a planar
/// segmentation and the stereo geometry, keep the regions that can be the
/// front (fore-edge) of a book on the upper shelf, take the right-most one,
/// find its upper-right image corner PI and turn it into P1 in `base`.
///
/// Image convention: x = column (right), y = row (down). The paper's
/// PI = (Y_min, X_max) is the pixel (x = largest column of the region,
/// y = smallest row of the region), i.e. the top-right corner of the region's
/// bounding box. If that pixel is not in the region, PI is the region pixel
/// nearest to it (Euclidean in pixels; ties: smaller row, then larger column).
/// P1 is where the viewing ray through the centre of PI meets the region's
/// fitted plane (so a noisy disparity at PI itself does not matter); if the
/// ray is nearly parallel to the plane, the region's 3D point at PI is used.

#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "services/bws_detector/disparity.h"
#include "services/bws_detector/plane_region.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// The upper-shelf volume: an oriented box in `base` (later from the cart
/// marker). Box axes: x = normal of the cart's rear board, y = along the
/// shelf, z = normal of the shelf board (up). Books stand inside it.
struct ShelfVolume {
  /// Pose of the box centre and axes in `base`.
  Eigen::Isometry3d box_in_base = Eigen::Isometry3d::Identity();
  /// Half sizes along the box axes, metres.
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();
};

/// How PI is found in the selected region (config `selection.pi_rule`).
enum class PiRule {
  /// The paper's (Y_min, X_max), or the nearest region pixel to it (upper_right_corner).
  kPaper,
  /// The top of the region's right-most well-filled column (right_column_top): the right-most book's
  /// own top even when a taller front to its left is part of the same region or band.
  kRightColumnTop,
};

/// Thresholds of the book-front tests (config section `selection`).
struct SelectionParams {
  /// Max angle between the region normal and the rear-board normal (box x), degrees.
  double parallel_tolerance_deg = 15.0;
  /// Max deviation from 90 deg between the region normal and the shelf normal (box z), degrees.
  double perpendicular_tolerance_deg = 15.0;
  /// Width of a book front along the shelf (box y), metres: [min, max].
  double min_width_m = 0.005;
  /// See min_width_m.
  double max_width_m = 0.08;
  /// Height of a book front (box z), metres: [min, max].
  double min_height_m = 0.08;
  /// See min_height_m.
  double max_height_m = 0.40;
  /// Fraction of the region's 3D points that must lie inside the shelf volume.
  double min_inside_fraction = 0.8;
  /// Regions with fewer pixels are dropped before any other test.
  int min_pixels = 30;
  /// Extents are measured between these quantiles of the points (robust to stray pixels), e.g. 0.02.
  double extent_quantile = 0.02;
  /// Split regions that pass the orientation and volume tests but are too wide (several coplanar
  /// book fronts standing side by side merge into one plane) into column bands, one per book.
  bool split_wide_fronts = true;
  /// A new band starts where the region's top contour jumps by more than this (pixels) between
  /// neighbouring columns (books of different heights) ...
  int split_top_jump_px = 4;
  /// ... or where the median depth along the rear-board normal of neighbouring columns differs by
  /// more than this (metres; fore-edges at different depths), or at a column without region pixels.
  double split_depth_step_m = 0.008;
  /// How PI is found in the selected region or band.
  PiRule pi_rule = PiRule::kRightColumnTop;
  /// PI then moves up its column over at most this many pixels whose stereo depth agrees with the
  /// front's plane (raise_to_plane_top; 0 = off): the segmentation often leaves the top of a narrow
  /// front to a region mixed with the book's top face.
  int top_growth_px = 0;
  /// Agreement with the plane for that growth, disparity pixels.
  double top_growth_disparity_px = 0.3;
  /// Rows without stereo depth or off the plane (StereoBM's holes and outliers) bridged in a row by that
  /// growth.
  int top_growth_max_gap_px = 3;
  /// PI's new row is the median of the grown tops of this many columns ending at PI's.
  int top_growth_columns = 3;
  /// ... of those that climbed more than top_growth_max_gap_px rows, when any did: a thin front's page face
  /// has no stereo depth inside its border columns, which then stay at the region's top and outvote the
  /// border column that follows the front up (docs/BWS.md "The top over the columns that climbed").
  bool top_growth_climbed_only = false;
  /// P1's viewing ray passes this many pixels left of and below PI: block matching extends a near
  /// surface into a farther background by up to half a block ((block_size - 1) / 2), and the
  /// right-most front's right and top edges border a farther background. 0 = the ray through PI.
  double edge_fattening_px = 0.0;

  /// Reads every key of the `selection` section.
  static SelectionParams from_config(const Config& section);
};

/// The verdict on one region, with the measures it was judged by.
struct RegionVerdict {
  /// Label in the segmentation.
  int label = 0;
  /// True if the region passed every book-front test.
  bool candidate = false;
  /// Why the region was dropped (empty for a candidate).
  std::string reason;
  /// Plane normal in base (unit) and offset (normal . p = offset, metres).
  Eigen::Vector3d normal_base = Eigen::Vector3d::Zero();
  /// See normal_base.
  double offset_base = 0.0;
  /// Centroid of the region's points in base, metres.
  Eigen::Vector3d centroid_base = Eigen::Vector3d::Zero();
  /// Axis-aligned extent in base (quantiles of the points), metres.
  Eigen::Vector3d extent_min_base = Eigen::Vector3d::Zero();
  /// See extent_min_base.
  Eigen::Vector3d extent_max_base = Eigen::Vector3d::Zero();
  /// Extent along the shelf (box y) and up (box z), metres.
  double width_m = 0.0;
  /// See width_m.
  double height_m = 0.0;
  /// Fraction of the region's points inside the shelf volume.
  double inside_fraction = 0.0;
  /// For a region split into column bands (see SelectionParams::split_wide_fronts): one entry per
  /// band, "[x0, x1] w W h H: ok" or the test it failed. Empty otherwise.
  std::string bands;
};

/// Result of the selection.
struct BookFrontResult {
  /// True if a book front was found.
  bool found = false;
  /// Why not (empty when found).
  std::string failure_reason;
  /// Label of the selected region (0 if none).
  int selected_label = 0;
  /// PI in the left image (column, row).
  cv::Point pi{-1, -1};
  /// True if (Y_min, X_max) was outside the region and the nearest region pixel was taken.
  bool pi_fallback = false;
  /// P1 in the left camera frame and in base, metres.
  Eigen::Vector3d p1_camera = Eigen::Vector3d::Zero();
  /// See p1_camera.
  Eigen::Vector3d p1_base = Eigen::Vector3d::Zero();
  /// One verdict per region of the segmentation, in label order.
  std::vector<RegionVerdict> regions;
  /// True if the selected book front is a column band of a wider region (see split_wide_fronts);
  /// columns [band_x0, band_x1] of the selected region.
  bool split = false;
  /// See split.
  int band_x0 = -1;
  /// See split.
  int band_x1 = -1;
};

/// The paper's PI of a region: (Y_min, X_max) or the nearest region pixel (see the file comment).
/// `fallback` (optional) tells which case applied. Throws std::invalid_argument if the label is absent.
cv::Point upper_right_corner(const cv::Mat& labels, int label, bool* fallback = nullptr);

/// PI as the top of the right-most well-filled column of `label`: the right-most column holding at
/// least 3 region pixels (or as many as the fullest column holds, if fewer; one or two stray pixels at
/// the region's right border do not count), and in it the topmost region pixel whose lower neighbour
/// is in the region too (the topmost pixel when none is). Throws std::invalid_argument if the label
/// is absent.
cv::Point right_column_top(const cv::Mat& labels, int label);

/// Moves `pi` up to the top of the front's plane as the stereo depth sees it. In each of `columns`
/// columns ending at pi.x (those holding region pixels), from the column's topmost region pixel, rows
/// above are taken while the pixel's disparity (fx B / z of `points_camera`) is within `tolerance_px`
/// of the disparity of the plane { p : normal . p = offset } (left camera frame, metres) on that
/// pixel's ray, up to `max_gap_px` pixels in a row without depth or off the plane bridged (StereoBM
/// leaves holes and outliers on a narrow front), at most `max_px` rows; the result keeps pi.x and
/// takes the median of the columns' tops (never lower than pi.y). With `climbed_only`, the median of the
/// tops of the columns that climbed more than `max_gap_px` rows, when any did.
cv::Point raise_to_plane_top(const cv::Mat& labels, int label, cv::Point pi, const cv::Mat& points_camera,
                             const Eigen::Vector3d& normal, double offset, const StereoGeometry& geometry,
                             double tolerance_px, int max_px, int max_gap_px, int columns, bool climbed_only = false);

/// Runs the book-front tests on every region of `segmentation` (planes in the
/// left camera frame, metres), picks the right-most candidate (smallest base y
/// of its centroid) and computes PI and P1. `points_camera` are the left-camera
/// points the segmentation was fitted to (CV_32FC3, metres).
BookFrontResult select_book_front(const SegmentationResult& segmentation, const cv::Mat& points_camera,
                                  const StereoGeometry& geometry, const Eigen::Isometry3d& camera_in_base,
                                  const ShelfVolume& shelf, const SelectionParams& params);

}  // namespace bookgrasp::bws
