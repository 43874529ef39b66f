#pragma once
// `reconstruct --executor slurm`: the request as a chain of Slurm jobs on storage every node
// shares. SfM runs as one job; the depth stage's photometric and geometric passes as job
// arrays, each task a block of views (pipeline/depth_workspace.h MvsBlock, not one view per
// task: each task reads the model), the geometric array only after every photometric task
// succeeded (afterok); then one job collects the depth maps and runs fusion, mesh and texture.
// Every task writes atomically and skips views already done, so a failed or pre-empted task is
// simply resubmitted. The stage keys are a local run's: a workspace moves freely between the
// two, and the files are the same.
#include <filesystem>
#include <string>
#include <vector>

#include "core/progress.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/reconstruct_options.h"

namespace parallax {

struct SlurmOptions {
  int block_size = 8;                       // Views (or frames) per array task.
  std::vector<std::string> sbatch_options;  // Given to every sbatch: partition, time, memory, CPUs.
  bool wait = false;                        // Return when the last job has ended (sbatch --wait).
  std::string sbatch = "sbatch";
};

struct SlurmSubmission {
  std::vector<std::string> job_ids;  // In the order they run.
  std::filesystem::path folder;      // <ws>/slurm: the job scripts and their logs.
};

// Writes the job scripts to <ws>/slurm and submits them. `parallax` is this executable, and
// `reconstruct_arguments` the reconstruct command line each job repeats (photos, workspace
// and options, not the executor's). Throws ToolError when sbatch fails (or, with `wait`, a
// job does), BadInputError for options the executor cannot split (SGBM stereo).
SlurmSubmission SubmitReconstructToSlurm(const std::filesystem::path& photos_dir,
                                         const std::filesystem::path& workspace,
                                         const ReconstructOptions& options,
                                         const std::string& parallax,
                                         const std::vector<std::string>& reconstruct_arguments,
                                         const SlurmOptions& slurm);

// `render --executor slurm`: one job writes what every frame reads (color gains, missing
// depth), a job array renders the `frames` cameras a block each (`slurm.block_size` frames per
// task), and one job collects the blocks into render.csv and report.json
// (pipeline/render_request.h RenderStep); the scripts and logs go to <out>/slurm.
// `render_arguments` is the render command line each job repeats, less the executor's options.
SlurmSubmission SubmitRenderToSlurm(const std::filesystem::path& out, size_t frames, const std::string& parallax,
                                    const std::vector<std::string>& render_arguments, const SlurmOptions& slurm);

// The steps of `parallax depth-block`, which the jobs run between SfM and fusion.
enum class DepthBlockStep {
  kPrepare,      // After SfM: removes estimates left for another model or other options.
  kPhotometric,  // RunMultiViewStereoBlock of one block.
  kGeometric,
  kCollect,      // The depth stage completed from the blocks, as a local run records it.
};

// Runs one step on the workspace with the depth request the submission saved. Returns what
// it did, for the job's log.
std::string RunDepthBlockStep(const std::filesystem::path& workspace, DepthBlockStep step,
                              const MvsBlock& block, Progress& progress);

}  // namespace parallax
