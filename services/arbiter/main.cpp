// arbiter: fuses P1 (BwS), PS (BSwH) and P2 (BwH) with the paper's combination strategy; publishes GRASP_POINT.
#include "common/process_main.h"
#include "services/arbiter/arbiter_node.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      {"bookgrasp_arbiter", "arbiter: combination strategy of BwS, BSwH and BwH (paper Section 3) -> GRASP_POINT",
       "config/services/arbiter.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp::ArbiterNode>(root); }});
}
