// planner service: PLAN_REQUEST (+ MARKERS) -> PLAN_RESULT.
#include "common/process_main.h"
#include "services/planner/planner_node.h"

int main(int argc, char** argv) {
  using namespace bookgrasp;
  return run_service_main(argc, argv,
                          ServiceDescription{"planner", "collision-free arm trajectories (CellBiRRT, RRTConnect, BiTRRT)",
                                             "config/services/planner.yaml",
                                             [](const Config& root) -> std::unique_ptr<Component> {
                                               return std::make_unique<PlannerNode>(PlannerSettings::from_config(root));
                                             }});
}
