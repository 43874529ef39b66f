#include "apps/render_options.h"

#include <map>

namespace parallax {

void NovelViewSettings::Resolve() {
  ForwardWarpOptions& warp_options = render.warp;
  warp_options.method = warp == "splat" ? WarpMethod::kSplat : WarpMethod::kMesh;
  if (warp == "naive") {
    warp_options.method = WarpMethod::kSplat;
    warp_options.max_splat_px = 1;
    warp_options.splat_overlap = 1;
    warp_options.background_at_infinity = false;
  }
}

void AddRenderOptions(CLI::App& command, NovelViewSettings& settings) {
  command.add_option("--sources", settings.selection.num_sources,
                     "source views per novel view: the best K by overlap and angle (default 4)")
      ->check(CLI::Range(1, 64));
  command.add_option("--warp", settings.warp,
                     "forward warp: mesh (default; triangles, dropped across depth edges), splat "
                     "(points with a footprint) or naive (nearest pixel, the baseline)")
      ->check(CLI::IsMember({"mesh", "splat", "naive"}, CLI::ignore_case));
  const std::map<std::string, FillMethod> fills = {{"none", FillMethod::kNone},
                                                   {"inpaint", FillMethod::kInpaint},
                                                   {"depth-aware", FillMethod::kDepthAware}};
  command.add_option("--fill", settings.render.fill.method,
                     "hole filling: none, inpaint (OpenCV Telea, the baseline) or depth-aware "
                     "(default: from the background side)")
      ->transform(CLI::CheckedTransformer(fills, CLI::ignore_case));
}

}  // namespace parallax
