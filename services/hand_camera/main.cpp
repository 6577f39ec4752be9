/// @file
/// hand_camera process: HAND_IMAGE from the simulation (SIM_STATE) or from image files.
#include "services/hand_camera/hand_camera_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::hand_camera_service()); }
