/// @file
/// bswh_detector process: the black stripe and its end in the hand image.

#include <memory>

#include "common/process_main.h"
#include "services/bswh_detector/bswh_detector_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      bookgrasp::ServiceDescription{
          "bswh_detector", "BSwH: black stripe and its end in HAND_IMAGE -> STRIPE_FEATURES_HAND",
          "config/services/bswh_detector.yaml", [](const bookgrasp::Config& root) {
            return std::make_unique<bookgrasp::BswhDetectorNode>(bookgrasp::BswhDetectorSettings::from_config(root));
          }});
}
