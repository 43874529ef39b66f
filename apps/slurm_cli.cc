#include "apps/slurm_cli.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"

namespace parallax {

SlurmOptions SlurmCli::Resolve() const {
  // Whitespace-separated words, from --sbatch and from --sbatch-file (where '#' starts a comment).
  std::string text = sbatch;
  if (!sbatch_file.empty()) {
    std::istringstream lines(ReadFileBytes(sbatch_file));
    for (std::string line; std::getline(lines, line);) text += " " + line.substr(0, line.find('#'));
  }
  SlurmOptions options = slurm;
  std::istringstream words(text);
  for (std::string word; words >> word;) options.sbatch_options.push_back(word);
  return options;
}

void AddSlurmOptions(CLI::App& command, SlurmCli& cli, const std::string& what, const std::string& block) {
  command.add_option("--executor", cli.executor,
                     "local (default), or slurm: submit " + what +
                         " as Slurm jobs on storage every node shares, and return")
      ->check(CLI::IsMember({"local", "slurm"}));
  command.add_option("--slurm-block-size", cli.slurm.block_size,
                     block + " with --executor slurm (default " + std::to_string(SlurmOptions().block_size) + ")")
      ->check(CLI::Range(1, 100000));
  command.add_option("--sbatch", cli.sbatch,
                     "options for every sbatch, e.g. \"--partition=cpu --time=2:00:00 --mem=8G "
                     "--cpus-per-task=8\"");
  command.add_option("--sbatch-file", cli.sbatch_file, "file of sbatch options (one or more per line, # comments)")
      ->check(CLI::ExistingFile);
  command.add_flag("--slurm-wait", cli.slurm.wait,
                   "with --executor slurm: return when the last job has ended, with its status");
}

std::vector<std::string> JobArguments(const CLI::App& command, const std::vector<std::filesystem::path>& positionals,
                                      const std::vector<std::string>& path_options) {
  std::vector<std::string> arguments = {command.get_name()};
  for (const std::filesystem::path& path : positionals) arguments.push_back(std::filesystem::absolute(path).string());
  for (const CLI::Option* option : command.get_options()) {
    const std::string name = option->get_name();
    if (option->count() == 0 || option->get_positional() || name == "--help" || name == "--executor" ||
        name.starts_with("--slurm") || name.starts_with("--sbatch")) {
      continue;
    }
    arguments.push_back(name);
    if (option->get_type_size() == 0) continue;
    const bool path = std::find(path_options.begin(), path_options.end(), name) != path_options.end();
    for (const std::string& value : option->results()) {
      arguments.push_back(path ? std::filesystem::absolute(value).string() : value);
    }
  }
  return arguments;
}

std::string ThisExecutable() { return std::filesystem::canonical("/proc/self/exe").string(); }

void PrintSubmission(const SlurmSubmission& submission, bool waited) {
  std::string ids;
  for (const std::string& id : submission.job_ids) ids += (ids.empty() ? "" : ",") + id;
  std::printf("slurm: submitted jobs %s (scripts and logs in %s)\n", ids.c_str(), submission.folder.c_str());
  if (!waited) std::printf("slurm: follow them with `squeue -j %s`\n", ids.c_str());
}

}  // namespace parallax
