/// @file
/// bwh_detector process: the right-most book and its corner R in the hand image.

#include <memory>

#include "common/process_main.h"
#include "services/bwh_detector/bwh_detector_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "bwh_detector", "BwH: right-most book, corner R and slope in HAND_IMAGE -> BOOK_FEATURES_HAND",
          "config/services/bwh_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::BwhDetectorNode>(bookgrasp::BwhDetectorSettings::from_config(root));
          }});
}
