#pragma once
// `parallax bench`: every stage on a scene with ground truth under a grid of settings, each run
// in a child process (wall time and peak memory), against baselines, reported as error
// against run time (bench_report.h).
#include <filesystem>

#include "bench/bench_report.h"

namespace parallax {

// How many settings per stage: every knob the report plots, or a smoke run of the same code
// (each stage, each baseline and the settings a check compares) for the test suite.
enum class BenchGrid { kFull, kSmoke };

struct BenchSummary {
  size_t runs = 0;     // Child runs measured.
  double seconds = 0;  // Wall time of the whole bench.
};

// Runs the bench on `scene_dir` (a scene folder made by parallax synth) under `grid`, its
// workspaces, logs and report (bench.csv, error_vs_time.png, report.md) in `out_dir`. The children are this
// executable (/proc/self/exe) and colmap. Throws BadInputError for a scene without ground
// truth, ToolError when a child fails (its log named).
BenchSummary RunBench(const std::filesystem::path& scene_dir, const std::filesystem::path& out_dir,
                      BenchGrid grid = BenchGrid::kFull);

}  // namespace parallax
