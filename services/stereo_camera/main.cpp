/// @file
/// stereo_camera process: STEREO_IMAGES from the simulation (SIM_STATE) or from image files.
#include "services/stereo_camera/stereo_camera_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::stereo_camera_service()); }
