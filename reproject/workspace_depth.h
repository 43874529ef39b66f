#pragma once
// The novel-view settings `render` and `evaluate` share, and how a workspace's estimated
// depth maps are prepared for warping.
#include <filesystem>
#include <string>

#include "reproject/novel_views.h"
#include "reproject/render.h"
#include "reproject/source_selection.h"

namespace parallax {

// How sources are warped: triangles dropped across depth edges, points with a footprint, or
// the baseline to beat (a nearest-pixel point warp without footprints or background at
// infinity).
enum class WarpMode { kMesh, kSplat, kNaive };

// Where a workspace's depth maps have no depth: filled from its mesh (when reconstruct made
// one), or left holes.
enum class DepthHoles { kMesh, kNone };

struct NovelViewSettings {
  SourceSelectionOptions selection;
  RenderOptions render;
  WarpMode warp = WarpMode::kMesh;
  DepthHoles depth_holes = DepthHoles::kMesh;
  // --edge-erosion: a workspace's depth pixels this close to a farther neighbour, on the near
  // side, are dropped (ErodeDepthEdges); 0 keeps them.
  int edge_erosion_px = 1;
  // --no-color-gains clears it: the photos are blended as they are, without the workspace's
  // per-photo exposure and white balance correction (core/color_gains.h).
  bool color_gains = true;
  // Applies `warp` to `render`; call before using the settings.
  void Resolve();
};

struct WorkspaceDepthPreparation {
  bool mesh = false;  // Depth holes take the mesh's depth.
  std::string note;   // What that means, or why the mesh is not used.
};

// Makes `library` prepare each workspace source's estimated depth map as it is loaded: specks
// removed (RemoveDepthSpeckles: patches under 1/2000 of the photo, which would float in the sky
// and be smeared into streaks by the fill), then, with DepthHoles::kMesh and the workspace's
// mesh (`obj`) present, the depth-0 pixels the mesh covers take its depth (Embree, one
// ray per pixel): estimated depth maps lack depth where matching failed; last, edge_erosion_px
// pixels of the near side of every depth edge are dropped (ErodeDepthEdges): window-based
// stereo fattens occluders, and their edge pixels mix in the background's color. Ground-truth
// depth is used as it is.
WorkspaceDepthPreparation PrepareWorkspaceDepth(const std::filesystem::path& obj,
                                                const NovelViewSettings& settings,
                                                SourceLibrary* library);

}  // namespace parallax
