// arbiter: fuses P1 (BwS), PS (BSwH) and P2 (BwH) with the paper's combination strategy; publishes GRASP_POINT.
#include "services/arbiter/arbiter_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::arbiter_service()); }
