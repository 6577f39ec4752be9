/// @file
/// marker_detector process: AprilTag markers of the left stereo image.

#include <memory>

#include "common/process_main.h"
#include "services/marker_detector/marker_detector_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "marker_detector", "AprilTag 3 markers (cart, holder) of the left stereo image -> MARKERS",
          "config/services/marker_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::MarkerDetectorNode>(
                bookgrasp::MarkerDetectorSettings::from_config(root));
          }});
}
