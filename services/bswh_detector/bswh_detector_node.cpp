#include "services/bswh_detector/bswh_detector_node.h"

#include <chrono>
#include <cmath>

#include "common/image_conversion.h"
#include "services/bswh_detector/stripe_debug_overlay.h"

namespace bookgrasp {

BswhDetectorSettings BswhDetectorSettings::from_config(const Config& root) {
  BswhDetectorSettings s;
  s.input_channel = root.get_channel("channels.input");
  s.output_channel = root.get_channel("channels.output");
  s.debug_image_channel = root.get_channel("channels.debug_image");
  s.publish_debug_image = root.get<bool>("debug.publish_image");
  s.stripe = StripeDetectionParams::from_config(root.child("stripe"));
  s.measure_processing_time = root.get<bool>("diagnostics.measure_processing_time");
  return s;
}

BswhDetectorNode::BswhDetectorNode(const BswhDetectorSettings& settings)
    : Component("bswh_detector", "threshold_canny"), settings_(settings) {
  subscribe(settings_.input_channel, &BswhDetectorNode::on_image);
}

bool BswhDetectorNode::process(const hand_image_t& msg, stripe_features_t* out, std::string* reason, image_t* debug) {
  const auto start = std::chrono::steady_clock::now();
  cv::Mat image;
  try {
    image = image_to_mat(msg.image);
  } catch (const std::exception& e) {
    *reason = std::string("hand image cannot be decoded: ") + e.what();
    return false;
  }
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    *reason = "hand image pixel format " + pixel_format_name(msg.image.pixel_format) +
              " is not an intensity image (send GRAY8, RGB8, PNG or JPEG)";
    return false;
  }
  const auto& c = msg.calibration;
  if (c.width != image.cols || c.height != image.rows) {
    *reason = "hand image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
              " but its calibration is for " + std::to_string(c.width) + "x" + std::to_string(c.height);
    return false;
  }
  const StripeDetection d = detect_stripe(image, settings_.stripe);
  out->utime = msg.image.utime;
  out->implementation = implementation();
  out->found = d.found;
  out->end_found = d.end_found;
  out->failure_reason = d.failure_reason;
  out->end_px[0] = d.end_found ? d.end.x : 0.0;
  out->end_px[1] = d.end_found ? d.end.y : 0.0;
  out->centre_line_px[0] = d.line_start.x;
  out->centre_line_px[1] = d.line_start.y;
  out->centre_line_px[2] = d.line_end.x;
  out->centre_line_px[3] = d.line_end.y;
  out->thickness_px = d.thickness_px;
  out->processing_ms = settings_.measure_processing_time
                           ? std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count()
                           : 0.0;
  if (debug && settings_.publish_debug_image)
    *debug = encode_png(draw_bswh_overlay(image, d, implementation() + " utime " + std::to_string(out->utime)),
                        out->utime, msg.image.frame);
  return true;
}

void BswhDetectorNode::on_image(const hand_image_t& msg) {
  stripe_features_t out;
  image_t debug;
  std::string reason;
  if (!process(msg, &out, &reason, &debug)) {
    reject(settings_.input_channel, reason);
    return;
  }
  publish(settings_.output_channel, out);
  if (settings_.publish_debug_image) publish(settings_.debug_image_channel, debug);
}

}  // namespace bookgrasp
