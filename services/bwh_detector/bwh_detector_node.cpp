#include "services/bwh_detector/bwh_detector_node.h"

#include <chrono>
#include <cmath>

#include "common/image_conversion.h"
#include "services/bwh_detector/bwh_debug_overlay.h"

namespace bookgrasp {

BwhDetectorSettings BwhDetectorSettings::from_config(const Config& root) {
  BwhDetectorSettings s;
  s.input_channel = root.get_channel("channels.input");
  s.output_channel = root.get_channel("channels.output");
  s.servo_request_channel = root.get_channel("channels.servo_request");
  s.debug_image_channel = root.get_channel("channels.debug_image");
  s.publish_debug_image = root.get<bool>("debug.publish_image");
  s.method = root.get_choice("method", {"page_faces", "canny_regions"});
  s.books = BookDetectionParams::from_config(root.child("books"));
  s.page_faces = PageFaceParams::from_config(root.child("page_faces"));
  s.measure_processing_time = root.get<bool>("diagnostics.measure_processing_time");
  return s;
}

bool decode_hand_image(const hand_image_t& msg, cv::Mat* image, std::string* reason) {
  try {
    *image = image_to_mat(msg.image);
  } catch (const std::exception& e) {
    *reason = std::string("hand image cannot be decoded: ") + e.what();
    return false;
  }
  if (image->type() != CV_8UC3 && image->type() != CV_8UC1) {
    *reason = "hand image pixel format " + pixel_format_name(msg.image.pixel_format) +
              " is not an intensity image (send GRAY8, RGB8, PNG or JPEG)";
    return false;
  }
  const auto& c = msg.calibration;
  if (c.width != image->cols || c.height != image->rows) {
    *reason = "hand image is " + std::to_string(image->cols) + "x" + std::to_string(image->rows) +
              " but its calibration is for " + std::to_string(c.width) + "x" + std::to_string(c.height);
    return false;
  }
  if (!std::isfinite(c.fx) || !std::isfinite(c.fy) || !std::isfinite(c.cx) || !std::isfinite(c.cy) || c.fx <= 0 ||
      c.fy <= 0) {
    *reason = "hand image calibration has a non-finite or non-positive fx, fy, cx or cy";
    return false;
  }
  return true;
}

BwhDetectorNode::BwhDetectorNode(const BwhDetectorSettings& settings)
    : Component("bwh_detector", settings.method), settings_(settings) {
  subscribe(settings_.input_channel, &BwhDetectorNode::on_image);
  subscribe(settings_.servo_request_channel, &BwhDetectorNode::on_request);
}

bool BwhDetectorNode::process(const hand_image_t& msg, book_features_hand_t* out, std::string* reason, image_t* debug) {
  const auto start = std::chrono::steady_clock::now();
  cv::Mat image;
  if (!decode_hand_image(msg, &image, reason)) return false;
  if (settings_.method == "page_faces" && image.type() != CV_8UC3) {
    *reason = "method page_faces needs a colour image (RGB8, PNG or JPEG colour); got grey";
    return false;
  }
  const BookDetection d = settings_.method == "page_faces" ? detect_books_page_faces(image, settings_.page_faces)
                                                           : detect_books_hand(image, settings_.books);
  out->utime = msg.image.utime;
  out->implementation = implementation();
  out->rank_from_right = rank_;
  out->found = false;
  out->failure_reason = d.failure_reason;
  out->r_px[0] = out->r_px[1] = 0.0;
  out->slope_rad = 0.0;
  out->book_width_px = 0.0;
  if (d.found && rank_ >= static_cast<int>(d.ranking.size())) {
    out->failure_reason = "rank " + std::to_string(rank_) + " requested but only " + std::to_string(d.ranking.size()) +
                          " book(s) accepted";
  } else if (d.found) {
    const BookCandidate& b = d.candidates[static_cast<size_t>(d.ranking[static_cast<size_t>(rank_)])];
    out->found = true;
    out->r_px[0] = b.corner_r.x;
    out->r_px[1] = b.corner_r.y;
    out->slope_rad = b.slope_rad;
    out->book_width_px = b.width_px;
  }
  out->candidates.clear();
  for (const BookCandidate& c : d.candidates) {
    book_candidate_t m;
    m.utime = out->utime;
    m.id = c.id;
    m.bbox_px[0] = c.bbox.x;
    m.bbox_px[1] = c.bbox.y;
    m.bbox_px[2] = c.bbox.x + c.bbox.width - 1;
    m.bbox_px[3] = c.bbox.y + c.bbox.height - 1;
    m.corner_r_px[0] = c.corner_r.x;
    m.corner_r_px[1] = c.corner_r.y;
    m.slope_rad = c.slope_rad;
    m.width_px = c.width_px;
    m.num_merged = c.num_merged;
    m.accepted = c.accepted;
    m.reject_reason = c.reject_reason;
    out->candidates.push_back(m);
  }
  out->num_candidates = static_cast<int32_t>(out->candidates.size());
  out->processing_ms = settings_.measure_processing_time
                           ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()
                           : 0.0;
  if (debug && settings_.publish_debug_image)
    *debug = encode_png(draw_bwh_overlay(image, d, rank_, settings_.method + " utime " + std::to_string(out->utime)),
                        out->utime, msg.image.frame);
  return true;
}

void BwhDetectorNode::on_image(const hand_image_t& msg) {
  book_features_hand_t out;
  image_t debug;
  std::string reason;
  if (!process(msg, &out, &reason, &debug)) {
    reject(settings_.input_channel, reason);
    return;
  }
  publish(settings_.output_channel, out);
  if (settings_.publish_debug_image) publish(settings_.debug_image_channel, debug);
}

void BwhDetectorNode::on_request(const servo_request_t& msg) {
  if (msg.mode != servo_request_t::BOOK_CORNER) return;
  if (msg.rank_from_right < 0) {
    reject(settings_.servo_request_channel,
           "rank_from_right must be >= 0 (got " + std::to_string(msg.rank_from_right) + ")");
    return;
  }
  rank_ = msg.rank_from_right;
}

}  // namespace bookgrasp
