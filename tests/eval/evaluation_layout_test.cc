#include "eval/evaluation_layout.h"

#include <gtest/gtest.h>

namespace parallax {
namespace {

TEST(EvaluationLayout, NamesWhatEvaluateWritesInTheWorkspace) {
  const EvaluationLayout layout("/w");
  EXPECT_EQ(layout.Json(), "/w/evaluation.json");
  EXPECT_EQ(layout.MeshRenders(), "/w/evaluation/mesh_render");
  EXPECT_EQ(layout.NovelComparisons(true), "/w/evaluation/novel_gt_sources");
  EXPECT_EQ(layout.NovelComparisons(false), "/w/evaluation/novel");
}

}  // namespace
}  // namespace parallax
