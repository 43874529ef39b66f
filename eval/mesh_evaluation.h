#pragma once
// How well a textured mesh reproduces the photos it was made from: rendered (Embree) from each
// workspace camera and compared with that camera's photo on the pixels the mesh covers.
#include <filesystem>

#include "core/color_gains.h"
#include "core/sparse_model.h"
#include "geometry/raycaster.h"
#include "geometry/obj.h"

namespace parallax {

struct TexturedMeshScore {
  int views = 0;
  double psnr_mean = 0;      // dB, sRGB values in [0, 1], covered pixels only.
  double coverage_mean = 0;  // Share of pixels the mesh covers.
};

// Renders `mesh` from every image of `model` (distortion-free cameras) and compares with
// `images_dir`/<name>. An atlas made at the photos' common exposure (core/color_gains.h) is
// compared at each photo's own: its render divided by the photo's gain in `gains`. With a
// non-empty `render_dir`, writes each render there as <stem>.png (uncovered pixels black) to
// look at.
TexturedMeshScore ScoreTexturedMesh(const TriangleMesh& mesh, const SparseModel& model, const ColorGains& gains,
                                    const std::filesystem::path& images_dir,
                                    const std::filesystem::path& render_dir);

// The textured mesh seen from a camera: sRGB color where covered, `covered` set there.
// `raycaster` holds `mesh`'s triangles (built once, shared by all views).
Image RenderTexturedMesh(const TriangleMesh& mesh, const MeshRaycaster& raycaster,
                         const Camera& camera, const Rigid3d& cam_from_world,
                         std::vector<uint8_t>& covered);

}  // namespace parallax
