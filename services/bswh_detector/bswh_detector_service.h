#pragma once
/// @file
/// What the bswh_detector process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/bswh_detector/bswh_detector_node.h"

namespace bookgrasp {

/// The bswh_detector service.
inline ServiceDescription bswh_detector_service() {
  return ServiceDescription{
          "bswh_detector", "BSwH: black stripe and its end in HAND_IMAGE -> STRIPE_FEATURES_HAND",
          "config/services/bswh_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::BswhDetectorNode>(bookgrasp::BswhDetectorSettings::from_config(root));
          }};
}

}  // namespace bookgrasp
