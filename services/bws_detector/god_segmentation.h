#pragma once
/// @file
/// Gradient-of-Depth (GoD) planar segmentation, paper Section 2.1 (eq. 1, 2
/// and Figure 3): DGoD/MGoD features, voting-histogram clustering, removal of
/// jump-edge pixels, connected regions, iterative plane merging. A pure
/// library: works on any CV_32F depth-like image (disparity, depth, range).
///
/// DGoD representation (degrees, image axes: x right = column, y down = row):
///   - NaN      : no feature (pixel or one of its four gradient neighbours invalid, or image border);
///   - 0        : "flat", the region is parallel to the image plane (MGoD <= flat_mgod_max; the paper's 0 deg);
///   - (0, 360] : direction atan2(dy, dx) of the gradient, full quadrant; dy = 0, dx > 0 gives exactly 360
///                (the paper's 360 deg), so 0 never means a direction.
/// In the voting histogram direction bins are centred on k * 360/B (bin 0 centred on 360 deg, so
/// directions just above 0 and just below 360 share a bin) and "flat" is its own extra bin B.

#include <string>

#include <opencv2/core.hpp>

#include "services/bws_detector/plane_region.h"

namespace bookgrasp {
class Config;
}

namespace bookgrasp::bws {

/// Space in which the merge criterion's point-to-plane distance is measured.
enum class MergeSpace {
  /// (x, y, image value): pixels and image units (disparity pixels for a disparity image).
  /// A 3D plane is a plane in (x, y, disparity); stereo noise is uniform in it.
  kImage,
  /// The caller's 3D points (e.g. metres in the camera frame).
  kPoints,
};

/// Parameters of the GoD segmentation (all from config, section `god`).
struct GodParams {
  /// Gradient half-step s: dx = P(y, x+s) - P(y, x-s), dy = P(y+s, x) - P(y-s, x). The paper uses 1.
  int gradient_step = 1;
  /// Radius r of the smoothing of the image the gradients are taken from (smooth_valid_values);
  /// 0 = none (the paper). Planes, the merge and the output use the unsmoothed image.
  int smoothing_radius_px = 0;
  /// Neighbours whose value differs from the centre's by more than this (image units) are left out of
  /// the smoothing, so that a jump edge does not become a ramp.
  double smoothing_max_difference = 1.0;
  /// Number of direction bins B of the voting histogram (the flat bin comes on top).
  int direction_bins = 16;
  /// Pixels with MGoD <= this are "flat" (DGoD = 0); 0 = only exactly zero gradients (the paper).
  double flat_mgod_max = 0.0;
  /// n of the n x n voting neighbourhood (odd).
  int window_size = 7;
  /// Pixels with MGoD > this are jump edges: they neither vote nor get a cluster (image units).
  double jump_mgod_min = 1.0;
  /// > 0: a pixel with MGoD > jump_mgod_min is a jump edge only where the gradient also changes across it,
  /// max(|P(y,x+s) - 2P(y,x) + P(y,x-s)|, |P(y+s,x) - 2P(y,x) + P(y-s,x)|) > this (image units); elsewhere it is a
  /// steep plane (a surface seen at a grazing angle) and votes with its direction. 0 = MGoD alone (the paper).
  double jump_min_curvature = 0.0;
  /// T_dis: two adjacent regions merge when the RMS distance of the smaller region's points to the
  /// larger region's plane is below this (unit of merge_space).
  double merge_distance = 0.75;
  /// Where merge_distance is measured.
  MergeSpace merge_space = MergeSpace::kImage;
  /// Orientation gate of the merge: when both regions have at least merge_angle_min_px points, their
  /// planes (fitted to the output points, e.g. metres) must be within this angle to merge. T_dis alone
  /// cannot tell a thin perpendicular strip (a book's side face seen at a grazing angle, a board's edge)
  /// from the plane it borders: its points are all within T_dis of that plane. 90 disables the gate.
  double merge_max_angle_deg = 30.0;
  /// See merge_max_angle_deg.
  int merge_angle_min_px = 100;
  /// Regions are adjacent if two of their pixels are within this Chebyshev distance (>= 1).
  int adjacency_radius_px = 2;
  /// After merging, unlabeled valid pixels next to a region join it (nearest plane within
  /// merge_distance) for up to this many dilation steps; 0 disables (the paper has no such step).
  int boundary_growth_px = 2;
  /// Max distance (merge-space unit) of a pixel to the plane of the region it grows into. Smaller than
  /// merge_distance: grazing strips next to a plane are within T_dis of it but must not join it.
  double boundary_growth_distance = 0.25;
  /// Regions with fewer pixels are dropped from the output.
  int min_region_px = 50;

