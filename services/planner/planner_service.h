#pragma once
/// @file
/// What the planner process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay) that build it in one process, so a recorded PLAN_REQUEST
/// can be planned again from a log with the shipped or a changed configuration.

#include <memory>

#include "common/process_main.h"
#include "services/planner/planner_node.h"

namespace bookgrasp {

/// The planner service.
inline ServiceDescription planner_service() {
  return ServiceDescription{"planner", "collision-free arm trajectories (CellBiRRT, RRTConnect, BiTRRT)",
                            "config/services/planner.yaml", [](const Config& root) -> std::unique_ptr<Component> {
                              return std::make_unique<PlannerNode>(PlannerSettings::from_config(root));
                            }};
}

}  // namespace bookgrasp
