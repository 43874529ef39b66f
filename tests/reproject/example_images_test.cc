// The renderer on example_images/small with ground-truth cameras and depth: novel views
// against their ground-truth images.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/image.h"
#include "core/scene_folder.h"
#include "core/sparse_model.h"
#include "eval/novel_evaluation.h"
#include "reproject/render.h"
#include "reproject/scene_views.h"
#include "reproject/source_selection.h"
#include "tests/reproject/analytic_scene.h"
#include "tests/test_paths.h"

namespace parallax {
namespace {

class SmallScene : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const SceneFolder folder{SourceDir() / "example_images" / "small"};
    training_ = new std::vector<SourceView>(ReadSourceViews(folder.Training()));
    novel_ = new std::vector<SourceView>(ReadSourceViews(folder.Novel()));
  }
  static void TearDownTestSuite() {
    delete training_;
    delete novel_;
  }

  static RenderResult RenderNovel(const SourceView& novel, int k, FillMethod fill) {
    std::vector<PosedCamera> cameras;
    for (const SourceView& view : *training_) cameras.push_back(view.Posed());
    SourceSelectionOptions selection;
    selection.num_sources = k;
    std::vector<const SourceView*> sources;
    for (int i : SelectSources(cameras, novel.Posed(), selection)) {
      sources.push_back(&(*training_)[static_cast<size_t>(i)]);
    }
    EXPECT_EQ(static_cast<int>(sources.size()), k);
    RenderOptions options;
    options.fill.method = fill;
    return Render(sources, novel.Posed(), options);
  }

  static std::vector<SourceView>* training_;
  static std::vector<SourceView>* novel_;
};
std::vector<SourceView>* SmallScene::training_ = nullptr;
std::vector<SourceView>* SmallScene::novel_ = nullptr;

// Measured PSNR (covered pixels, sRGB): 36.4, 36.4, 27.7, 31.0. novel_0000/0001 lie on the
// training arc. novel_0002 looks down from 3.5 m, nearer than the sources: they see the
// ground and the crate's top ~1.4x magnified and foreshortened, and linear interpolation of
// the fine fbm texture loses detail (one source alone gives 27.8 dB, so it is resampling, not
// misregistration: the depth check below agrees). novel_0003 is low, off the arc.
constexpr double kMinPsnrDb[] = {33, 33, 27, 30};

TEST_F(SmallScene, NovelViewsFromTheTwoBestSourcesMatchGroundTruth) {
  ASSERT_EQ(novel_->size(), 4u);
  for (size_t v = 0; v < novel_->size(); ++v) {
    const SourceView& novel = (*novel_)[v];
    SCOPED_TRACE(novel.name);
    const RenderResult result = RenderNovel(novel, 2, FillMethod::kNone);
    const double psnr = test::PsnrSrgb(result.color, novel.color, [&](int x, int y) {
      return result.classes.At(x, y) == PixelClass::kCovered ||
             result.classes.At(x, y) == PixelClass::kBackground;
    });
    EXPECT_GE(psnr, kMinPsnrDb[v]);
    // novel_0003 sees much that two arc views hide (measured 0.67 covered or background).
    EXPECT_GT(result.metrics.covered_ratio + result.metrics.background_ratio, 0.6);
    // Covered depth agrees with the ground truth (the same depth maps, warped).
    long agree = 0, compared = 0;
    for (int y = 0; y < novel.depth.Height(); ++y) {
      for (int x = 0; x < novel.depth.Width(); ++x) {
        const float truth = novel.depth.At(x, y), depth = result.depth.At(x, y);
        if (result.classes.At(x, y) != PixelClass::kCovered || truth == 0) continue;
        ++compared;
        agree += std::abs(depth - truth) < 0.01f * truth ? 1 : 0;
      }
    }
    EXPECT_GT(static_cast<double>(agree), 0.98 * static_cast<double>(compared));
  }
}

TEST_F(SmallScene, FourSourcesLeaveFewerHolesThanOne) {
  double one = 0, four = 0;
  for (const SourceView& novel : *novel_) {
    SCOPED_TRACE(novel.name);
    const RenderResult k1 = RenderNovel(novel, 1, FillMethod::kNone);
    const RenderResult k4 = RenderNovel(novel, 4, FillMethod::kDepthAware);
    EXPECT_LE(k4.metrics.hole_ratio, k1.metrics.hole_ratio);
    EXPECT_LE(k4.metrics.hole_ratio + k4.metrics.out_of_view_ratio,
              k1.metrics.hole_ratio + k1.metrics.out_of_view_ratio);
    EXPECT_LT(k4.fill.hole_ratio_filled, 0.001);
    one += k1.metrics.hole_ratio;
    four += k4.metrics.hole_ratio;
  }
  EXPECT_LT(four, one);
}

