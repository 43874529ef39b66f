#include "reproject/workspace_depth.h"

#include <cmath>
#include <memory>

#include "geometry/raycaster.h"
#include "geometry/obj.h"
#include "reproject/background.h"

namespace parallax {

void NovelViewSettings::Resolve() {
  ForwardWarpOptions& warp_options = render.warp;
  warp_options.method = warp == WarpMode::kMesh ? WarpMethod::kMesh : WarpMethod::kSplat;
  if (warp == WarpMode::kNaive) {
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
  // Every depth-0 pixel the mesh covers, sky-colored ones too: keeping those that
  // MarkBackground calls sky out of the fill lost accuracy: the mesh is right there more
  // often than a smooth color is sky.
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

WorkspaceDepthPreparation PrepareWorkspaceDepth(const std::filesystem::path& obj,
                                                const NovelViewSettings& settings,
                                                SourceLibrary* library) {
  WorkspaceDepthPreparation result;
  std::shared_ptr<const MeshRaycaster> caster;
  if (settings.depth_holes == DepthHoles::kNone) {
    result.note = "not requested (--depth-holes none)";
  } else if (!std::filesystem::exists(obj)) {
    result.note = "no " + obj.string() + " (reconstruct makes it; render does not build one for this)";
  } else {
    const TriangleMesh mesh = ReadTexturedMesh(obj);
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

}  // namespace parallax
