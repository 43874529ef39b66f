#include "apps/render_options.h"

#include <cmath>
#include <map>
#include <memory>

#include "pipeline/raycaster.h"
#include "pipeline/textured_mesh.h"

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

std::string UseMeshForDepthHoles(const std::filesystem::path& workspace,
                                 const NovelViewSettings& settings, SourceLibrary* library) {
  if (settings.depth_holes == "none") return "not requested (--depth-holes none)";
  const std::filesystem::path obj = workspace / "mesh" / "mesh.obj";
  if (!std::filesystem::exists(obj)) {
    return "no " + obj.string() + " (reconstruct makes it; render does not build one for this)";
  }
  const TexturedMesh mesh = ReadTexturedMesh(obj);
  auto caster = std::make_shared<const MeshRaycaster>(mesh.vertices, mesh.triangles);
  library->SetDepthCompletion([caster](const PosedCamera& camera, DepthMap* depth) {
    const std::vector<RayHit> hits = caster->CastPixels(camera.camera, camera.cam_from_world);
    std::vector<float>& values = depth->Values();
    if (hits.size() != values.size()) return 0;
    int filled = 0;
    for (size_t i = 0; i < hits.size(); ++i) {
      const float z = hits[i].depth;
      if (values[i] != 0 || hits[i].triangle < 0 || !(z > 0) || !std::isfinite(z)) continue;
      values[i] = z;
      ++filled;
    }
    return filled;
  });
  return "from " + obj.string() + " (" + std::to_string(mesh.triangles.size()) + " triangles)";
}

void AddRenderOptions(CLI::App& command, NovelViewSettings& settings) {
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
                     "while holes remain, each the one that sees most of what they hide "
                     "(default 2; 0: only the --sources best)")
      ->check(CLI::Range(0, 16));
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
