#include <fstream>

#include <gtest/gtest.h>

#include "tests/cli_runner.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

TEST(Cli, HelpExitsZeroAndNamesEveryCommand) {
  const CliResult result = RunParallax("--help");
  EXPECT_EQ(result.exit_code, 0);
  for (const char* command : {"synth", "reconstruct", "render", "evaluate", "view", "bench"}) {
    EXPECT_NE(result.output.find(command), std::string::npos) << command;
  }
  EXPECT_EQ(RunParallax("synth --help").exit_code, 0);
  EXPECT_EQ(RunParallax("reconstruct --help").exit_code, 0);
}

TEST(Cli, UsageErrorsExitOne) {
  EXPECT_EQ(RunParallax("").exit_code, 1);
  EXPECT_EQ(RunParallax("no-such-command").exit_code, 1);
  EXPECT_EQ(RunParallax("synth").exit_code, 1);
  EXPECT_EQ(RunParallax("reconstruct a b --quality ultra").exit_code, 1);
  EXPECT_EQ(RunParallax("render scene --out o --fill blur").exit_code, 1);
  EXPECT_EQ(RunParallax("bench").exit_code, 1);
}

TEST(Cli, SynthWithMalformedJsonExitsTwoNamingTheFileAndLine) {
  const TempDir dir;
  const auto scene = dir.Path() / "broken scene.json";
  std::ofstream(scene) << "{\n  \"objects\": [\n    {\"type\": \"sphere\",,}\n  ]\n}\n";
  const CliResult result = RunParallax("synth " + Quote(scene.string()) + " " +
                                       Quote((dir.Path() / "out").string()));
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_NE(result.output.find("broken scene.json"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("line 3"), std::string::npos) << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir.Path() / "out"));
}

TEST(Cli, SynthWithAMissingSceneFileExitsTwo) {
  const CliResult result = RunParallax("synth /nonexistent/scene.json /tmp/unused");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_NE(result.output.find("/nonexistent/scene.json"), std::string::npos) << result.output;
}

}  // namespace
}  // namespace parallax
