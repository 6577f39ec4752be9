#pragma once
/// @file
/// The bswh_detector component: HAND_IMAGE -> STRIPE_FEATURES_HAND.
/// With debug.publish_image, also BSWH_DEBUG_IMAGE: a PNG of the stripe line and its end.

#include <string>

#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/stripe_features_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/bswh_detector/stripe_detection.h"

namespace bookgrasp {

/// Everything the BSwH node reads from its configuration.
struct BswhDetectorSettings {
  std::string input_channel;            ///< channels.input (hand_image_t)
  std::string output_channel;           ///< channels.output (stripe_features_t)
  std::string debug_image_channel;      ///< channels.debug_image (image_t, PNG)
  bool publish_debug_image = false;     ///< debug.publish_image
  StripeDetectionParams stripe;         ///< stripe.*
  bool measure_processing_time = true;  ///< diagnostics.measure_processing_time

  /// Reads the configuration root. Throws ConfigError naming a bad key.
  static BswhDetectorSettings from_config(const Config& root);
};

/// BSwH as a component.
class BswhDetectorNode : public Component {
 public:
  /// Subscribes the input channel.
  explicit BswhDetectorNode(const BswhDetectorSettings& settings);
  /// The handler's work without a bus: false and a reason for an unusable image. Fills
  /// `debug` (when not null and debug.publish_image is on) with the overlay as PNG.
  bool process(const hand_image_t& msg, stripe_features_t* out, std::string* reason, image_t* debug = nullptr);

 private:
  void on_image(const hand_image_t& msg);
  BswhDetectorSettings settings_;
};

}  // namespace bookgrasp
