#include "apps/novel_view_options.h"

#include <map>
#include <string>

namespace parallax {

void AddNovelViewOptions(CLI::App& command, NovelViewSettings& settings) {
  command.add_option("--edge-erosion", settings.edge_erosion_px,
                     "workspace sources: drop this many pixels of estimated depth on the near side "
                     "of every depth edge, where stereo fattens occluders (default 1; 0 keeps them)")
      ->check(CLI::Range(0, 8));
  const std::map<std::string, DepthHoles> depth_holes = {{"mesh", DepthHoles::kMesh},
                                                         {"none", DepthHoles::kNone}};
  command.add_option("--depth-holes", settings.depth_holes,
                     "workspace sources: fill the pixels their depth maps have no depth for from "
                     "the reconstruction's mesh (mesh, default, when reconstruct made one) or "
                     "leave them holes (none)")
      ->transform(CLI::CheckedTransformer(depth_holes, CLI::ignore_case));
  command.add_flag("--no-color-gains{false}", settings.color_gains,
                   "workspace sources: blend the photos as they are, without correcting each "
                   "one's exposure and white balance (color_gains.json, estimated by reconstruct)");
  command.add_option("--sources", settings.selection.num_sources,
                     "source views per novel view: the best K by overlap and angle (default 4)")
      ->check(CLI::Range(1, 64));
  command.add_option("--hole-sources", settings.selection.hole_sources,
                     "at most this many more source views per novel view, added one at a time "
                     "while holes or surfaces out of view remain, each the one that sees most of "
                     "them (default 2; 0: only the --sources best)")
      ->check(CLI::Range(0, 16));
  const std::map<std::string, WarpMode> warps = {
      {"mesh", WarpMode::kMesh}, {"splat", WarpMode::kSplat}, {"naive", WarpMode::kNaive}};
  command.add_option("--warp", settings.warp,
                     "forward warp: mesh (default; triangles, dropped across depth edges), splat "
                     "(points with a footprint) or naive (nearest pixel, the baseline)")
      ->transform(CLI::CheckedTransformer(warps, CLI::ignore_case));
  const std::map<std::string, TextureFilter> filters = {{"auto", TextureFilter::kAuto},
                                                        {"bicubic", TextureFilter::kBicubic}};
  command.add_option("--texture-filter", settings.render.warp.texture_filter,
                     "mesh warp color sampling: auto (default; Catmull-Rom where the view "
                     "magnifies a source, bilinear elsewhere) or bicubic (Catmull-Rom everywhere: "
                     "sharper, ~10% slower)")
      ->transform(CLI::CheckedTransformer(filters, CLI::ignore_case));
  const std::map<std::string, FillMethod> fills = {{"none", FillMethod::kNone},
                                                   {"inpaint", FillMethod::kInpaint},
                                                   {"depth-aware", FillMethod::kDepthAware}};
  command.add_option("--fill", settings.render.fill.method,
                     "hole filling: none, inpaint (OpenCV Telea, the baseline) or depth-aware "
                     "(default: from the background side)")
      ->transform(CLI::CheckedTransformer(fills, CLI::ignore_case));
  command.add_flag("--no-fill-from-sources{false}", settings.render.fill.from_sources,
                   "depth-aware fill: keep the fill's color in holes whose continued surface a "
                   "source saw without depth, instead of that source's color");
  command.add_flag("--no-fill-smoothing{false}", settings.render.fill.smooth,
                   "depth-aware fill: keep the streaks of the hole's rim instead of averaging "
                   "them over windows that grow with the distance to it");
}

}  // namespace parallax
