#include "pipeline/slurm.h"

#include <algorithm>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "colmap/subprocess.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/workspace.h"
#include "core/workspace_lock.h"
#include "pipeline/dense_stages.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/stage_graph.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

fs::path SlurmFolder(const Workspace& workspace) { return workspace.Root() / "slurm"; }
fs::path DepthRequestFile(const Workspace& workspace) { return SlurmFolder(workspace) / "depth_request.json"; }

std::string ShellQuote(const std::string& word) {
  std::string quoted = "'";
  for (const char c : word) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted.push_back(c);
    }
  }
  return quoted + "'";
}

std::string CommandLine(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& word : argv) {
    if (!line.empty()) line += ' ';
    line += ShellQuote(word);
  }
  return line;
}

// A batch script running `commands` in order, stopping at the first that fails.
void WriteJobScript(const fs::path& path, const std::vector<std::string>& commands) {
  std::string script = "#!/bin/bash\nset -euo pipefail\n";
  for (const std::string& command : commands) script += command + "\n";
  WriteFileAtomically(path, script);
}

// A job to submit: the script <name>.sh, logged to logs/<name>-<id>.log; an array of
// `array_size` tasks unless 0.
struct Job {
  std::string name;
  int array_size = 0;
};

std::string RunSlurmTool(const std::vector<std::string>& argv, int* exit_code) {
  std::string output;
  try {
    *exit_code = RunProcess(argv, {}, [&](std::string_view line) { output += std::string(line) + "\n"; }).exit_code;
  } catch (const std::runtime_error& error) {
    throw ToolError(argv.front() + " cannot be started (" + error.what() +
                    "); is Slurm installed (apt-get install slurm-client)?");
  }
  return output;
}

// Submits the job `folder`/<name>.sh after `after` succeeded (if given); returns its id.
std::string Submit(const SlurmOptions& slurm, const fs::path& folder, const Job& job, const std::string& after,
                   bool wait) {
  const bool array = job.array_size > 0;
  std::vector<std::string> argv = {
      slurm.sbatch, "--parsable", "--job-name=parallax-" + job.name,
      "--output=" + (folder / "logs" / (job.name + (array ? "-%A_%a.log" : "-%j.log"))).string()};
  if (array) argv.push_back("--array=0-" + std::to_string(job.array_size - 1));
  argv.insert(argv.end(), slurm.sbatch_options.begin(), slurm.sbatch_options.end());
  if (!after.empty()) {
    // A failed task fails its dependents at once instead of leaving them pending forever.
    argv.insert(argv.end(), {"--dependency=afterok:" + after, "--kill-on-invalid-dep=yes"});
  }
  if (wait) argv.push_back("--wait");
  argv.push_back((folder / (job.name + ".sh")).string());
  int exit_code = 0;
  const std::string output = RunSlurmTool(argv, &exit_code);
  // --parsable prints "id" or "id;cluster"; --wait adds a line when the job ends.
  const std::string id = output.substr(0, output.find_first_of(";\n"));
  if (exit_code != 0 || id.empty() || !std::all_of(id.begin(), id.end(), ::isdigit)) {
    throw ToolError(CommandLine(argv) + " failed (exit status " + std::to_string(exit_code) + "): " + output +
                    "see " + (folder / "logs").string());
  }
  return id;
}

// Throws ToolError unless every task of every job completed. sbatch --wait exits 0 for a job
// cancelled because one before it failed, so the states are read back (scontrol keeps them
// for MinJobAge after the end, 300 s by default).
void CheckCompleted(const std::vector<std::string>& job_ids, const fs::path& folder) {
  for (const std::string& id : job_ids) {
    int exit_code = 0;
    const std::string output = RunSlurmTool({"scontrol", "--oneliner", "show", "job", id}, &exit_code);
    for (size_t at = output.find("JobState="); at != std::string::npos; at = output.find("JobState=", at + 1)) {
      const std::string state = output.substr(at + 9, output.find_first_of(" \n", at) - at - 9);
      if (state != "COMPLETED") {
        throw ToolError("slurm job " + id + " ended " + state + "; see its log in " + (folder / "logs").string());
      }
    }
  }
}

// The most views a depth pass can have: one per file in the photo folder.
int MaxViews(const fs::path& photos_dir) {
  int files = 0;
  for (const auto& entry : fs::directory_iterator(photos_dir)) {
    files += entry.is_regular_file() && !entry.path().filename().string().starts_with(".");
  }
  return files;
}

DepthRequest ReadDepthRequest(const Workspace& workspace) {
  const fs::path file = DepthRequestFile(workspace);
  try {
    return nlohmann::json::parse(ReadFileBytes(file)).get<DepthRequest>();
  } catch (const nlohmann::json::exception& error) {
    throw BadInputError(file.string() + " is not a depth request: " + error.what());
  }
}

// Submits `jobs` from `folder`, each after the one before succeeded; with slurm.wait, returns
// when the last has ended and throws unless every one completed.
SlurmSubmission SubmitChain(const SlurmOptions& slurm, const fs::path& folder, const std::vector<Job>& jobs) {
  SlurmSubmission submission{{}, folder};
  std::string after;
  for (const Job& job : jobs) {
    after = Submit(slurm, folder, job, after, slurm.wait && &job == &jobs.back());
    submission.job_ids.push_back(after);
  }
  if (slurm.wait) CheckCompleted(submission.job_ids, folder);
  return submission;
}

}  // namespace

