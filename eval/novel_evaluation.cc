#include "eval/novel_evaluation.h"

#include <array>

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/color_gains.h"
#include "core/image.h"
#include "core/image_metrics.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

Eigen::Vector3f ClassColor(PixelClass pixel_class) {
  switch (pixel_class) {
    case PixelClass::kCovered: return {0, 0, 0};
    case PixelClass::kBackground: return {0.2f, 0.4f, 1};
    case PixelClass::kOutOfView: return {0.5f, 0.5f, 0.5f};
    case PixelClass::kCrack: return {1, 0.9f, 0};
    case PixelClass::kDisocclusion: return {1, 0, 0};
  }
  return {1, 1, 1};
}

// The flow length that shows white in the comparison's misalignment panel.
constexpr float kFlowWhitePx = 4;

// render | truth | |error| x 4 | classes | flow length where `aligned`, side by side (sRGB).
Image SideBySide(const Image& render, const Image& truth, const ClassMap& classes, const Image& flow_length,
                 const std::vector<uint8_t>& aligned) {
  const int w = render.Width(), h = render.Height();
  Image out(5 * w, h, 3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const Eigen::Vector3f pixel_class = ClassColor(classes.At(x, y));
      for (int c = 0; c < 3; ++c) {
        out.At(x, y, c) = render.At(x, y, c);
        out.At(w + x, y, c) = truth.At(x, y, c);
        out.At(2 * w + x, y, c) = std::min(1.0f, 4 * std::abs(render.At(x, y, c) - truth.At(x, y, c)));
        out.At(3 * w + x, y, c) = pixel_class[c];
        out.At(4 * w + x, y, c) = aligned[static_cast<size_t>(y) * w + x]
                                      ? std::min(1.0f, flow_length.At(x, y, 0) / kFlowWhitePx)
                                      : 0.0f;
      }
    }
  }
  return out;
}

// `render` (linear) times the per-channel gain that fits it best to `truth` (sRGB) where
// `mask` is set, in sRGB.
Image ExposureMatched(const Image& render, const Image& truth, const std::vector<uint8_t>& mask) {
  const Image truth_linear = SrgbToLinear(truth);
  std::array<double, 3> cross{0, 0, 0}, square{0, 0, 0};
  for (size_t p = 0; p < mask.size(); ++p) {
    if (!mask[p]) continue;
    for (size_t c = 0; c < 3; ++c) {
      const double r = render.Pixels()[3 * p + c];
      cross[c] += r * static_cast<double>(truth_linear.Pixels()[static_cast<size_t>(truth_linear.Channels()) * p + c]);
      square[c] += r * r;
    }
  }
  RgbGain gain;
  for (size_t c = 0; c < 3; ++c) gain[c] = square[c] > 0 ? static_cast<float>(cross[c] / square[c]) : 1.0f;
  Image matched = render;
  ApplyGain(gain, matched);
  return LinearToSrgb(matched);
}

// The pixels whose class is in `classes`.
std::vector<uint8_t> MaskOf(const ClassMap& map, std::initializer_list<PixelClass> classes) {
  std::vector<uint8_t> mask(map.classes.size());
  for (size_t p = 0; p < mask.size(); ++p) {
    mask[p] = std::find(classes.begin(), classes.end(), map.classes[p]) != classes.end();
  }
  return mask;
}

PixelShareLoss ShareLoss(const Image& render, const Image& truth, const std::vector<uint8_t>& mask,
                         double frame_psnr) {
  PixelShareLoss loss;
  const auto pixels = static_cast<double>(std::count(mask.begin(), mask.end(), uint8_t{1}));
  if (pixels == 0) return loss;
  loss.share = pixels / static_cast<double>(mask.size());
  loss.psnr = Psnr(render, truth, mask);
  const double frame_mse = std::pow(10.0, -frame_psnr / 10), mse = std::pow(10.0, -loss.psnr / 10);
  loss.db_lost = 10 * std::log10(frame_mse / std::max(frame_mse - loss.share * mse, 1e-10));
  return loss;
}

// The pixels set in both masks.
std::vector<uint8_t> Both(std::vector<uint8_t> mask, const std::vector<uint8_t>& other) {
  for (size_t p = 0; p < mask.size(); ++p) mask[p] = mask[p] && other[p];
  return mask;
}

// `aligned`: the covered pixels whose misalignment is measured.
LossBudget BudgetOf(const Image& render, const Image& truth, const ClassMap& classes, const HoleMetrics& metrics,
                    double psnr, double psnr_exposure_matched, const Image& flow_length,
                    const std::vector<uint8_t>& aligned) {
  LossBudget budget;
  budget.covered = ShareLoss(render, truth, MaskOf(classes, {PixelClass::kCovered}), psnr);
  budget.background = ShareLoss(render, truth, MaskOf(classes, {PixelClass::kBackground}), psnr);
  budget.filled = ShareLoss(
      render, truth, MaskOf(classes, {PixelClass::kOutOfView, PixelClass::kCrack, PixelClass::kDisocclusion}), psnr);
  budget.out_of_view_share = metrics.out_of_view_ratio;
  budget.exposure_db = psnr_exposure_matched - psnr;
  budget.misalignment = MisalignmentOf(flow_length, aligned);
  return budget;
}

