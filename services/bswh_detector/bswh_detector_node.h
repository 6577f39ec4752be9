#pragma once
/// @file
/// The bswh_detector component: HAND_IMAGE -> STRIPE_FEATURES_HAND.

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
  /// The handler's work without a bus: false and a reason for an unusable image.
  bool process(const hand_image_t& msg, stripe_features_t* out, std::string* reason);

 private:
  void on_image(const hand_image_t& msg);
  BswhDetectorSettings settings_;
};

}  // namespace bookgrasp
