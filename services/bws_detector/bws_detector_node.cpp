#include "services/bws_detector/bws_detector_node.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "services/bws_detector/debug_overlay.h"

namespace bookgrasp {

BwsDetectorSettings BwsDetectorSettings::from_config(const Config& root) {
  BwsDetectorSettings s;
  s.stereo_channel = root.get_channel("channels.stereo");
  s.markers_channel = root.get_channel("channels.markers");
  s.corner_channel = root.get_channel("channels.corner");
  s.debug_image_channel = root.get_channel("channels.debug_image");
  s.publish_debug_image = root.get<bool>("debug.publish_image");
  s.cart_marker_role = root.get<std::string>("cart.marker_role");
  s.max_pending_frames = root.get_int("pairing.max_pending_frames", 0, 100);
  s.min_frame_interval_s = root.get_double("processing.min_frame_interval_s", 0.0, 3600.0);
  s.measure_processing_time = root.get<bool>("diagnostics.measure_processing_time");
  s.params = bws::BwsParams::from_config(root);
  return s;
}

std::string stereo_input_from_frame(const stereo_frame_t& f, bws::StereoInput* in) {
  cv::Mat left, right;
  try {
    left = image_to_mat(f.left);
  } catch (const std::exception& e) {
    return std::string("left image cannot be decoded: ") + e.what();
  }
  try {
    right = image_to_mat(f.right);
  } catch (const std::exception& e) {
    return std::string("right image cannot be decoded: ") + e.what();
  }
  for (const auto* m : {&left, &right})
    if (m->depth() != CV_8U || (m->channels() != 1 && m->channels() != 3))
      return std::string(m == &left ? "left" : "right") + " image is not 8-bit grey or RGB (format " +
             pixel_format_name(m == &left ? f.left.pixel_format : f.right.pixel_format) + ")";
  if (left.size() != right.size())
    return "left image is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) + " but right is " +
           std::to_string(right.cols) + "x" + std::to_string(right.rows) + " (send a rectified pair of one size)";
  if (left.cols < 32 || left.rows < 32) return "images are smaller than 32x32";
  const camera_calibration_t& c = f.left_calibration;
  if (c.width != left.cols || c.height != left.rows)
    return "left image is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
           " but its calibration is for " + std::to_string(c.width) + "x" + std::to_string(c.height);
  if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && std::isfinite(c.cx) && std::isfinite(c.cy)))
    return "left calibration has a non-finite fx, fy, cx or cy";
  if (c.fx <= 0 || c.fy <= 0) return "left calibration focal lengths must be > 0";
  if (!(std::isfinite(f.baseline_m) && f.baseline_m > 0))
    return "baseline_m must be finite and > 0 (got " + std::to_string(f.baseline_m) + ")";
  if (!is_valid_pose(c.camera_in_base))
    return "left calibration camera_in_base is not a valid pose (NaN or quaternion)";
  in->left = left;
  in->right = right;
  in->geometry = {c.fx, c.fy, c.cx, c.cy, f.baseline_m};
  in->camera_in_base = pose_to_isometry(c.camera_in_base);
  return "";
}

BwsDetectorNode::BwsDetectorNode(const BwsDetectorSettings& settings)
    : Component("bws_detector", settings.params.implementation), s_(settings) {
  subscribe(s_.stereo_channel, &BwsDetectorNode::on_stereo);
  subscribe(s_.markers_channel, &BwsDetectorNode::on_markers);
}

std::string BwsDetectorNode::take_markers(const marker_detections_t& msg) {
  if (msg.num_markers != int32_t(msg.markers.size()))
    return "num_markers " + std::to_string(msg.num_markers) + " does not match the " +
           std::to_string(msg.markers.size()) + " markers sent";
  std::optional<Eigen::Isometry3d> cart;
  for (const marker_t& m : msg.markers) {
    if (m.role != s_.cart_marker_role) continue;
    if (!is_valid_pose(m.pose_in_base))
      return "cart marker " + std::to_string(m.id) + " has an invalid pose_in_base (NaN or not a unit quaternion)";
    cart = pose_to_isometry(m.pose_in_base);
    break;
  }
  track_.add(msg.utime, cart);  // without the cart marker: still says the detector answered up to msg.utime
  return "";
}

void BwsDetectorNode::on_markers(const marker_detections_t& msg) {
  const std::string why = take_markers(msg);
  if (!why.empty()) reject(s_.markers_channel, why);
  while (!pending_.empty() && track_.covers(pending_.front().utime)) {
    answer(pending_.front());
    pending_.pop_front();
  }
}

namespace {
void put3(double* dst, const Eigen::Vector3d& v) {
  for (int i = 0; i < 3; ++i) dst[i] = v(i);
}
}  // namespace

