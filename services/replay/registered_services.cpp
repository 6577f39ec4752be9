// The production services known to offline tools. Add a service here when it has a node.
#include "services/replay/component_registry.h"

namespace bookgrasp {

ComponentRegistry project_services() {
  ComponentRegistry r;
  return r;
}

}  // namespace bookgrasp