  /// Reads every key of the `god` section (names the key on a bad value).
  static GodParams from_config(const Config& section);
  /// Throws std::invalid_argument naming the field if a value is out of range.
  void validate() const;
};

/// The two GoD components of every pixel.
struct GodFeatures {
  /// CV_32F DGoD in degrees (see the file comment for the representation).
  cv::Mat dgod;
  /// CV_32F MGoD (eq. 2, image units per 2s pixels); NaN where DGoD is NaN.
  cv::Mat mgod;
};

/// Computes DGoD (eq. 1) and MGoD (eq. 2) of a CV_32F image; values that are
/// non-finite or <= 0 are invalid. Angles are within 1e-3 deg of atan2 (a
/// polynomial arctangent); axis directions (0/90/180/270/360) are exact.
GodFeatures compute_god_features(const cv::Mat& image, int gradient_step, double flat_mgod_max);

/// Edge-preserving mean for the gradients: every valid pixel becomes the mean of the valid pixels of
/// its (2r+1) x (2r+1) neighbourhood whose value is within `max_difference` of its own (a horizontal
/// pass, then a vertical one, each with that test against the pass's centre). Invalid pixels (non-finite
/// or <= 0) stay as they are. A plane stays the same plane away from its border; zero-mean noise of
/// standard deviation sigma drops to about sigma / (2r+1). r = 0 returns a copy. CV_32F in and out.
cv::Mat smooth_valid_values(const cv::Mat& image, int radius, double max_difference);

/// Histogram bin of every pixel: 0..B-1 direction, B = flat, 255 = does not vote
/// (no feature, or MGoD > jump_mgod_min). CV_8U. B must be <= 254.
cv::Mat god_bins(const GodFeatures& features, int direction_bins, double jump_mgod_min);

/// Voting clustering: every voting pixel gets the bin with most votes in its
/// n x n neighbourhood (ties: lowest bin); non-voting pixels stay 255. Sliding
/// column histograms: O(N * bins), independent of n. CV_8U in, CV_8U out.
cv::Mat vote_clusters(const cv::Mat& bins, int num_bins, int window_size);

/// Gives the pixels that god_bins left out as jump edges (MGoD > jump_mgod_min) their direction bin back where
/// the second differences along x and y are both <= max_curvature (GodParams::jump_min_curvature): a steep
/// plane, not a step between surfaces. `image` is the gradients' input; pixels with no feature stay 255.
void keep_steep_planes(const cv::Mat& image, int gradient_step, int direction_bins, double jump_mgod_min,
                       double max_curvature, cv::Mat& bins);

/// 4-connected components of equal values of a CV_8U image (255 = background).
/// Returns CV_32S labels 1..count (0 background) in raster order; count in *count.
cv::Mat connected_regions(const cv::Mat& clusters, int* count);

/// Intermediate images of a GoD run, for diagnostics and tests.
struct GodDebug {
  /// DGoD and MGoD.
  GodFeatures features;
  /// Bins before voting (god_bins).
  cv::Mat bins;
  /// Clustered bins after voting.
  cv::Mat clusters;
  /// Initial segments (connected regions of the clustered image), CV_32S.
  cv::Mat initial_labels;
  /// Number of initial segments.
  int initial_count = 0;
  /// Number of merges performed.
  int merges = 0;
  /// Number of merge rounds until nothing merged.
  int merge_rounds = 0;
};

/// Full GoD segmentation of `image` (CV_32F depth or disparity; invalid = NaN or <= 0).
/// `points` (CV_32FC3, same size, NaN = invalid) are the 3D points the output planes are fitted
/// to (and the merge space when params.merge_space == kPoints); if empty, (x, y, value) is used.
/// Throws std::invalid_argument on a wrong type/size or bad parameters.
SegmentationResult segment_god(const cv::Mat& image, const cv::Mat& points, const GodParams& params,
                               GodDebug* debug = nullptr);

}  // namespace bookgrasp::bws
