#pragma once
// The executor options `reconstruct` and `render` share (--executor, --slurm-block-size,
// --sbatch, --sbatch-file, --slurm-wait), and what both do with them.
#include <filesystem>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pipeline/slurm.h"

namespace parallax {

struct SlurmCli {
  std::string executor = "local";
  SlurmOptions slurm;
  std::string sbatch;
  std::filesystem::path sbatch_file;

  bool OnSlurm() const { return executor == "slurm"; }
  // The options with the sbatch words read from --sbatch and --sbatch-file.
  SlurmOptions Resolve() const;
};

// Adds the options to `command`; `what` says what the jobs run ("SfM, the depth passes as job
// arrays and the rest"), `block` what a task's block holds ("views per depth task").
void AddSlurmOptions(CLI::App& command, SlurmCli& cli, const std::string& what, const std::string& block);

// The command line as given, for the cluster's jobs to repeat: the subcommand's name, then
// `positionals`, then every option used except the executor's own; the positionals and the
// values of `path_options` made absolute.
std::vector<std::string> JobArguments(const CLI::App& command, const std::vector<std::filesystem::path>& positionals,
                                      const std::vector<std::string>& path_options = {});

// This executable, for the jobs to run.
std::string ThisExecutable();

void PrintSubmission(const SlurmSubmission& submission, bool waited);

}  // namespace parallax
