#include "services/bws_detector/pcl_plane_segmentation.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/segmentation/organized_multi_plane_segmentation.h>

#include "common/config.h"

namespace bookgrasp::bws {

PclPlaneParams PclPlaneParams::from_config(const Config& c) {
  PclPlaneParams p;
  p.space = c.get_choice("space", {"points", "image"}) == "image" ? PclSpace::kImage : PclSpace::kPoints;
  p.disparity_scale = c.get_double("disparity_scale", 1e-6, 1e6);
  p.covariance_normals = c.get_choice("normal_method", {"covariance", "average_3d_gradient"}) == "covariance";
  p.max_depth_change_factor = c.get_double("max_depth_change_factor", 0.0, 10.0);
  p.normal_smoothing_size = c.get_double("normal_smoothing_size", 1.0, 1000.0);
  p.min_inliers = c.get_int("min_inliers", 3, 100000000);
  p.angular_threshold_deg = c.get_double("angular_threshold_deg", 0.0, 90.0);
  p.distance_threshold_m = c.get_double("distance_threshold_m", 0.0, 10.0);
  p.maximum_curvature = c.get_double("maximum_curvature", 0.0, 10.0);
  p.min_region_px = c.get_int("min_region_px", 1, 100000000);
  return p;
}

namespace {
/// Plane labels (CV_32S, 0 = none) of the organized cloud `points` by PCL.
cv::Mat pcl_plane_labels(const cv::Mat& points, const PclPlaneParams& p) {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->width = uint32_t(points.cols);
  cloud->height = uint32_t(points.rows);
  cloud->is_dense = false;
  cloud->points.resize(size_t(points.cols) * size_t(points.rows));
  for (int y = 0; y < points.rows; ++y) {
    const cv::Vec3f* q = points.ptr<cv::Vec3f>(y);
    for (int x = 0; x < points.cols; ++x) {
      auto& pt = cloud->points[size_t(y) * size_t(points.cols) + size_t(x)];
      pt.x = q[x][0];
      pt.y = q[x][1];
      pt.z = q[x][2];
    }
  }
  pcl::PointCloud<pcl::Normal>::Ptr normals(new pcl::PointCloud<pcl::Normal>);
  pcl::IntegralImageNormalEstimation<pcl::PointXYZ, pcl::Normal> ne;
  ne.setNormalEstimationMethod(p.covariance_normals ? ne.COVARIANCE_MATRIX : ne.AVERAGE_3D_GRADIENT);
  ne.setMaxDepthChangeFactor(float(p.max_depth_change_factor));
  ne.setNormalSmoothingSize(float(p.normal_smoothing_size));
  ne.setInputCloud(cloud);
  ne.compute(*normals);

  pcl::OrganizedMultiPlaneSegmentation<pcl::PointXYZ, pcl::Normal, pcl::Label> mps;
  mps.setMinInliers(unsigned(p.min_inliers));
  mps.setAngularThreshold(p.angular_threshold_deg * M_PI / 180.0);
  mps.setDistanceThreshold(p.distance_threshold_m);
  mps.setMaximumCurvature(p.maximum_curvature);
  mps.setInputNormals(normals);
  mps.setInputCloud(cloud);
  std::vector<pcl::ModelCoefficients> coefficients;
  std::vector<pcl::PointIndices> inliers;
  mps.segment(coefficients, inliers);

  cv::Mat labels(points.size(), CV_32S, cv::Scalar(0));
  int* l = labels.ptr<int>(0);
  for (size_t k = 0; k < inliers.size(); ++k)
    for (int idx : inliers[k].indices) l[idx] = int(k) + 1;  // labels is continuous
  return labels;
}
}  // namespace

SegmentationResult segment_pcl_planes(const cv::Mat& points, const PclPlaneParams& p) {
  if (points.type() != CV_32FC3 || points.empty())
    throw std::invalid_argument("segment_pcl_planes: points must be a non-empty CV_32FC3 image");
  return describe_regions(pcl_plane_labels(points, p), points, p.min_region_px);
}

SegmentationResult segment_pcl_planes(const cv::Mat& disparity, const cv::Mat& points, const PclPlaneParams& p) {
  if (points.type() != CV_32FC3 || points.empty())
    throw std::invalid_argument("segment_pcl_planes: points must be a non-empty CV_32FC3 image");
  if (p.space == PclSpace::kPoints) return segment_pcl_planes(points, p);
  if (disparity.type() != CV_32F || disparity.size() != points.size())
    throw std::invalid_argument("segment_pcl_planes: the disparity must be CV_32F of the points' size");
  cv::Mat cloud = image_space_points(disparity);
  if (p.disparity_scale != 1.0) cv::multiply(cloud, cv::Scalar(1.0, 1.0, p.disparity_scale), cloud);
  return describe_regions(pcl_plane_labels(cloud, p), points, p.min_region_px);
}

}  // namespace bookgrasp::bws
