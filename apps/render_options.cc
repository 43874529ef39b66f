#include "apps/render_options.h"

#include <cmath>
#include <map>
#include <memory>

#include "pipeline/raycaster.h"
#include "pipeline/textured_mesh.h"
#include "reproject/background.h"

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

namespace {

// Gives the depth-0 pixels of `view` the mesh covers the mesh's depth; returns how many.
int FillFromMesh(const MeshRaycaster& caster, const SourceView& view, DepthMap* depth) {
  const std::vector<RayHit> hits = caster.CastPixels(view.camera, view.cam_from_world);
  std::vector<float>& values = depth->Values();
  if (hits.size() != values.size()) return 0;
  // Every depth-0 pixel the mesh covers, sky-coloured ones too: keeping those that
  // MarkBackground calls sky out of the fill cost 0.2 dB on the courtyard (27.15 -> 26.93):
  // the mesh is right there more often than a smooth colour is sky.
  int filled = 0;
  for (size_t i = 0; i < hits.size(); ++i) {
    const float z = hits[i].depth;
    if (values[i] != 0 || hits[i].triangle < 0 || !(z > 0) || !std::isfinite(z)) continue;
    values[i] = z;
    ++filled;
  }
  return filled;
}

}  // namespace

WorkspaceDepthPreparation PrepareWorkspaceDepth(const std::filesystem::path& workspace,
                                                const NovelViewSettings& settings,
                                                SourceLibrary* library) {
  WorkspaceDepthPreparation result;
  const std::filesystem::path obj = workspace / "mesh" / "mesh.obj";
  std::shared_ptr<const MeshRaycaster> caster;
  if (settings.depth_holes == "none") {
    result.note = "not requested (--depth-holes none)";
  } else if (!std::filesystem::exists(obj)) {
    result.note = "no " + obj.string() + " (reconstruct makes it; render does not build one for this)";
  } else {
    const TexturedMesh mesh = ReadTexturedMesh(obj);
    caster = std::make_shared<const MeshRaycaster>(mesh.vertices, mesh.triangles);
    result.mesh = true;
    result.note = "from " + obj.string() + " (" + std::to_string(mesh.triangles.size()) + " triangles)";
  }
  const int erosion_px = settings.edge_erosion_px;
  library->SetDepthPreparation([caster, erosion_px](SourceView* view) {
    DepthMap& depth = view->depth;
    RemoveDepthSpeckles(&depth, depth.Width() * depth.Height() / 2000, 0.1f);
    const int filled = caster ? FillFromMesh(*caster, *view, &depth) : 0;
    // After the mesh: its edges are as fat as the depth it was fused from. 5% separates the
    // courtyard's occluders from their background and keeps slanted ground whole.
    ErodeDepthEdges(&depth, 0.05f, erosion_px);
    return filled;
  });
  return result;
}

void AddRenderOptions(CLI::App& command, NovelViewSettings& settings) {
  command.add_option("--edge-erosion", settings.edge_erosion_px,
                     "workspace sources: drop this many pixels of estimated depth on the near side "
                     "of every depth edge, where stereo fattens occluders (default 1; 0 keeps them)")
      ->check(CLI::Range(0, 8));
  command.add_option("--depth-holes", settings.depth_holes,
                     "workspace sources: fill the pixels their depth maps have no depth for from "
                     "the reconstruction's mesh (mesh, default, when reconstruct made one) or "
                     "leave them holes (none)")
      ->check(CLI::IsMember({"mesh", "none"}, CLI::ignore_case));
  command.add_option("--sources", settings.selection.num_sources,
                     "source views per novel view: the best K by overlap and angle (default 4)")
      ->check(CLI::Range(1, 64));
  command.add_option("--hole-sources", settings.selection.hole_sources,
                     "at most this many more source views per novel view, added one at a time "
                     "while holes or surfaces out of view remain, each the one that sees most of "
                     "them (default 2; 0: only the --sources best)")
      ->check(CLI::Range(0, 16));
  command.add_option("--warp", settings.warp,
                     "forward warp: mesh (default; triangles, dropped across depth edges), splat "
                     "(points with a footprint) or naive (nearest pixel, the baseline)")
      ->check(CLI::IsMember({"mesh", "splat", "naive"}, CLI::ignore_case));
  const std::map<std::string, TextureFilter> filters = {{"auto", TextureFilter::kAuto},
                                                        {"bicubic", TextureFilter::kBicubic}};
  command.add_option("--texture-filter", settings.render.warp.texture_filter,
                     "mesh warp colour sampling: auto (default; Catmull-Rom where the view "
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
}

}  // namespace parallax
