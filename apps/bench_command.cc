#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <memory>

#include "apps/commands.h"
#include "bench/bench_runner.h"

namespace parallax {

void RegisterBenchCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path scene;
    std::filesystem::path out;
    BenchGrid grid = BenchGrid::kFull;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "bench",
      "Run every stage on a scene with ground truth under a grid of settings and against "
      "baselines (COLMAP automatic_reconstructor, OpenCV StereoSGBM, a naive warp with OpenCV "
      "inpainting); writes bench.csv, error_vs_time.png and report.md. About 15 minutes on the "
      "courtyard with 2 cores.");
  command->add_option("scene_dir", arguments->scene, "scene folder (parallax synth output)")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("out_dir", arguments->out, "where the workspaces and the report go")->required();
  command
      ->add_option("--grid", arguments->grid,
                   "full: every setting of every knob; smoke: each stage and baseline with the few "
                   "settings the test suite compares (a quick check that the bench works)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, BenchGrid>{{"full", BenchGrid::kFull},
                                                                           {"smoke", BenchGrid::kSmoke}},
                                          CLI::ignore_case))
      ->default_str("full");
  command->callback([arguments] {
    const BenchSummary summary = RunBench(arguments->scene, arguments->out, arguments->grid);
    std::printf("bench: %zu runs in %.0f s -> %s (report.md, bench.csv, error_vs_time.png)\n",
                summary.runs, summary.seconds, arguments->out.string().c_str());
  });
}

}  // namespace parallax
