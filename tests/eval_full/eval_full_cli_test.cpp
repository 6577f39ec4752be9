// bookgrasp_eval_full as a tool: a configuration error stops it before any scene, with a message naming the key,
// and leaves nothing a later --resume would take for scene results.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

/// Runs the tool with `args`; returns its exit code and puts its stderr in `err`. The stderr file is the running
/// test's own: ctest runs the tests of this file side by side, and a shared file let one read the other's message
/// (the clean-clone CI of 180b7ea).
int run_tool(const std::string& args, std::string* err) {
  const std::string err_file = ::testing::TempDir() + "/eval_full_cli_err_" +
                               ::testing::UnitTest::GetInstance()->current_test_info()->name() + ".txt";
  const std::string cmd = std::string(BOOKGRASP_EVAL_FULL_EXE) + " " + args + " >/dev/null 2>" + err_file;
  const int rc = std::system(cmd.c_str());
  std::ifstream f(err_file);
  std::stringstream ss;
  ss << f.rdbuf();
  *err = ss.str();
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
}

TEST(EvalFullTool, ABadOverrideStopsBeforeAnySceneAndRecordsNothing) {
  const std::string out = ::testing::TempDir() + "/eval_full_bad_set";
  for (const auto& [set, named] :
       {std::pair<std::string, std::string>{"coordinator:geometry.grasp.no_such_key_m=0.005", "no_such_key_m"},
        {"coordinator:grasp.width_left_clearance_m=0.005", "no section 'grasp'"},
        {"coordinator:geometry.grasp.palm_half_width_m=0.5", "palm_half_width_m"},  // beyond its range
        {"coordinator-geometry=1", "not service:dotted.key=value"}}) {
    std::filesystem::remove_all(out);
    std::string err;
    EXPECT_EQ(run_tool("--scenes 3 --seed 1 --out " + out + " --set " + set, &err), 2) << set;
    EXPECT_NE(err.find("configuration:"), std::string::npos) << err;
    EXPECT_NE(err.find(named), std::string::npos) << err;
    EXPECT_EQ(err.find("scene 1/3"), std::string::npos) << "no scene may be reported: " << err;
    const bool recorded = std::filesystem::exists(out + "/scenes") && !std::filesystem::is_empty(out + "/scenes");
    EXPECT_FALSE(recorded) << set << ": a --resume would keep these as scene results";
  }
}

TEST(EvalFullTool, LogImagesWithoutLogIsRefusedByName) {
  const std::string out = ::testing::TempDir() + "/eval_full_log_images";
  std::filesystem::remove_all(out);
  std::string err;
  EXPECT_EQ(run_tool("--scenes 1 --seed 1 --out " + out + " --log-images", &err), 2);
  EXPECT_NE(err.find("--log-images records with --log"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(out + "/scenes")) << "no scene may have run";
}

}  // namespace
