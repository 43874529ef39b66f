// The depth stage run in blocks, as cluster jobs run it, writes what one run writes.
#include <filesystem>
#include <map>

#include <gtest/gtest.h>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/workspace.h"
#include "mvs/mvs.h"
#include "pipeline/depth_workspace.h"
#include "pipeline/reconstruct.h"
#include "tests/temp_dir.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

namespace fs = std::filesystem;

const fs::path kSmall = SourceDir() / "example_images" / "small";

// Every file under `dir`, by its path relative to `dir`, with its bytes.
std::map<std::string, std::string> FilesUnder(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (entry.is_regular_file()) files[fs::relative(entry.path(), dir).string()] = ReadFileBytes(entry.path());
  }
  return files;
}

TEST(MvsBlocks, BlocksInAnyOrderAndRerunWriteWhatOneRunWrites) {
  const TempDir dir;
  SilentProgress progress;
  // Known cameras: the same model in both workspaces without trusting colmap to repeat itself.
  ReconstructOptions sfm;
  sfm.known_cameras = kSmall / "gt" / "sparse";
  sfm.estimate_depth = false;
  sfm.build_mesh = false;
  const fs::path one_run = dir.Path() / "one_run";
  Reconstruct(kSmall / "images", one_run, sfm, progress);
  const fs::path blocks_dir = dir.Path() / "blocks";
  fs::copy(one_run, blocks_dir, fs::copy_options::recursive);
  const Workspace blocks(blocks_dir);

  MvsOptions options = MvsOptionsFor(Quality::kFast);
  options.max_image_size = 160;
  const MvsSummary whole = RunMultiViewStereo(Workspace(one_run), options, "whole", progress);
  ASSERT_EQ(whole.views.size(), 12u);

  // Blocks of 5: the last photometric block first, the first geometric block twice (a
  // resubmitted job), and a block past the end.
  for (const int index : {2, 0, 1}) {
    EXPECT_EQ(RunMultiViewStereoBlock(blocks, options, {MvsPass::kPhotometric, index, 5}, progress),
              index == 2 ? 2 : 5);
  }
  EXPECT_EQ(RunMultiViewStereoBlock(blocks, options, {MvsPass::kPhotometric, 3, 5}, progress), 0);
  EXPECT_THROW(FinishMultiViewStereoBlocks(blocks, options), BadInputError);
  for (const int index : {0, 0, 1, 2}) {
    RunMultiViewStereoBlock(blocks, options, {MvsPass::kGeometric, index, 5}, progress);
  }
  const MvsSummary merged = FinishMultiViewStereoBlocks(blocks, options);
  EXPECT_FALSE(fs::exists(blocks.StereoEstimates()));

  ASSERT_EQ(merged.views.size(), whole.views.size());
  for (size_t i = 0; i < whole.views.size(); ++i) {
    EXPECT_EQ(merged.views[i].name, whole.views[i].name);
    EXPECT_EQ(merged.views[i].sources, whole.views[i].sources);
    EXPECT_EQ(merged.views[i].geometric_share, whole.views[i].geometric_share);
  }
  EXPECT_EQ(merged.skipped, whole.skipped);
  for (const char* folder : {"depth", "stereo"}) {
    const auto expected = FilesUnder(one_run / folder);
    const auto actual = FilesUnder(blocks_dir / folder);
    ASSERT_EQ(actual.size(), expected.size()) << folder;
    for (const auto& [name, bytes] : expected) {
      ASSERT_TRUE(actual.contains(name)) << name;
      EXPECT_TRUE(actual.at(name) == bytes) << name << " differs";
    }
  }
}

}  // namespace
}  // namespace parallax
