#pragma once
/// @file
/// What the coordinator process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/coordinator/coordinator_node.h"

namespace bookgrasp {

/// The coordinator service.
inline ServiceDescription coordinator_service() {
  return ServiceDescription{"coordinator", "coordinator: the library cycle (BwS, BSwH, BwH, grasp, holder, lower shelf), resumable",
       "config/services/coordinator.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::CoordinatorNode>(root); }};
}

}  // namespace bookgrasp
