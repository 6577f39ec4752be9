// arm_driver: executes arm and gripper commands within limits; streams setpoints; reports ARM_STATE.
#include "services/arm_driver/arm_driver_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::arm_driver_service()); }
