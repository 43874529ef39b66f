#pragma once
// Texturing a mesh from the photos: every triangle gets its own cell in one atlas, colored
// from the photos that see it best (most head-on and most pixels per unit area) without
// occlusion (Embree visibility), up to 8, each weighed by the triangle's area in it: the seam between
// triangles that chose different photos fades instead of jumping, and a viewpoint between the
// photos sees their mean rather than one photo's reflections and misregistration.
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image.h"
#include "core/pose.h"
#include "geometry/obj.h"

namespace parallax {

struct TextureView {
  Camera camera;  // Distortion-free (the undistorted workspace).
  Rigid3d cam_from_world;
  // Linear RGB, camera.width x camera.height; or, when empty, what `load_color` returns.
  // TextureMesh reads the photos one at a time, so that its memory is one photo and the
  // atlas, whatever their number.
  Image color;
  std::function<Image()> load_color;
};

struct TextureOptions {
  // Texels along a triangle's legs: the median projected size of the triangles in their best
  // photos (texel ~ pixel), clamped to this range, and lowered if the atlas would exceed
  // `max_atlas_size` on a side.
  int min_texels_per_edge = 2;
  int max_texels_per_edge = 16;
  int max_atlas_size = 8192;
  // Photos blended per triangle (at most 8), and the exponent of their weight (score / best
  // score). Fewer photos or a higher exponent draw each triangle from its best photo alone:
  // sharper from that photo's camera, worse from anywhere else (docs/mesh.md).
  int max_views_per_triangle = 8;
  double blend_exponent = 1;
  // A photo sees a triangle when the angle between its ray and the normal is below this. Near
  // 90: ground seen from head height 15 m away lies 84 degrees off, and a grazing photo beats
  // none (the blend weighs it by its small area on screen where a better photo sees the triangle).
  double max_view_angle_deg = 88;
  void Check() const;
};

struct TextureSummary {
  int texels_per_edge = 0;
  size_t untextured_triangles = 0;  // No photo sees them: mid-grey.
};

// Throws UsageError for invalid options, InternalError for invalid views (or what load_color
// throws).
TriangleMesh TextureMesh(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles,
                         const std::vector<TextureView>& views, const TextureOptions& options,
                         TextureSummary& summary);

}  // namespace parallax
