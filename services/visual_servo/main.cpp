/// @file
/// visual_servo process: IBVS on the book corner R (P2) and PBVS along the black stripe (PS).

#include "services/visual_servo/visual_servo_service.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(argc, argv, bookgrasp::visual_servo_service());
}
