/// @file
/// bswh_detector process: the black stripe and its end in the hand image.
#include "services/bswh_detector/bswh_detector_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::bswh_detector_service()); }
