#pragma once
// The depth stage over a workspace: multi-view stereo (mvs/mvs.h) for the views of <ws>/sparse
// (undistorted PINHOLE) from the photos of <ws>/images, writing docs/design.md's dense files
// (COLMAP format under <ws>/stereo, EXR depth + confidence under <ws>/depth); the same in
// blocks that separate processes (cluster jobs, pipeline/slurm.h) can run; and the StereoSGBM
// baseline (mvs/sgbm.h).
#include "core/progress.h"
#include "core/workspace.h"
#include "mvs/mvs.h"
#include "mvs/sgbm.h"

namespace parallax {

// What an interrupted depth stage left in <ws>/stereo/estimates that a new run can keep.
struct ResumedViews {
  int estimates = 0;  // Views' PatchMatch estimates.
  int filtered = 0;   // Views' filtered maps (their reports).
};

// Readies <ws>/stereo/estimates for a depth stage with `key` (its hash of model and options):
// kept when it was made for that key, with every estimate and report checked whole (a
// damaged one is removed, and its view computed again); else emptied and marked with the key.
ResumedViews PrepareEstimates(const Workspace& workspace, const std::string& key);
// Whether <ws>/stereo/estimates was readied for `key`.
bool EstimatesMadeFor(const Workspace& workspace, const std::string& key);

// Reads <ws>/sparse and <ws>/images. Throws BadInputError for a missing model or image.
// PrepareEstimates(key), every block of both passes, then FinishMultiViewStereoBlocks: a run
// cut short resumes with the views it finished when run again with the same key.
MvsSummary RunMultiViewStereo(const Workspace& workspace, const MvsOptions& options, const std::string& key,
                              Progress& progress);

// The depth stage in parts that separate processes can run: block `index` of `size`
// consecutive views of one pass (size 0: every view). Every photometric block must be done
// before a geometric block starts, since a view is checked against its sources' estimates.
enum class MvsPass { kPhotometric, kGeometric };
struct MvsBlock {
  MvsPass pass;
  int index = 0;
  int size = 0;
};

// Runs one block. Photometric: PatchMatch, each view's estimate to <ws>/stereo/estimates;
// geometric: the filter, each view's depth maps, then its report beside the estimates. A view
// whose estimate (or report) exists is not computed again, so a resubmitted job redoes only
// what is missing. Returns the number of views in the block (0: past the last one).
int RunMultiViewStereoBlock(const Workspace& workspace, const MvsOptions& options, const MvsBlock& block,
                            Progress& progress);

// Once every block ran: the summary from the views' reports (seconds left 0), and the
// estimates removed. Throws BadInputError naming a view whose report is missing.
MvsSummary FinishMultiViewStereoBlocks(const Workspace& workspace, const MvsOptions& options);

// Writes <ws>/depth/<stem>.exr and <stem>.confidence.exr for every view with a usable pair
// (mvs/sgbm.h SgbmViewDepth, after both options' Check()); no normal maps (so fusion leaves
// SGBM views out). Views without a source to their right are listed in `skipped`.
MvsSummary RunSgbmStereo(const Workspace& workspace, const ViewSelectionOptions& views, const SgbmOptions& options,
                         Progress& progress);

}  // namespace parallax
