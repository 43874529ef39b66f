#include "pipeline/stage_graph.h"

#include <stdexcept>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// A stage that writes `output` and counts its runs.
Stage Counting(const std::string& key, const std::filesystem::path& output, int* runs) {
  return {"stage", key, {output}, [output, runs] {
            ++*runs;
            WriteFileAtomically(output, "done");
          }, ""};
}

TEST(StageGraph, RunsOnceThenSkipsUntilTheKeyOrTheOutputChanges) {
  const TempDir dir;
  const Workspace workspace(dir.Path());
  const std::filesystem::path output = dir.Path() / "out.txt";
  int runs = 0;
  {
    StageGraph graph(workspace, false);
    graph.Run(Counting("a", output, &runs));
    ASSERT_EQ(graph.Records().size(), 1u);
    EXPECT_FALSE(graph.Records()[0].skipped);
    EXPECT_EQ(graph.CompletedKey("stage"), "a");
  }
  StageGraph again(workspace, false);  // A new process reads stages.json.
  again.Run(Counting("a", output, &runs));
  EXPECT_EQ(runs, 1);
  EXPECT_TRUE(again.Records().back().skipped);
  EXPECT_EQ(again.Records().back().reason, "inputs and options unchanged since the last run");
  again.Run(Counting("b", output, &runs));
  EXPECT_EQ(runs, 2) << "a new key runs the stage";
  std::filesystem::remove(output);
  again.Run(Counting("b", output, &runs));
  EXPECT_EQ(runs, 3) << "a missing output runs the stage";
  EXPECT_EQ(again.CompletedKey("other"), std::nullopt);
}

TEST(StageGraph, DryRunPlansWithTheReasonAndRunsNothing) {
  const TempDir dir;
  const std::filesystem::path output = dir.Path() / "out.txt";
  int runs = 0;
  StageGraph plan(Workspace(dir.Path()), true);
  plan.Run(Counting("a", output, &runs));
  EXPECT_EQ(runs, 0);
  EXPECT_FALSE(plan.Records()[0].skipped);
  EXPECT_EQ(plan.Records()[0].reason, "not run yet");
  WriteFileAtomically(output, "stale");
  plan.Run(Counting("a", output, &runs));
  EXPECT_EQ(plan.Records()[1].reason, "inputs or options changed");
  EXPECT_FALSE(std::filesystem::exists(Workspace(dir.Path()).Stages()));
}

TEST(StageGraph, AStageNotNeededIsReportedSkippedWithItsReason) {
  const TempDir dir;
  int runs = 0;
  Stage stage = Counting("a", dir.Path() / "out.txt", &runs);
  stage.not_needed = "nothing to resample";
  StageGraph graph(Workspace(dir.Path()), false);
  graph.Run(stage);
  EXPECT_EQ(runs, 1) << "the little that remains still runs";
  EXPECT_TRUE(graph.Records()[0].skipped);
  EXPECT_EQ(graph.Records()[0].reason, "nothing to resample");
}

TEST(StageGraph, AnInterruptedStageIsNotRecordedAndRunsAgain) {
  const TempDir dir;
  const Workspace workspace(dir.Path());
  const std::filesystem::path output = dir.Path() / "out.txt";
  Stage failing{"stage", "a", {output}, [output] {
                  WriteFileAtomically(output, "partial");
                  throw std::runtime_error("interrupted");
                }, ""};
  StageGraph graph(workspace, false);
  EXPECT_THROW(graph.Run(failing), std::runtime_error);
  EXPECT_EQ(graph.CompletedKey("stage"), std::nullopt);
  int runs = 0;
  StageGraph again(workspace, false);
  again.Run(Counting("a", output, &runs));
  EXPECT_EQ(runs, 1);
}

}  // namespace
}  // namespace parallax
