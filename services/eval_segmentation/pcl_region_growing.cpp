#include "services/eval_segmentation/pcl_region_growing.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <pcl/features/integral_image_normal.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/region_growing.h>

namespace bookgrasp::eval_segmentation {

cv::Mat segment_region_growing(const cv::Mat& points, const RegionGrowingParams& p) {
  if (points.type() != CV_32FC3 || points.empty())
    throw std::invalid_argument("segment_region_growing: points must be a non-empty CV_32FC3 image");
  if (!(p.normal_smoothing_size >= 1) || p.neighbours < 3 || !(p.smoothness_deg > 0) || !(p.curvature_threshold > 0) ||
      p.min_region_px < 1 || !(p.max_depth_change_factor > 0))
    throw std::invalid_argument(
        "segment_region_growing: normal_smoothing_size >= 1, neighbours >= 3, smoothness_deg, curvature_threshold, "
        "max_depth_change_factor > 0 and min_region_px >= 1 are required");
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
  ne.setNormalEstimationMethod(ne.COVARIANCE_MATRIX);
  ne.setMaxDepthChangeFactor(float(p.max_depth_change_factor));
  ne.setNormalSmoothingSize(float(p.normal_smoothing_size));
  ne.setInputCloud(cloud);
  ne.compute(*normals);

  // Only points with a finite position and normal take part (the search tree and the growth need them).
  pcl::IndicesPtr valid(new pcl::Indices);
  for (size_t i = 0; i < cloud->points.size(); ++i) {
    const auto& pt = cloud->points[i];
    const auto& n = normals->points[i];
    if (std::isfinite(pt.z) && std::isfinite(n.normal_x) && std::isfinite(n.normal_y) && std::isfinite(n.normal_z) &&
        std::isfinite(n.curvature))
      valid->push_back(pcl::index_t(i));
  }
  cv::Mat labels(points.size(), CV_32S, cv::Scalar(0));
  if (valid->empty()) return labels;
  pcl::search::Search<pcl::PointXYZ>::Ptr tree(new pcl::search::KdTree<pcl::PointXYZ>);
  pcl::RegionGrowing<pcl::PointXYZ, pcl::Normal> rg;
  rg.setMinClusterSize(p.min_region_px);
  rg.setMaxClusterSize(std::numeric_limits<int>::max());
  rg.setSearchMethod(tree);
  rg.setNumberOfNeighbours(unsigned(p.neighbours));
  rg.setInputCloud(cloud);
  rg.setIndices(valid);
  rg.setInputNormals(normals);
  rg.setSmoothnessThreshold(float(p.smoothness_deg * M_PI / 180.0));
  rg.setCurvatureThreshold(float(p.curvature_threshold));
  std::vector<pcl::PointIndices> clusters;
  rg.extract(clusters);
  int* l = labels.ptr<int>(0);  // continuous
  for (size_t k = 0; k < clusters.size(); ++k)
    for (const auto idx : clusters[k].indices) l[idx] = int(k) + 1;
  return labels;
}

}  // namespace bookgrasp::eval_segmentation