// EvaluateNovelViews from the ground-truth sources (as `evaluate --gt-sources`): one score
// per novel view, in order, whose means are the evaluation's.
// The small scene's novel cameras, and their image names.
std::vector<NamedCamera> NovelCameras(const SceneFolder& folder, std::vector<std::string>* names) {
  const SparseModel model = ReadSparseModel(folder.Novel().sparse);
  std::vector<NamedCamera> targets;
  for (const SparseImage& image : model.Images()) {
    targets.push_back({std::filesystem::path(image.name).stem().string(),
                       {model.CameraById(image.camera_id), image.cam_from_world}});
    names->push_back(image.name);
  }
  return targets;
}

TEST(SmallSceneEvaluation, PerViewScoresAverageToTheMeans) {
  const SceneFolder folder{SourceDir() / "example_images" / "small"};
  std::vector<std::string> names;
  const std::vector<NamedCamera> targets = NovelCameras(folder, &names);
  SourceLibrary library(folder.Training());
  const NovelEvaluation evaluation =
      EvaluateNovelViews(library, targets, names, folder.Novel(), {}, {}, {});
  ASSERT_EQ(evaluation.views, 4);
  ASSERT_EQ(evaluation.per_view.size(), 4u);
  double psnr = 0, ssim = 0, psnr_valid = 0, holes = 0;
  for (size_t v = 0; v < targets.size(); ++v) {
    const NovelViewScore& score = evaluation.per_view[v];
    EXPECT_EQ(score.name, targets[v].name);
    // Measured 36.5, 36.6, 28.6, 25.0 dB after filling (SSIM 0.89-0.98); novel_0003, low
    // and off the training arc, fills what no source saw (31.3 dB on its sampled pixels).
    EXPECT_GT(score.psnr, 24) << score.name;
    EXPECT_GT(score.psnr_valid, 28) << score.name;
    EXPECT_GT(score.ssim, 0.85) << score.name;
    psnr += score.psnr / 4;
    ssim += score.ssim / 4;
    psnr_valid += score.psnr_valid / 4;
    holes += score.hole_ratio / 4;
  }
  EXPECT_NEAR(evaluation.psnr_mean, psnr, 1e-9);
  EXPECT_NEAR(evaluation.ssim_mean, ssim, 1e-12);
  EXPECT_NEAR(evaluation.psnr_valid_mean, psnr_valid, 1e-9);
  EXPECT_NEAR(evaluation.hole_ratio_mean, holes, 1e-12);
}

// A camera turned by a small angle renders the scene shifted by about focal x angle pixels:
// the budget's misalignment measures that shift, and is a fraction of a pixel at the true poses.
TEST(SmallSceneEvaluation, MisalignmentMeasuresATurnedCamera) {
  const SceneFolder folder{SourceDir() / "example_images" / "small"};
  std::vector<std::string> names;
  std::vector<NamedCamera> targets = NovelCameras(folder, &names);
  SourceLibrary library(folder.Training());
  const NovelEvaluation exact = EvaluateNovelViews(library, targets, names, folder.Novel(), {}, {}, {});
  constexpr double kTurnRad = 0.5 * M_PI / 180;
  for (NamedCamera& target : targets) {
    const Rigid3d turn(Eigen::Quaterniond(Eigen::AngleAxisd(kTurnRad, Eigen::Vector3d::UnitY())),
                       Eigen::Vector3d::Zero());
    target.camera.cam_from_world = turn * target.camera.cam_from_world;
  }
  const NovelEvaluation turned = EvaluateNovelViews(library, targets, names, folder.Novel(), {}, {}, {});
  for (size_t v = 0; v < targets.size(); ++v) {
    const Misalignment& at_truth = exact.per_view[v].budget.misalignment;
    const Misalignment& off = turned.per_view[v].budget.misalignment;
    const double shift_px = targets[v].camera.camera.FocalX() * std::tan(kTurnRad);
    std::printf("[ measure ] %s: misalignment median / p90 %.3f / %.3f px at the true pose, %.3f / %.3f px "
                "turned by %.2f px\n",
                targets[v].name.c_str(), at_truth.median_px, at_truth.p90_px, off.median_px, off.p90_px, shift_px);
    // Measured 0.03-0.15 px at the true poses, 2.64-2.71 px turned by 2.44 px (off the image
    // centre a turn moves pixels further: 1 + (x / f)^2 times).
    EXPECT_LT(at_truth.median_px, 0.3) << targets[v].name;
    EXPECT_GT(off.median_px, 0.95 * shift_px) << targets[v].name;
    EXPECT_LT(off.median_px, 1.25 * shift_px) << targets[v].name;
  }
}

}  // namespace
}  // namespace parallax
