#pragma once
/// @file
/// What the marker_detector process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/marker_detector/marker_detector_node.h"

namespace bookgrasp {

/// The marker_detector service.
inline ServiceDescription marker_detector_service() {
  return ServiceDescription{
      "marker_detector", "AprilTag 3 markers (cart, holder) of the left stereo image -> MARKERS",
      "config/services/marker_detector.yaml", [](const bookgrasp::Config& root) {
        return std::make_unique<bookgrasp::MarkerDetectorNode>(bookgrasp::MarkerDetectorSettings::from_config(root));
      }};
}

}  // namespace bookgrasp
