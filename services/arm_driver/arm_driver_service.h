#pragma once
/// @file
/// What the arm_driver process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/arm_driver/arm_driver_node.h"

namespace bookgrasp {

/// The arm_driver service.
inline ServiceDescription arm_driver_service() {
  return ServiceDescription{"arm_driver", "arm driver: trajectories, Cartesian velocity, gripper; limits and heartbeat",
       "config/services/arm_driver.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::ArmDriverNode>(root); }};
}

}  // namespace bookgrasp
