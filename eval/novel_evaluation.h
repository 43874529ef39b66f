#pragma once
// Novel views against ground truth (docs/design.md evaluate JSON, "novel" section): each held-out
// camera rendered from the sources and compared with its real image.
#include <filesystem>
#include <string>
#include <vector>

#include "core/scene_folder.h"
#include "eval/misalignment.h"
#include "reproject/novel_views.h"

namespace parallax {

// The pixels of one kind in a rendered view: their share of the frame, their PSNR (0 where
// there are none) and the dB the whole frame's PSNR would gain were they exact.
struct PixelShareLoss {
  double share = 0;
  double psnr = 0;
  double db_lost = 0;
};

// Where a view's error comes from (docs/novel-views.md): the pixels warped surfaces covered,
// those only background (sky) covered, and those the fill made (holes and out of view); and
// what matching the render's exposure to the photo gains; and how far the covered pixels sit
// from where the photo shows them (the flow from the exposure-matched render to the photo, on
// the covered pixels where the photo has texture).
struct LossBudget {
  PixelShareLoss covered;
  PixelShareLoss background;
  PixelShareLoss filled;
  double out_of_view_share = 0;  // Of the filled pixels, those no source saw at all.
  double exposure_db = 0;        // Exposure-matched PSNR minus PSNR.
  Misalignment misalignment;     // On the covered pixels the photo has texture at.
};

// One novel view's scores (as the means below).
struct NovelViewScore {
  std::string name;
  double psnr = 0;
  double ssim = 0;
  double psnr_valid = 0;
  double psnr_exposure_matched = 0;
  double hole_ratio = 0;
  std::vector<std::string> sources;  // The views it was rendered from, best first.
  LossBudget budget;
};

struct NovelEvaluation {
  std::vector<NovelViewScore> per_view;  // In the order of the targets.
  int views = 0;
  double psnr_mean = 0;        // All pixels, after filling (sRGB in [0, 1]).
  double ssim_mean = 0;        // All pixels, after filling.
  double psnr_valid_mean = 0;  // Pixels a sample landed on (surface or background), before filling.
  // All pixels, after the render's exposure and white balance are matched to the photo's (one
  // gain per channel, least squares over the sampled pixels in linear light), as real-photo
  // benchmarks do: a held-out photo's own auto exposure cannot be known from the others.
  double psnr_exposure_matched_mean = 0;
  double hole_ratio_mean = 0;
  double crack_ratio_mean = 0;
  double out_of_view_ratio_mean = 0;
  double background_ratio_mean = 0;
  double hole_ratio_filled_mean = 0;
  double ms_per_view = 0;
  // The views' budgets averaged (each class's PSNR over the views that have such pixels).
  LossBudget budget_mean;
  int sources_loaded = 0;  // Source views read from disk, of `sources_total`.
  int sources_total = 0;
};

// Renders every camera of `targets` (in the sources' frame; names are the stems of the
// ground-truth images in `truth.images`) and compares. With a non-empty `comparison_dir`,
// writes <name>.png there: render | ground truth | error x4 | pixel classes (covered black,
// background blue, out of view grey, crack yellow, disocclusion red) | misalignment (the flow's
// length where it is measured, white at 4 px and more).
NovelEvaluation EvaluateNovelViews(SourceLibrary& library, const std::vector<NamedCamera>& targets,
                                   const std::vector<std::string>& truth_image_names,
                                   const ViewSetPaths& truth,
                                   const SourceSelectionOptions& selection,
                                   const RenderOptions& options,
                                   const std::filesystem::path& comparison_dir);

}  // namespace parallax
