// coordinator: the library task (take each book to the holder and then to the lower shelf) as a state machine.
#include "common/process_main.h"
#include "services/coordinator/coordinator_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      {"bookgrasp_coordinator", "coordinator: the library cycle (BwS, BSwH, BwH, grasp, holder, lower shelf), resumable",
       "config/services/coordinator.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::CoordinatorNode>(root); }});
}
