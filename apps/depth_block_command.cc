#include <cstdio>
#include <map>
#include <memory>

#include "apps/commands.h"
#include "apps/terminal_progress.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/slurm.h"

namespace parallax {

void RegisterDepthBlockCommand(CLI::App& app) {
  struct Arguments {
    std::filesystem::path workspace;
    DepthBlockStep step = DepthBlockStep::kPrepare;
    MvsBlock block{MvsPass::kPhotometric, 0, 0};
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "depth-block",
      "One step of the depth stage as `reconstruct --executor slurm` splits it (the jobs run "
      "it; pipeline/slurm.h): prepare after SfM, photometric or geometric for one block of "
      "views, collect before fusion. Views already done are skipped.");
  command->add_option("workspace", arguments->workspace, "workspace the SfM job wrote")->required();
  const std::map<std::string, DepthBlockStep> steps = {{"prepare", DepthBlockStep::kPrepare},
                                                      {"photometric", DepthBlockStep::kPhotometric},
                                                      {"geometric", DepthBlockStep::kGeometric},
                                                      {"collect", DepthBlockStep::kCollect}};
  command->add_option("step", arguments->step, "prepare, photometric, geometric or collect")
      ->required()
      ->transform(CLI::CheckedTransformer(steps, CLI::ignore_case));
  command->add_option("--block", arguments->block.index, "block number, from 0 (SLURM_ARRAY_TASK_ID)")
      ->check(CLI::NonNegativeNumber);
  command->add_option("--block-size", arguments->block.size, "views per block (default 0: every view)")
      ->check(CLI::NonNegativeNumber);
  command->callback([arguments] {
    MvsBlock block = arguments->block;
    block.pass = arguments->step == DepthBlockStep::kGeometric ? MvsPass::kGeometric : MvsPass::kPhotometric;
    std::string done;
    {
      TerminalProgress progress;
      done = RunDepthBlockStep(arguments->workspace, arguments->step, block, progress);
    }
    std::printf("depth-block: %s\n", done.c_str());
  });
}

}  // namespace parallax
