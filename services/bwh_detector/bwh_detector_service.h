#pragma once
/// @file
/// What the bwh_detector process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/bwh_detector/bwh_detector_node.h"

namespace bookgrasp {

/// The bwh_detector service.
inline ServiceDescription bwh_detector_service() {
  return ServiceDescription{
          "bwh_detector", "BwH: right-most book, corner R and slope in HAND_IMAGE -> BOOK_FEATURES_HAND",
          "config/services/bwh_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::BwhDetectorNode>(bookgrasp::BwhDetectorSettings::from_config(root));
          }};
}

}  // namespace bookgrasp
