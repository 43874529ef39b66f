#include <gtest/gtest.h>

#include "core/sparse_model.h"
#include "core/workspace.h"
#include "pipeline/dense_stages.h"
#include "tests/temp_dir.h"

namespace parallax {
namespace {

// A workspace whose undistorted model has one camera of width x height.
void WriteModel(const Workspace& workspace, int width, int height) {
  SparseModel model;
  model.AddCamera(MakePinholeCamera(1, static_cast<uint64_t>(width), static_cast<uint64_t>(height), width, width,
                                    width / 2.0, height / 2.0));
  WriteSparseModel(model, workspace.Sparse(), SparseFormat::kText);
}

std::string DepthKey(const Workspace& workspace, const DepthRequest& request) {
  SilentProgress progress;
  return DepthStage(workspace, "undistorted", request, progress).key;
}

TEST(DepthResolution, EachQualityCapsTheLongSideAndAScaleLiftsTheCap) {
  EXPECT_DOUBLE_EQ(MvsOptionsOf({}).ScaleFor(1536, 1024), 1024.0 / 1536);
  EXPECT_DOUBLE_EQ(MvsOptionsOf({}).ScaleFor(1024, 3072), 1024.0 / 3072) << "portrait: the long side";
  EXPECT_DOUBLE_EQ(MvsOptionsOf({}).ScaleFor(640, 480), 1.0) << "photos under the cap keep their size";
  DepthRequest fast;
  fast.quality = Quality::kFast;
  EXPECT_DOUBLE_EQ(MvsOptionsOf(fast).ScaleFor(1536, 1024), 0.5);
  DepthRequest full;
  full.scale = 1;
  EXPECT_DOUBLE_EQ(MvsOptionsOf(full).ScaleFor(6000, 4000), 1.0);
  DepthRequest capped;
  capped.max_size = 1500;
  EXPECT_DOUBLE_EQ(MvsOptionsOf(capped).ScaleFor(6000, 4000), 0.25);
  const std::string why = DescribeDepthResolution({}, 1536, 1024);
  EXPECT_NE(why.find("depth at 1024x683 for 1536x1024 photos"), std::string::npos) << why;
  EXPECT_NE(why.find("balanced caps the long side at 1024 px"), std::string::npos) << why;
  EXPECT_NE(DescribeDepthResolution(capped, 6000, 4000).find("--mvs-max-size 1500"), std::string::npos);
}

TEST(DepthResolution, TheKeyFollowsTheWorkingSizeNotTheKnobs) {
  const TempDir small_dir, large_dir;
  const Workspace small(small_dir.Path()), large(large_dir.Path());
  WriteModel(small, 640, 480);
  WriteModel(large, 1536, 1024);
  DepthRequest full;
  full.scale = 1;
  // 640x480 is under every cap: the default is the full size, and a workspace estimated
  // before the cap existed keeps its depth maps.
  EXPECT_EQ(DepthKey(small, {}), DepthKey(small, full));
  EXPECT_NE(DepthKey(large, {}), DepthKey(large, full));
  DepthRequest capped;
  capped.max_size = 1024;
  EXPECT_EQ(DepthKey(large, {}), DepthKey(large, capped)) << "the same working size";
  DepthRequest half;
  half.scale = 0.5;
  DepthRequest fast;
  fast.quality = Quality::kFast;
  EXPECT_NE(DepthKey(large, half), DepthKey(large, fast)) << "same size, other quality";
}

TEST(DepthResolution, AnotherSeedIsAnotherEstimateAndSeedZeroKeepsTheOldKey) {
  const TempDir folder;
  const Workspace workspace(folder.Path());
  WriteModel(workspace, 640, 480);
  DepthRequest reseeded;
  reseeded.seed = 7;
  EXPECT_EQ(MvsOptionsOf(reseeded).seed, 7u);
  EXPECT_NE(DepthKey(workspace, reseeded), DepthKey(workspace, {}));
  // The key of seed 0, fixed: it changes only where every workspace's depth is to be estimated
  // again (a new kMvsVersion), not with the seed option's arrival.
  EXPECT_EQ(DepthKey(workspace, {}), "c7c1619a169a4e1e");
}

}  // namespace
}  // namespace parallax
