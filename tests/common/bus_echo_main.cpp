// Test fixture process: the EchoComponent under the real process runtime.
#include "common/process_main.h"
#include "tests/common/echo_component.h"

int main(int argc, char** argv) {
  return bookgrasp::run_service_main(
      argc, argv,
      {"bookgrasp_test_echo", "echo service for the runtime tests", "tests/common/echo.yaml",
       [](const bookgrasp::Config& root) { return std::make_unique<bookgrasp_test::EchoComponent>(root); }});
}