// The mean of the views' budgets; each class's PSNR, and the misalignment, over the views that
// have its pixels.
LossBudget MeanBudget(const std::vector<NovelViewScore>& views) {
  LossBudget mean;
  std::array<int, 3> with_pixels{0, 0, 0};
  for (const NovelViewScore& view : views) {
    const std::array<const PixelShareLoss*, 3> parts = {&view.budget.covered, &view.budget.background,
                                                        &view.budget.filled};
    const std::array<PixelShareLoss*, 3> sums = {&mean.covered, &mean.background, &mean.filled};
    for (size_t k = 0; k < 3; ++k) {
      sums[k]->share += parts[k]->share;
      sums[k]->db_lost += parts[k]->db_lost;
      if (parts[k]->share > 0) {
        sums[k]->psnr += parts[k]->psnr;
        ++with_pixels[k];
      }
    }
    mean.out_of_view_share += view.budget.out_of_view_share;
    mean.exposure_db += view.budget.exposure_db;
    if (view.budget.covered.share > 0) {
      mean.misalignment.median_px += view.budget.misalignment.median_px;
      mean.misalignment.p90_px += view.budget.misalignment.p90_px;
    }
  }
  if (views.empty()) return mean;
  const auto n = static_cast<double>(views.size());
  const std::array<PixelShareLoss*, 3> sums = {&mean.covered, &mean.background, &mean.filled};
  for (size_t k = 0; k < 3; ++k) {
    sums[k]->share /= n;
    sums[k]->db_lost /= n;
    if (with_pixels[k] > 0) sums[k]->psnr /= with_pixels[k];
  }
  mean.out_of_view_share /= n;
  mean.exposure_db /= n;
  if (with_pixels[0] > 0) {
    mean.misalignment.median_px /= with_pixels[0];
    mean.misalignment.p90_px /= with_pixels[0];
  }
  return mean;
}

}  // namespace

NovelEvaluation EvaluateNovelViews(SourceLibrary& library, const std::vector<NamedCamera>& targets,
                                   const std::vector<std::string>& truth_image_names,
                                   const ViewSetPaths& truth,
                                   const SourceSelectionOptions& selection,
                                   const RenderOptions& options, const fs::path& comparison_dir) {
  NovelEvaluation evaluation;
  Renderer renderer(options);
  NovelView view;
  for (size_t i = 0; i < targets.size(); ++i) {
    const fs::path truth_path = truth.images / truth_image_names.at(i);
    const Image truth_image = ReadImage(truth_path);
    RenderNovelView(library, targets[i], selection, renderer, &view);
    const Image render = LinearToSrgb(view.result.color);
    if (truth_image.Width() != render.Width() || truth_image.Height() != render.Height() ||
        truth_image.Channels() < 3) {
      throw BadInputError(truth_path.string() + ": not an RGB image of its camera's size");
    }
    const std::vector<uint8_t> sampled =
        MaskOf(view.result.classes, {PixelClass::kCovered, PixelClass::kBackground});
    const HoleMetrics& metrics = view.result.metrics;
    // The flow is measured at the photo's exposure: a gain would bias its brightness matching.
    const Image exposure_matched = ExposureMatched(view.result.color, truth_image, sampled);
    const Image flow_length = FlowLength(exposure_matched, truth_image);
    const std::vector<uint8_t> aligned =
        Both(MaskOf(view.result.classes, {PixelClass::kCovered}), TexturedPixels(truth_image));
    NovelViewScore score{targets[i].name, Psnr(render, truth_image), Ssim(render, truth_image),
                               Psnr(render, truth_image, sampled), Psnr(exposure_matched, truth_image),
                               metrics.hole_ratio, view.sources, {}};
    score.budget = BudgetOf(render, truth_image, view.result.classes, metrics, score.psnr,
                            score.psnr_exposure_matched, flow_length, aligned);
    evaluation.per_view.push_back(score);
    evaluation.psnr_mean += score.psnr;
    evaluation.ssim_mean += score.ssim;
    evaluation.psnr_valid_mean += score.psnr_valid;
    evaluation.psnr_exposure_matched_mean += score.psnr_exposure_matched;
    evaluation.hole_ratio_mean += metrics.hole_ratio;
    evaluation.crack_ratio_mean += metrics.crack_ratio;
    evaluation.out_of_view_ratio_mean += metrics.out_of_view_ratio;
    evaluation.background_ratio_mean += metrics.background_ratio;
    evaluation.hole_ratio_filled_mean += view.result.fill.hole_ratio_filled;
    evaluation.ms_per_view += view.ms;
    ++evaluation.views;
    if (!comparison_dir.empty()) {
      fs::create_directories(comparison_dir);
      WriteImage(comparison_dir / (targets[i].name + ".png"),
                 SideBySide(render, truth_image, view.result.classes, flow_length, aligned), PixelFormat::kUint8);
    }
  }
  if (evaluation.views > 0) {
    const double n = evaluation.views;
    for (double* mean : {&evaluation.psnr_mean, &evaluation.ssim_mean, &evaluation.psnr_valid_mean,
                         &evaluation.psnr_exposure_matched_mean,
                         &evaluation.hole_ratio_mean, &evaluation.crack_ratio_mean,
                         &evaluation.out_of_view_ratio_mean, &evaluation.background_ratio_mean,
                         &evaluation.hole_ratio_filled_mean, &evaluation.ms_per_view}) {
      *mean /= n;
    }
  }
  evaluation.budget_mean = MeanBudget(evaluation.per_view);
  evaluation.sources_loaded = library.LoadedCount();
  evaluation.sources_total = static_cast<int>(library.Cameras().size());
  return evaluation;
}

}  // namespace parallax
