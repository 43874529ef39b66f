#pragma once
// The stages of a request as data, and the graph that plans, skips and runs them. A stage's
// key hashes its inputs and options, its upstream stages' keys included, so a change anywhere
// upstream reaches every stage after it; <ws>/stages.json (StageCache) holds the key each
// stage last completed with.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/workspace.h"
#include "pipeline/stage_cache.h"

namespace parallax {

struct Stage {
  std::string name;
  std::string key;
  // Files that exist once the stage completed (a stage is skipped only while they all do).
  std::vector<std::filesystem::path> outputs;
  // Computes the outputs, each written atomically or moved into place whole.
  std::function<void()> run;
  // Non-empty: why the stage's real work is not needed for this scene (`run` then does only
  // the little that remains); the stage is reported as skipped, with this reason.
  std::string not_needed;
};

// What became of a stage: run (and how long it took), or skipped and why; in a dry run,
// skipped or "will run" and why.
struct StageRecord {
  std::string name;
  bool skipped = false;
  std::string reason;
  double seconds = 0;
  // Peak resident memory of this process while the stage ran, and the largest of the colmap
  // processes it ran (each on its own, beside this one); 0 when it did not run (or ran none).
  double peak_rss_mb = 0;
  double tool_peak_rss_mb = 0;
  // CPU time of this process and the colmap processes it ran while the stage ran.
  double cpu_seconds = 0;
};

class StageGraph {
 public:
  // With `dry_run`, stages are planned (recorded with the reason they would run), never run.
  StageGraph(const Workspace& workspace, bool dry_run);

  // Runs `stage` unless it completed before with the same key and its outputs exist; records
  // what happened either way.
  void Run(const Stage& stage);

  // The key `stage` last completed with in this workspace, if any.
  std::optional<std::string> CompletedKey(const std::string& stage) const;

  bool DryRun() const { return dry_run_; }
  // StageCache::Damage of the workspace's stages.json.
  const std::string& CacheDamage() const { return cache_.Damage(); }
  const std::vector<StageRecord>& Records() const { return records_; }

 private:
  StageCache cache_;
  bool dry_run_;
  std::vector<StageRecord> records_;
};

}  // namespace parallax
