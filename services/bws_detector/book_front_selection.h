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
/// P1 is where the viewing ray through the centre of PI meets the front's
/// plane (so a noisy disparity at PI itself does not matter): the region's
/// fitted plane (the paper's) or the plane parallel to the rear board through
/// the front's points (SelectionParams::front_plane); if the ray is nearly
/// parallel to the plane, the region's 3D point at PI is used.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "services/bws_detector/disparity.h"
#include "services/bws_detector/plane_region.h"
#include "services/bws_detector/top_crease.h"

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

/// The plane P1 lies on, for a front selected from a region (config `selection.front_plane`); the front layer
/// always uses the rear board's.
enum class FrontPlane {
  /// The region's own fitted plane: the paper's.
  kRegion,
  /// The plane parallel to the cart's rear board (its normal from the cart marker) through the median of the
  /// selected front's points: a front that passed the parallel test is taken as parallel, so pixels of a top
  /// face or a neighbour's cover in the region do not tilt it (the region's plane put P1 1.6 mm too deep on
  /// average, docs/BWS.md "The front's plane").
  kRearBoard,
};

/// How raise_to_plane_top moves PI up its column to the top of the front's plane (config keys
/// `selection.top_growth_*`).
struct TopGrowthParams {
  /// At most this many rows above the region's top (0 = off).
  int max_px = 0;
  /// Agreement of a pixel's disparity with the plane's on its ray, disparity pixels.
  double disparity_px = 0.3;
  /// Rows off the plane (StereoBM's outliers, or the book's top face) bridged in a row; also rows without
  /// depth when max_hole_px is -1.
  int max_gap_px = 3;
  /// Rows without stereo depth bridged in a row, counted apart from the rows off the plane: a page face's
  /// sparse texture leaves StereoBM holes 6-22 rows tall inside a front (docs/BWS.md "Holes in the
  /// front, the front layer"). -1 = counted with the rows off the plane, against max_gap_px.
  int max_hole_px = -1;
  /// PI's new row is the median of the grown tops of this many columns ending at PI's ...
  int columns = 3;
  /// ... of those that climbed more than max_gap_px rows, when any did: a thin front's page face has no
  /// stereo depth inside its border columns, which then stay at the region's top and outvote the border
  /// column that follows the front up (docs/BWS.md "The top over the columns that climbed").
  bool climbed_only = false;
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
  /// How PI then moves up to the top of the front's plane (raise_to_plane_top): the segmentation often
  /// leaves the top of a narrow front to a region mixed with the book's top face.
  TopGrowthParams top_growth;
  /// The front layer (0 = off): after PI is found, the pixels inside the upper-shelf volume whose
  /// disparity is within this (disparity px) of the plane parallel to the rear board through the
  /// selected front's pixels are the fronts' layer. When its right-most front (the right-most run of
  /// columns below, as tall as a book above the volume's floor, with a level top) lies right of PI, PI
  /// moves to its top and P1 onto the layer's plane there. The right-most front often breaks into
  /// regions that each fail the tests while a front further left passes, but the fronts stand in one
  /// plane (docs/BWS.md "Holes in the front, the front layer").
  double layer_disparity_px = 0.0;
  /// A layer column counts with at least this many layer pixels ...
  int layer_min_rows = 15;
  /// ... and this many such columns side by side ...
  int layer_min_columns = 2;
  /// ... and moves PI only when it lies more than this many columns right of PI.
  int layer_min_shift_px = 3;
  /// When no region passes the tests (0 = off): the layer's plane (parallel to the rear board) is placed
  /// where the points inside the upper-shelf volume lie densest along the rear board's normal, in a
  /// window this deep (metres), and PI is the layer's right-most front. Fronts face the camera and stand
  /// 0-2 cm apart in depth, while top faces spread over the shelf's depth; a far cart's fronts are only
  /// a few pixels wide, too narrow for the segmentation (docs/BWS.md "A layer when no front passes").
  double layer_without_front_m = 0.0;
  /// P1's viewing ray passes this many pixels left of and below PI: block matching extends a near
  /// surface into a farther background by up to half a block ((block_size - 1) / 2), and the
  /// right-most front's right and top edges border a farther background. 0 = the ray through PI.
  double edge_fattening_px = 0.0;
  /// The plane the top's growth climbs and P1's ray meets, for a front selected from a region.
  FrontPlane front_plane = FrontPlane::kRegion;
  /// Then P1's height from the crease between the front and the book's top face (fit_top_crease).
  TopCreaseParams top_crease;

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
  /// True if PI moved right onto the front layer (SelectionParams::layer_disparity_px).
  bool pi_from_layer = false;
  /// How far the top's crease moved P1 up its front (metres, negative = down); NaN when the crease was
  /// not fitted or not found (SelectionParams::top_crease).
  double top_crease_shift_m = std::numeric_limits<double>::quiet_NaN();
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

/// Moves `pi` up to the top of the front's plane as the stereo depth sees it. In each of `t.columns`
/// columns ending at pi.x (those holding region pixels), from the column's topmost region pixel, rows
/// above are taken while the pixel's disparity (fx B / z of `points_camera`) is within `t.disparity_px`
/// of the disparity of the plane { p : normal . p = offset } (left camera frame, metres) on that
/// pixel's ray, bridging up to `t.max_gap_px` rows in a row off the plane and `t.max_hole_px` without
/// depth (both counted since the last row on the plane; with -1 the holes count as rows off the plane),
/// at most `t.max_px` rows. The result keeps pi.x and takes the median of the columns' tops (never lower
/// than pi.y); see TopGrowthParams for `climbed_only`.
cv::Point raise_to_plane_top(const cv::Mat& labels, int label, cv::Point pi, const cv::Mat& points_camera,
                             const Eigen::Vector3d& normal, double offset, const StereoGeometry& geometry,
                             const TopGrowthParams& t);

/// Runs the book-front tests on every region of `segmentation` (planes in the
/// left camera frame, metres), picks the right-most candidate (smallest base y
/// of its centroid) and computes PI and P1. `points_camera` are the left-camera
/// points the segmentation was fitted to (CV_32FC3, metres).
BookFrontResult select_book_front(const SegmentationResult& segmentation, const cv::Mat& points_camera,
                                  const StereoGeometry& geometry, const Eigen::Isometry3d& camera_in_base,
                                  const ShelfVolume& shelf, const SelectionParams& params);

}  // namespace bookgrasp::bws
