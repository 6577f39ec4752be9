#include "services/marker_detector/marker_detector_node.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "common/image_conversion.h"
#include "common/pose_conversion.h"

namespace bookgrasp {

MarkerDetectorSettings MarkerDetectorSettings::from_config(const Config& root) {
  MarkerDetectorSettings s;
  s.input_channel = root.get<std::string>("channels.input");
  s.output_channel = root.get<std::string>("channels.output");
  s.detector = TagDetectorParams::from_config(root.child("apriltag"));
  s.fallback_quad_sigma = root.get_double("apriltag.fallback_quad_sigma", 0.0, 5.0);
  s.tracking = TagTrackingParams::from_config(root.child("tracking"));
  s.default_tag_size_m = root.get_double("tags.default_size_m", 0.005, 2.0);
  s.cart_ids = root.get<std::vector<int>>("tags.cart.ids");
  s.cart_tag_size_m = root.get_double("tags.cart.size_m", 0.005, 2.0);
  s.holder_ids = root.get<std::vector<int>>("tags.holder.ids");
  s.holder_tag_size_m = root.get_double("tags.holder.size_m", 0.005, 2.0);
  s.cart_max_tilt_rad = root.get_double("tags.cart.max_tilt_deg", 0.0, 180.0) * M_PI / 180.0;
  s.holder_max_tilt_rad = root.get_double("tags.holder.max_tilt_deg", 0.0, 180.0) * M_PI / 180.0;
  s.pose_ambiguity_px = root.get_double("tags.pose_ambiguity_px", 0.0, 100.0);
  s.stereo_range = TagStereoRangeParams::from_config(root.child("stereo_range"));
  s.report_unassigned = root.get<bool>("tags.report_unassigned");
  s.measure_processing_time = root.get<bool>("diagnostics.measure_processing_time");
  for (int id : s.cart_ids) {
    for (int h : s.holder_ids) {
      if (id == h) {
        throw ConfigError(root.source() + ": " + root.path_of("tags.holder.ids") + ": id " + std::to_string(id) +
                          " is also in tags.cart.ids; give each marker one role");
      }
    }
    if (id < 0) throw ConfigError(root.source() + ": " + root.path_of("tags.cart.ids") + ": ids must be >= 0");
  }
  for (int id : s.holder_ids) {
    if (id < 0) throw ConfigError(root.source() + ": " + root.path_of("tags.holder.ids") + ": ids must be >= 0");
  }
  return s;
}

bool intrinsics_from_calibration(const camera_calibration_t& c, int image_width, int image_height,
                                 TagCameraIntrinsics* k, std::string* reason) {
  if (!std::isfinite(c.fx) || !std::isfinite(c.fy) || !std::isfinite(c.cx) || !std::isfinite(c.cy)) {
    *reason = "calibration has a non-finite fx, fy, cx or cy";
    return false;
  }
  if (c.fx <= 0.0 || c.fy <= 0.0) {
    *reason =
        "calibration focal lengths must be > 0 (fx=" + std::to_string(c.fx) + ", fy=" + std::to_string(c.fy) + ")";
    return false;
  }
  if (c.width != image_width || c.height != image_height) {
    *reason = "image is " + std::to_string(image_width) + "x" + std::to_string(image_height) +
              " but its calibration is for " + std::to_string(c.width) + "x" + std::to_string(c.height);
    return false;
  }
  if (c.num_distortion != static_cast<int32_t>(c.distortion.size())) {
    *reason = "calibration num_distortion (" + std::to_string(c.num_distortion) + ") does not match the " +
              std::to_string(c.distortion.size()) + " coefficients sent";
    return false;
  }
  for (double d : c.distortion) {
    if (!std::isfinite(d)) {
      *reason = "calibration has a non-finite distortion coefficient";
      return false;
    }
  }
  k->fx = c.fx;
  k->fy = c.fy;
  k->cx = c.cx;
  k->cy = c.cy;
  k->distortion.clear();
  if (c.distortion_model == "none" || c.distortion_model.empty()) {
    for (double d : c.distortion) {
      if (d != 0.0) {
        *reason = "calibration distortion_model is 'none' but it carries non-zero coefficients";
        return false;
      }
    }
  } else if (c.distortion_model == "plumb_bob") {
    if (c.num_distortion != 5) {
      *reason = "plumb_bob distortion needs 5 coefficients (k1 k2 p1 p2 k3), got " + std::to_string(c.num_distortion);
      return false;
    }
    k->distortion = c.distortion;
  } else {
    *reason = "unknown distortion_model '" + c.distortion_model + "' (use 'none' or 'plumb_bob')";
    return false;
  }
  return true;
}

namespace {

/// The image as CV_8UC1; false and a reason if it cannot be decoded or is not an intensity image.
bool decode_gray(const image_t& msg, cv::Mat* gray, std::string* reason) {
  cv::Mat image;
  try {
    image = image_to_mat(msg);
  } catch (const std::exception& e) {
    *reason = std::string("image cannot be decoded: ") + e.what();
    return false;
  }
  if (image.type() == CV_8UC1) {
    *gray = image;
  } else if (image.type() == CV_8UC3) {
    cv::cvtColor(image, *gray, cv::COLOR_RGB2GRAY);
  } else {
    *reason = "image pixel format " + pixel_format_name(msg.pixel_format) +
              " is not an intensity image (send GRAY8, RGB8, PNG or JPEG)";
    return false;
  }
  return true;
}

std::map<int, std::string> roles_of_ids(const MarkerDetectorSettings& s) {
  std::map<int, std::string> roles;
  for (int id : s.cart_ids) roles[id] = "cart";
  for (int id : s.holder_ids) roles[id] = "holder";
  return roles;
}

std::set<int> ids_with_a_role(const std::map<int, std::string>& roles) {
  std::set<int> ids;
  for (const auto& [id, role] : roles) ids.insert(id);
  return ids;
}

}  // namespace

MarkerDetectorNode::MarkerDetectorNode(const MarkerDetectorSettings& settings)
    : Component("marker_detector", "apriltag3"),
      settings_(settings),
      role_of_id_(roles_of_ids(settings)),
      search_(settings.detector, settings.fallback_quad_sigma, settings.tracking, ids_with_a_role(role_of_id_)) {
  subscribe(settings_.input_channel, &MarkerDetectorNode::on_stereo);
}

bool MarkerDetectorNode::process(const stereo_frame_t& frame, marker_detections_t* out, std::string* reason) {
  const auto start = std::chrono::steady_clock::now();
  cv::Mat gray;
  if (!decode_gray(frame.left, &gray, reason)) {
    *reason = "left " + *reason;
    return false;
  }
  TagCameraIntrinsics k;
  if (!intrinsics_from_calibration(frame.left_calibration, gray.cols, gray.rows, &k, reason)) {
    *reason = "left " + *reason;
    return false;
  }
  if (!is_valid_pose(frame.left_calibration.camera_in_base)) {
    *reason = "left calibration camera_in_base is not a valid pose (NaN or non-unit quaternion)";
    return false;
  }
  const Eigen::Isometry3d camera_in_base = pose_to_isometry(frame.left_calibration.camera_in_base);
  const std::string camera_frame =
      frame.left_calibration.frame.empty() ? frame.left.frame : frame.left_calibration.frame;

  // A cart or holder tag the first pass misses is searched again with a blur (aliased or noisy edges,
  // e.g. the rendered tags); between whole-image searches only the previous frame's tags' regions.
  const std::vector<TagDetection> detections = search_.detect(gray, frame.left.utime).tags;
  out->utime = frame.left.utime;
  out->implementation = implementation();
  out->camera_frame = camera_frame;
  out->markers.clear();
  cv::Mat right_gray;  // decoded when the first tag needs it
  for (const TagDetection& d : detections) {
    const auto role_it = role_of_id_.find(d.id);
    const std::string role = role_it == role_of_id_.end() ? "" : role_it->second;
    if (role.empty() && !settings_.report_unassigned) continue;
    const double size = role == "cart"     ? settings_.cart_tag_size_m
                        : role == "holder" ? settings_.holder_tag_size_m
                                           : settings_.default_tag_size_m;
    TagPose pose;
    try {
      const std::vector<TagPose> candidates = estimate_tag_pose_candidates(d.corners, size, k);
      if (role.empty()) {
        pose = candidates.front();
      } else {
        // The cart's and the holder's tags are mounted upright: of IPPE's two solutions (a small or
        // distant tag fits a mirrored tilt nearly as well) take the one that is.
        const double max_tilt = role == "cart" ? settings_.cart_max_tilt_rad : settings_.holder_max_tilt_rad;
        const std::optional<TagPose> upright =
            choose_upright_pose(candidates, camera_in_base, max_tilt, settings_.pose_ambiguity_px);
        if (!upright) {
          char buf[200];
          std::snprintf(buf, sizeof buf,
                        "%s tag %d dropped: no pose within %.0f deg of upright (best fit tilted %.0f deg, %.2f px)",
                        role.c_str(), d.id, max_tilt * 180.0 / M_PI,
                        tag_tilt_from_upright(candidates.front().tag_in_camera, camera_in_base) * 180.0 / M_PI,
                        candidates.front().reprojection_error_px);
          report_error(buf);
          continue;
        }
        pose = *upright;
      }
      if (settings_.stereo_range.enabled) range_in_stereo(frame, gray, k, d, role, &right_gray, &pose);
    } catch (const std::exception& e) {
      report_error("tag " + std::to_string(d.id) + ": " + e.what());
      continue;
    }
    marker_t m;
    m.utime = out->utime;
    m.family = d.family;
    m.id = d.id;
    m.role = role;
    for (int i = 0; i < 4; ++i) {
      m.corners_px[i][0] = d.corners[static_cast<size_t>(i)].x;
      m.corners_px[i][1] = d.corners[static_cast<size_t>(i)].y;
    }
    m.center_px[0] = d.center.x;
    m.center_px[1] = d.center.y;
    const std::string child = role.empty() ? d.family + "_" + std::to_string(d.id) : role;
    m.pose_in_camera = isometry_to_pose(pose.tag_in_camera, camera_frame, child, out->utime);
    m.pose_in_base = isometry_to_pose(camera_in_base * pose.tag_in_camera, "base", child, out->utime);
    m.decision_margin = d.decision_margin;
    m.hamming = d.hamming;
    m.reprojection_error_px = pose.reprojection_error_px;
    out->markers.push_back(m);
  }
  out->num_markers = static_cast<int32_t>(out->markers.size());
  out->processing_ms = settings_.measure_processing_time
                           ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()
                           : 0.0;
  return true;
}

void MarkerDetectorNode::range_in_stereo(const stereo_frame_t& frame, const cv::Mat& left_gray,
                                         const TagCameraIntrinsics& k, const TagDetection& d, const std::string& role,
                                         cv::Mat* right_gray, TagPose* pose) {
  const std::string what = (role.empty() ? std::string("tag ") : role + " tag ") + std::to_string(d.id);
  if (right_gray->empty()) {
    std::string why;
    if (!decode_gray(frame.right, right_gray, &why)) {
      report_error(what + ": no stereo range, right " + why + " (monocular pose)");
      return;
    }
  }
  const TagStereoRange r =
      range_tag_in_stereo(left_gray, *right_gray, d.corners, k.fx, k.cx, frame.right_calibration.cx, frame.baseline_m,
                          settings_.stereo_range, pose->tag_in_camera.translation().z());
  if (!r.ok) {
    report_error(what + ": no stereo range: " + r.reason + " (monocular pose)");
    return;
  }
  const double mono = pose->tag_in_camera.translation().z();
  if (!(std::abs(r.depth_m - mono) <= settings_.stereo_range.max_disagreement * mono)) {
    char b[200];
    std::snprintf(b, sizeof b, "%s: stereo range %.3f m and monocular %.3f m disagree beyond %.0f %% (monocular pose)",
                  what.c_str(), r.depth_m, mono, settings_.stereo_range.max_disagreement * 100);
    report_error(b);
    return;
  }
  pose->tag_in_camera = tag_pose_at_depth(pose->tag_in_camera, r.depth_m);
}

void MarkerDetectorNode::on_stereo(const stereo_frame_t& frame) {
  marker_detections_t out;
  std::string reason;
  if (!process(frame, &out, &reason)) {
    reject(settings_.input_channel, reason);
    return;
  }
  publish(settings_.output_channel, out);
}

}  // namespace bookgrasp
