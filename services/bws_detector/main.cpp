/// @file
/// bws_detector process: P1 of the right-most book from STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO.
/// `service.implementation` (god | pcl) selects the planar segmentation; config/services/bws_detector.yaml
/// (GoD) and bws_detector_pcl.yaml (PCL) are the two shipped configurations.

#include <memory>

#include "common/process_main.h"
#include "services/bws_detector/bws_detector_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "bws_detector", "BwS: right-most book corner P1 from STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO",
          "config/services/bws_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::BwsDetectorNode>(bookgrasp::BwsDetectorSettings::from_config(root));
          }});
}
