#pragma once
/// @file
/// The output every planar segmentation of this service produces (GoD, PCL,
/// baselines): a label image plus, per region, a least-squares plane and its
/// extent. Also the moment accumulator and plane fit they share.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace bookgrasp::bws {

/// One planar region of a segmentation.
struct PlaneRegion {
  /// Value of the region's pixels in SegmentationResult::labels (1..regions.size()).
  int label = 0;
  /// Number of pixels carrying the label.
  int pixel_count = 0;
  /// Number of those pixels with a finite 3D point (the ones the plane is fitted to).
  int point_count = 0;
  /// Bounding box of the region's pixels (x, y, width, height), image pixels.
  cv::Rect bbox;
  /// Unit plane normal in the frame of the points the plane was fitted to,
  /// oriented towards the origin of that frame (the camera): normal . centroid <= 0.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  /// Plane offset: the plane is { p : normal . p = offset }.
  double offset = 0.0;
  /// Mean of the region's points.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  /// Root-mean-square point-to-plane distance of the region's points (points' unit).
  double rms_residual = 0.0;
  /// Axis-aligned extent of the region's points (points' frame and unit).
  Eigen::Vector3d extent_min = Eigen::Vector3d::Zero();
  /// Axis-aligned extent of the region's points (points' frame and unit).
  Eigen::Vector3d extent_max = Eigen::Vector3d::Zero();
};

/// A planar segmentation: label image (CV_32S, 0 = no region) and one
/// PlaneRegion per label, regions[i].label == i + 1.
struct SegmentationResult {
  /// CV_32S label image, same size as the input; 0 = pixel in no region.
  cv::Mat labels;
  /// Per-label descriptions; regions[i].label == i + 1.
  std::vector<PlaneRegion> regions;
};

/// First and second moments of a point set: enough to fit a least-squares
/// plane and to evaluate point-to-plane distances of the whole set in O(1).
struct PointMoments {
  /// Number of points.
  double n = 0.0;
  /// Sum of the points.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  /// Sum of p p^T.
  Eigen::Matrix3d sum_outer = Eigen::Matrix3d::Zero();

  /// Adds one point.
  void add(const Eigen::Vector3d& p) {
    n += 1.0;
    sum += p;
    sum_outer.noalias() += p * p.transpose();
  }
  /// Adds every point of another set.
  void add(const PointMoments& o) {
    n += o.n;
    sum += o.sum;
    sum_outer += o.sum_outer;
  }
};

/// A least-squares plane { p : normal . p = offset }.
struct Plane {
  /// Unit normal (orientation: see fit_plane).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  /// Offset along the normal.
  double offset = 0.0;
  /// False when the set had fewer than 3 points or was degenerate (collinear).
  bool valid = false;
};

/// Total-least-squares plane of a point set (eigenvector of the smallest
/// eigenvalue of the covariance). The normal is oriented so that
/// normal . mean <= 0 (towards the frame origin).
Plane fit_plane(const PointMoments& m);

/// Root-mean-square distance of the points of `m` to `plane` (O(1), from moments).
double rms_distance(const PointMoments& m, const Plane& plane);

/// Describes every label > 0 of `labels` (CV_32S) with the points of `points`
/// (CV_32FC3, same size; pixels with a non-finite coordinate are skipped for
/// the plane and extent). Labels are renumbered 1..K in raster order of their
/// first pixel; regions with fewer than `min_pixels` pixels or no valid plane
/// become 0. Returns the renumbered label image and the descriptions.
SegmentationResult describe_regions(const cv::Mat& labels, const cv::Mat& points, int min_pixels);

/// describe_regions() that renumbers `labels` in place: the result's label image is `labels`' buffer
/// (saves allocating and touching another label image).
SegmentationResult describe_regions_in_place(cv::Mat& labels, const cv::Mat& points, int min_pixels);

/// A CV_32FC3 image of (x, y, value) for every pixel of a CV_32F image
/// (non-finite or <= 0 values give NaN points). In this space a 3D plane seen
/// in a disparity image is a plane (disparity is affine in x, y on a plane).
cv::Mat image_space_points(const cv::Mat& image);

}  // namespace bookgrasp::bws
