#pragma once
/// @file
/// What the arbiter process is (name, summary, default configuration, factory), shared by its
/// main() and by the offline tools (replay, evaluation) that build it in one process.

#include <memory>

#include "common/process_main.h"
#include "services/arbiter/arbiter_node.h"

namespace bookgrasp {

/// The arbiter service.
inline ServiceDescription arbiter_service() {
  return ServiceDescription{"arbiter", "arbiter: combination strategy of BwS, BSwH and BwH (paper Section 3) -> GRASP_POINT",
       "config/services/arbiter.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::ArbiterNode>(root); }};
}

}  // namespace bookgrasp