std::string BwsDetectorNode::process(const stereo_frame_t& frame, book_corner_stereo_t* out, image_t* debug) {
  bws::StereoInput in;
  std::string why = stereo_input_from_frame(frame, &in);
  if (!why.empty()) return why;
  const std::optional<bws::CartObservation> cart = track_.nearest(frame.utime);
  if (!cart)
    return "no cart marker (role '" + s_.cart_marker_role + "') received on " + s_.markers_channel +
           " yet: is the marker_detector running and the cart marker visible?";
  const double age_s = double(frame.utime - cart->utime) * 1e-6;
  if (age_s * 1e6 < -double(bws::CartMarkerTrack::kRestartUtime)) {
    // Every cart marker kept is from more than a second after the frame: the frames' source restarted
    // (a restarted simulation's clock starts over). Those markers belong to the old timeline: drop them
    // and wait for one of the new (skipped, not rejected, like the start-up).
    track_.clear();
    return "no cart marker (role '" + s_.cart_marker_role + "') received on " + s_.markers_channel +
           " since the stereo source restarted (the nearest is " + std::to_string(-age_s) + " s after this frame)";
  }
  if (std::fabs(age_s) > s_.params.cart.max_marker_age_s)
    return "nearest cart marker is " + std::to_string(age_s) +
           " s from the stereo frame (limit cart.max_marker_age_s = " +
           std::to_string(s_.params.cart.max_marker_age_s) + ")";
  bws::BwsOutput r;
  try {
    r = bws::run_bws(in, cart->cart_in_base, s_.params, s_.measure_processing_time);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  book_corner_stereo_t m;
  m.utime = frame.utime;
  m.implementation = s_.params.implementation;
  m.found = r.selection.found;
  m.failure_reason = r.selection.found ? "" : r.selection.failure_reason;
  m.pi_px[0] = r.selection.found ? r.selection.pi.x : -1;
  m.pi_px[1] = r.selection.found ? r.selection.pi.y : -1;
  if (r.selection.found) {
    put3(m.p1_base, r.selection.p1_base);
    put3(m.p1_grasp, r.p1_grasp);
  } else {
    put3(m.p1_base, Eigen::Vector3d::Constant(nan));
    put3(m.p1_grasp, Eigen::Vector3d::Constant(nan));
  }
  m.selected_label = r.selection.selected_label;
  for (const bws::RegionVerdict& v : r.selection.regions) {
    const bws::PlaneRegion& pr = r.segmentation.regions[size_t(v.label - 1)];
    plane_region_t q;
    q.utime = frame.utime;
    q.label = v.label;
    q.pixel_count = pr.pixel_count;
    q.bbox_px[0] = pr.bbox.x;
    q.bbox_px[1] = pr.bbox.y;
    q.bbox_px[2] = pr.bbox.x + pr.bbox.width - 1;
    q.bbox_px[3] = pr.bbox.y + pr.bbox.height - 1;
    put3(q.normal_base, v.normal_base);
    q.offset_m = v.offset_base;
    put3(q.extent_min_base, v.extent_min_base);
    put3(q.extent_max_base, v.extent_max_base);
    q.candidate = v.candidate;
    q.reject_reason = v.candidate ? "" : v.reason;
    m.regions.push_back(std::move(q));
  }
  m.num_regions = int32_t(m.regions.size());
  m.num_valid_disparity = r.num_valid_disparity;
  m.disparity_ms = r.disparity_ms;
  m.segmentation_ms = r.segmentation_ms;
  m.total_ms = r.total_ms;
  *out = std::move(m);
  last_ = r;
  if (debug && s_.publish_debug_image) {
    const cv::Mat overlay =
        bws::draw_bws_overlay(in.left, r, s_.params.implementation + " utime " + std::to_string(frame.utime));
    *debug = encode_png(overlay, frame.utime, frame.left.frame);
  }
  return "";
}

void BwsDetectorNode::on_stereo(const stereo_frame_t& frame) {
  // Wait for the marker detector's answer for this frame (MARKERS at its utime), so the pair is
  // the same live, in a replay and in a chain replay; a detector that is late or down holds at
  // most pairing.max_pending_frames frames back, then the nearest cart marker is used.
  pending_.push_back(frame);
  while (!pending_.empty() &&
         (track_.covers(pending_.front().utime) || pending_.size() > size_t(s_.max_pending_frames))) {
    answer(pending_.front());
    pending_.pop_front();
  }
}

void BwsDetectorNode::answer(const stereo_frame_t& frame) {
  // Message time decides which frames are skipped, so a replay skips the same frames as the live run.
  // Only answered frames count (a rejected or waiting frame does not hold the next one back), and a
  // frame from before the last answer (a restarted source) is always taken.
  if (last_answered_utime_ && frame.utime >= *last_answered_utime_ &&
      double(frame.utime - *last_answered_utime_) < s_.min_frame_interval_s * 1e6) {
    ++skipped_frames_;
    return;
  }
  book_corner_stereo_t out;
  image_t debug;
  const std::string why = process(frame, &out, &debug);
  if (!why.empty()) {
    // Before the first cart marker the frame is not bad input, the system is starting (or this
    // detector just restarted): skipped and said in last_error, not counted as a rejection.
    if (track_.empty())
      report_error("waiting: " + why);
    else
      reject(s_.stereo_channel, why);
    return;
  }
  last_answered_utime_ = frame.utime;
  publish(s_.corner_channel, out);
  if (s_.publish_debug_image) publish(s_.debug_image_channel, debug);
}

}  // namespace bookgrasp
