// coordinator: the library task (take each book to the holder and then to the lower shelf) as a state machine.
#include "services/coordinator/coordinator_service.h"

int main(int argc, char** argv) { return bookgrasp::run_service_main(argc, argv, bookgrasp::coordinator_service()); }
