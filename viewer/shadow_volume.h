#pragma once
// Shadow volumes of a triangle mesh (SEEDS.md: silhouette edges extruded away from the light,
// counted in the stencil buffer). The volume is built on the CPU for one light and drawn with
// z-fail counting, so it stays right with the eye inside it.
//
// Reconstructed meshes are open and their winding is not consistent, so the volume does not
// rely on either: each triangle is turned to face the light, and the volume is the sum of the
// triangles' own closed volumes (the triangle, its three edges extruded to infinity and, for a
// point light, the triangle's image at infinity). Where two triangles meet at an edge from
// opposite sides, as on any smooth stretch of surface, their two extruded faces coincide with
// opposite orientations and cancel; they are left out. What is left is the silhouette: edges
// where the surface folds over as the light sees it, and the open edges of the mesh. A point's
// count is then the number of triangles between it and the light, so it is shadowed where the
// count is not zero, exactly as a ray traced towards the light finds.
#include <vector>

#include <Eigen/Core>

#include "geometry/obj.h"

namespace parallax {

struct ShadowVolume {
  // Triangles, three homogeneous world points each (w = 0: a point at infinity), wound so
  // that each faces out of the volume.
  std::vector<Eigen::Vector4f> vertices;
  int caps = 0;             // Triangles that are caps (the casters, and their images at infinity).
  int silhouette_edges = 0;  // Edges extruded (each once per triangle it is the silhouette of).
};

// The shadow volume of `mesh` for a light given as in the shaders: (direction towards the
// light, 0) for a directional light, (position, 1) for a point light. Every caster is moved
// `offset` (scene units) away from the light, so that a surface lit by the light lies in front
// of its own volume, not inside it. Triangles seen edge-on by the light cast nothing.
ShadowVolume BuildShadowVolume(const TriangleMesh& mesh, const Eigen::Vector4d& light, float offset);

}  // namespace parallax
