#pragma once
/// @file
/// What the bws_detector process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation). `service.implementation` (god | pcl) selects
/// the planar segmentation; config/services/bws_detector.yaml (GoD) and bws_detector_pcl.yaml (PCL).

#include <memory>

#include "common/process_main.h"
#include "services/bws_detector/bws_detector_node.h"

namespace bookgrasp {

/// The bws_detector service.
inline ServiceDescription bws_detector_service() {
  return ServiceDescription{
      "bws_detector", "BwS: right-most book corner P1 from STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO",
      "config/services/bws_detector.yaml",
      [](const Config& root) { return std::make_unique<BwsDetectorNode>(BwsDetectorSettings::from_config(root)); }};
}

}  // namespace bookgrasp
