/// @file
/// bws_detector process: P1 of the right-most book from STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO.
#include "services/bws_detector/bws_detector_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::bws_detector_service()); }
