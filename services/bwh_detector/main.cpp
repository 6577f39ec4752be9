/// @file
/// bwh_detector process: the right-most book and its corner R in the hand image.
#include "services/bwh_detector/bwh_detector_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::bwh_detector_service()); }
