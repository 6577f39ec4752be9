/// @file
/// marker_detector process: AprilTag markers of the left stereo image.
#include "services/marker_detector/marker_detector_service.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(argc, argv, bookgrasp::marker_detector_service());
}
