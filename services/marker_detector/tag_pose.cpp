#include "services/marker_detector/tag_pose.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

namespace bookgrasp {
namespace {

std::vector<cv::Point3d> tag_object_points(double s) {
  const double h = s / 2.0;
  return {{-h, h, 0.0}, {h, h, 0.0}, {h, -h, 0.0}, {-h, -h, 0.0}};
}

cv::Mat camera_matrix(const TagCameraIntrinsics& k) {
  return (cv::Mat_<double>(3, 3) << k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0);
}

cv::Mat distortion_vector(const TagCameraIntrinsics& k) {
  if (k.distortion.empty()) return cv::Mat();
  return cv::Mat(k.distortion, true).reshape(1, 1);
}

void check_intrinsics(const TagCameraIntrinsics& k) {
  const bool finite = std::isfinite(k.fx) && std::isfinite(k.fy) && std::isfinite(k.cx) && std::isfinite(k.cy);
  if (!finite || k.fx <= 0.0 || k.fy <= 0.0) {
    throw std::invalid_argument("camera intrinsics must be finite with fx, fy > 0");
  }
  for (double d : k.distortion) {
    if (!std::isfinite(d)) throw std::invalid_argument("distortion coefficients must be finite");
  }
}

}  // namespace

std::vector<TagPose> estimate_tag_pose_candidates(const std::array<cv::Point2d, 4>& corners, double tag_size_m,
                                                  const TagCameraIntrinsics& intrinsics) {
  if (!(tag_size_m > 0.0) || !std::isfinite(tag_size_m)) {
    throw std::invalid_argument("tag size must be a positive number of metres");
  }
  check_intrinsics(intrinsics);
  for (const auto& c : corners) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y)) throw std::invalid_argument("tag corners must be finite");
  }
  const std::vector<cv::Point3d> object = tag_object_points(tag_size_m);
  const std::vector<cv::Point2d> image(corners.begin(), corners.end());
  const cv::Mat k = camera_matrix(intrinsics);
  const cv::Mat dist = distortion_vector(intrinsics);
  std::vector<cv::Mat> rvecs, tvecs;
  if (cv::solvePnPGeneric(object, image, k, dist, rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE) < 1) {
    throw std::runtime_error("no pose for the tag corners (degenerate quadrilateral)");
  }
  std::vector<TagPose> poses;
  for (size_t s = 0; s < rvecs.size(); ++s) {
    cv::Mat rvec = rvecs[s], tvec = tvecs[s];
    cv::solvePnPRefineLM(object, image, k, dist, rvec, tvec);
    cv::Mat r;
    cv::Rodrigues(rvec, r);
    Eigen::Matrix3d rot;
    cv::cv2eigen(r, rot);
    TagPose pose;
    pose.tag_in_camera.linear() = rot;
    pose.tag_in_camera.translation() = Eigen::Vector3d(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
    std::vector<cv::Point2d> projected;
    cv::projectPoints(object, rvec, tvec, k, dist, projected);
    double sum = 0.0;
    for (size_t i = 0; i < 4; ++i) {
      const cv::Point2d d = projected[i] - image[i];
      sum += d.dot(d);
    }
    pose.reprojection_error_px = std::sqrt(sum / 4.0);
    poses.push_back(pose);
  }
  std::stable_sort(poses.begin(), poses.end(), [](const TagPose& a, const TagPose& b) {
    return a.reprojection_error_px < b.reprojection_error_px;
  });
  return poses;
}

TagPose estimate_tag_pose(const std::array<cv::Point2d, 4>& corners, double tag_size_m,
                          const TagCameraIntrinsics& intrinsics) {
  return estimate_tag_pose_candidates(corners, tag_size_m, intrinsics).front();
}

double tag_tilt_from_upright(const Eigen::Isometry3d& tag_in_camera, const Eigen::Isometry3d& camera_in_base) {
  const Eigen::Vector3d down = (camera_in_base.linear() * tag_in_camera.linear()).col(1);
  return std::acos(std::clamp(-down.z() / down.norm(), -1.0, 1.0));
}

std::optional<TagPose> choose_upright_pose(const std::vector<TagPose>& candidates,
                                           const Eigen::Isometry3d& camera_in_base, double max_tilt_rad,
                                           double ambiguity_px) {
  if (candidates.empty()) return std::nullopt;
  const TagPose* best = nullptr;
  double best_tilt = 0;
  for (const TagPose& c : candidates) {
    if (c.reprojection_error_px > candidates.front().reprojection_error_px + ambiguity_px) continue;
    const double tilt = tag_tilt_from_upright(c.tag_in_camera, camera_in_base);
    if (!best || tilt < best_tilt) {
      best = &c;
      best_tilt = tilt;
    }
  }
  if (best_tilt > max_tilt_rad) return std::nullopt;
  return *best;
}

std::array<cv::Point2d, 4> project_tag_corners(const Eigen::Isometry3d& tag_in_camera, double tag_size_m,
                                               const TagCameraIntrinsics& intrinsics) {
  check_intrinsics(intrinsics);
  const std::vector<cv::Point3d> object = tag_object_points(tag_size_m);
  cv::Mat r;
  const Eigen::Matrix3d rot = tag_in_camera.rotation();
  cv::eigen2cv(rot, r);
  cv::Mat rvec;
  cv::Rodrigues(r, rvec);
  const Eigen::Vector3d t = tag_in_camera.translation();
  const cv::Mat tvec = (cv::Mat_<double>(3, 1) << t.x(), t.y(), t.z());
  std::vector<cv::Point2d> projected;
  cv::projectPoints(object, rvec, tvec, camera_matrix(intrinsics), distortion_vector(intrinsics), projected);
  return {projected[0], projected[1], projected[2], projected[3]};
}

}  // namespace bookgrasp
