// planner service: PLAN_REQUEST (+ MARKERS) -> PLAN_RESULT.
#include "services/planner/planner_service.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(argc, argv, bookgrasp::planner_service());
}