SlurmSubmission SubmitReconstructToSlurm(const fs::path& photos_dir, const fs::path& workspace,
                                         const ReconstructOptions& options, const std::string& parallax,
                                         const std::vector<std::string>& reconstruct_arguments,
                                         const SlurmOptions& slurm) {
  if (options.stereo == StereoMethod::kSgbm) {
    throw BadInputError("--executor slurm splits PatchMatch's passes; --stereo sgbm runs locally only");
  }
  if (!fs::is_directory(photos_dir)) throw BadInputError("photo folder " + photos_dir.string() + " does not exist");
  const Workspace ws(workspace);
  const fs::path folder = SlurmFolder(ws);
  fs::create_directories(folder / "logs");
  const std::string reconstruct = CommandLine({parallax}) + " " + CommandLine(reconstruct_arguments);
  std::vector<Job> jobs;
  if (!options.estimate_depth) {
    WriteJobScript(folder / "sfm.sh", {reconstruct});
    jobs = {{"sfm"}};
  } else {
    WriteFileAtomically(DepthRequestFile(ws), nlohmann::json(DepthRequestOf(options)).dump(2) + "\n");
    const std::string depth_block = CommandLine({parallax, "depth-block", ws.Root().string()});
    const int tasks = std::max(1, (MaxViews(photos_dir) + slurm.block_size - 1) / slurm.block_size);
    const std::string block = " --block \"$SLURM_ARRAY_TASK_ID\" --block-size " + std::to_string(slurm.block_size);
    WriteJobScript(folder / "sfm.sh", {reconstruct + " --no-depth", depth_block + " prepare"});
    WriteJobScript(folder / "photometric.sh", {depth_block + " photometric" + block});
    WriteJobScript(folder / "geometric.sh", {depth_block + " geometric" + block});
    WriteJobScript(folder / "final.sh", {depth_block + " collect", reconstruct});
    jobs = {{"sfm"}, {"photometric", tasks}, {"geometric", tasks}, {"final"}};
  }
  return SubmitChain(slurm, folder, jobs);
}

SlurmSubmission SubmitRenderToSlurm(const fs::path& out, size_t frames, const std::string& parallax,
                                    const std::vector<std::string>& render_arguments, const SlurmOptions& slurm) {
  const fs::path folder = out / "slurm";
  fs::create_directories(folder / "logs");
  const std::string render = CommandLine({parallax}) + " " + CommandLine(render_arguments) + " --block-size " +
                             std::to_string(slurm.block_size) + " --job-step ";
  const int tasks = std::max(1, static_cast<int>((frames + slurm.block_size - 1) / slurm.block_size));
  WriteJobScript(folder / "prepare.sh", {render + "prepare"});
  WriteJobScript(folder / "frames.sh", {render + "frames --block \"$SLURM_ARRAY_TASK_ID\""});
  WriteJobScript(folder / "collect.sh", {render + "collect"});
  return SubmitChain(slurm, folder, {{"prepare"}, {"frames", tasks}, {"collect"}});
}

std::string RunDepthBlockStep(const fs::path& workspace, DepthBlockStep step, const MvsBlock& block,
                              Progress& progress) {
  const Workspace ws(workspace);
  const bool collect = step == DepthBlockStep::kCollect;
  // The tasks of an array write side by side; collecting writes what reconstruct reads.
  const WorkspaceLock lock(workspace, collect ? LockMode::kExclusive : LockMode::kShared, "depth-block");
  DepthRequest request = ReadDepthRequest(ws);
  request.collect_blocks = collect;
  StageGraph graph(ws, false);
  const Stage depth = DepthStage(ws, UndistortedModelKey(ws, graph), request, progress);
  if (graph.CompletedKey("depth") == depth.key && fs::exists(ws.DepthViews())) {
    return "depth already done for this model and these options";
  }
  switch (step) {
    case DepthBlockStep::kPrepare: {
      const ResumedViews resumed = PrepareEstimates(ws, depth.key);
      if (resumed.estimates + resumed.filtered > 0) {
        return "estimates kept: same model and options (" + std::to_string(resumed.estimates) + " estimates, " +
               std::to_string(resumed.filtered) + " filtered views)";
      }
      return "estimates ready for depth key " + depth.key;
    }
    case DepthBlockStep::kPhotometric:
    case DepthBlockStep::kGeometric: {
      if (!EstimatesMadeFor(ws, depth.key)) {
        throw BadInputError(ws.StereoEstimates().string() + " was not prepared for this model and these options "
                            "(run `parallax depth-block " + workspace.string() + " prepare` after SfM)");
      }
      const int views = RunMultiViewStereoBlock(ws, MvsOptionsOf(request), block, progress);
      return std::to_string(views) + " view(s) in block " + std::to_string(block.index);
    }
    case DepthBlockStep::kCollect:
      graph.Run(depth);
      return "depth stage completed from the blocks";
  }
  return "";
}

}  // namespace parallax
