#include "pipeline/stage_graph.h"

#include "core/elapsed.h"
#include "core/memory.h"

#include <algorithm>
#include <chrono>

namespace parallax {
namespace fs = std::filesystem;
namespace {

bool AllExist(const std::vector<fs::path>& paths) {
  return std::all_of(paths.begin(), paths.end(), [](const fs::path& path) { return fs::exists(path); });
}

}  // namespace

StageGraph::StageGraph(const Workspace& workspace, bool dry_run)
    : cache_(workspace.Stages()), dry_run_(dry_run) {}

void StageGraph::Run(const Stage& stage) {
  StageRecord record{stage.name, false, "", 0, 0, 0, 0};
  const bool outputs_exist = AllExist(stage.outputs);
  if (cache_.IsDone(stage.name, stage.key) && outputs_exist) {
    record.skipped = true;
    record.reason = "inputs and options unchanged since the last run";
  } else if (dry_run_) {
    record.skipped = !stage.not_needed.empty();
    record.reason = !stage.not_needed.empty() ? stage.not_needed
                    : outputs_exist           ? "inputs or options changed"
                                              : "not run yet";
  } else {
    ReturnFreedMemory();
    ResetPeakResidentMemory();
    const double cpu_start = CpuSeconds();
    const auto start = std::chrono::steady_clock::now();
    stage.run();
    record.seconds = SecondsSince(start);
    record.peak_rss_mb = PeakResidentMemoryMb();
    record.tool_peak_rss_mb = PeakChildResidentMemoryMb();
    record.cpu_seconds = CpuSeconds() - cpu_start;
    cache_.MarkDone(stage.name, stage.key);
    record.skipped = !stage.not_needed.empty();
    record.reason = stage.not_needed;
  }
  records_.push_back(record);
}

std::optional<std::string> StageGraph::CompletedKey(const std::string& stage) const {
  return cache_.KeyOf(stage);
}

}  // namespace parallax
