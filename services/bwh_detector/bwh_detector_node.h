#pragma once
/// @file
/// The bwh_detector component: HAND_IMAGE -> BOOK_FEATURES_HAND (the book
/// ranked `rank_from_right`, its corner R, slope, width, and every candidate
/// with its reason). SERVO_REQUEST (BOOK_CORNER) sets the rank to report.
/// With debug.publish_image, also BWH_DEBUG_IMAGE: a PNG of the candidates, R and slope.

#include <string>

#include "bookgrasp/book_features_hand_t.hpp"
#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/bwh_detector/book_detection_hand.h"
#include "services/bwh_detector/page_face_detection.h"

namespace bookgrasp {

/// Everything the BwH node reads from its configuration.
struct BwhDetectorSettings {
  std::string input_channel;            ///< channels.input (hand_image_t)
  std::string output_channel;           ///< channels.output (book_features_hand_t)
  std::string servo_request_channel;    ///< channels.servo_request (servo_request_t)
  std::string debug_image_channel;      ///< channels.debug_image (image_t, PNG)
  bool publish_debug_image = false;     ///< debug.publish_image
  std::string method;                   ///< method: "page_faces" (rendered/real views, default) or "canny_regions"
  BookDetectionParams books;            ///< books.* (canny_regions)
  PageFaceParams page_faces;            ///< page_faces.* (page_faces)
  bool measure_processing_time = true;  ///< diagnostics.measure_processing_time

  /// Reads the configuration root. Throws ConfigError naming a bad key.
  static BwhDetectorSettings from_config(const Config& root);
};

/// Decodes a hand image to RGB/grey and checks it against its calibration.
/// Returns false with a reason for an image that cannot be used.
bool decode_hand_image(const hand_image_t& msg, cv::Mat* image, std::string* reason);

/// BwH as a component.
class BwhDetectorNode : public Component {
 public:
  /// Subscribes the input and servo request channels.
  explicit BwhDetectorNode(const BwhDetectorSettings& settings);
  /// The handler's work without a bus: false and a reason for an unusable image. Fills
  /// `debug` (when not null and debug.publish_image is on) with the overlay as PNG.
  bool process(const hand_image_t& msg, book_features_hand_t* out, std::string* reason, image_t* debug = nullptr);
  /// The rank currently reported (0 = right-most).
  int rank_from_right() const { return rank_; }

 private:
  void on_image(const hand_image_t& msg);
  void on_request(const servo_request_t& msg);

  BwhDetectorSettings settings_;
  int rank_ = 0;
};

}  // namespace bookgrasp
