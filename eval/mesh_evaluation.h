#pragma once
// How well a textured mesh reproduces photos: rendered (Embree) at each photo's camera and
// compared with the photo. At the workspace's own cameras it shows the texture; at held-out
// cameras (photos kept out of the dense stages) it is what a user sees from a new viewpoint.
#include <filesystem>
#include <string>
#include <vector>

#include "core/color_gains.h"
#include "core/sparse_model.h"
#include "geometry/raycaster.h"
#include "geometry/obj.h"
#include "reproject/novel_views.h"

namespace parallax {

struct TexturedMeshView {
  std::string name;         // The camera's name (its photo's stem).
  double psnr = 0;          // The whole frame, pixels the mesh misses black (dB, sRGB in [0, 1]).
  double ssim = 0;          // The whole frame, likewise.
  double psnr_covered = 0;  // The pixels the mesh covers (0 where it covers none).
  double coverage = 0;      // Their share of the frame.
  // With another run's coverage masks: the pixels both meshes cover, and their share.
  double psnr_common = 0;
  double common_share = 0;
};

struct TexturedMeshScore {
  int views = 0;             // Views the mesh covers at least one pixel of.
  double psnr_mean = 0;      // Covered pixels only, over `views`.
  double coverage_mean = 0;  // Over `views`.
  double frame_psnr_mean = 0;  // Whole frames, over every view.
  double frame_ssim_mean = 0;
  double common_psnr_mean = 0;  // Pixels both runs cover, over the views with some; 0 without masks.
  double common_share_mean = 0;
  std::vector<TexturedMeshView> per_view;
};

// Renders `mesh` at every camera (distortion-free; `image_names[i]` is camera i's photo in
// `images_dir`; a model's from CamerasOfModel) and compares with the photos. An atlas made at
// the photos' common exposure (core/color_gains.h) is compared at each photo's own: its render
// divided by the photo's gain in `gains` (1 for a photo without one). With a non-empty `render_dir`, writes each render
// there as <name>.png (uncovered pixels black) and its coverage as <name>.covered.png (white
// where covered). With a non-empty `common_dir` (another run's render_dir at the same cameras),
// also scores the pixels both runs cover. Throws BadInputError naming a photo that is missing
// or not of its camera's size, or a missing or mismatched coverage mask.
TexturedMeshScore ScoreTexturedMesh(const TriangleMesh& mesh, const std::vector<NamedCamera>& cameras,
                                    const std::vector<std::string>& image_names, const ColorGains& gains,
                                    const std::filesystem::path& images_dir,
                                    const std::filesystem::path& render_dir,
                                    const std::filesystem::path& common_dir = {});

// The textured mesh seen from a camera: sRGB color where covered, `covered` set there.
// `raycaster` holds `mesh`'s triangles (built once, shared by all views).
Image RenderTexturedMesh(const TriangleMesh& mesh, const MeshRaycaster& raycaster,
                         const Camera& camera, const Rigid3d& cam_from_world,
                         std::vector<uint8_t>& covered);

}  // namespace parallax
