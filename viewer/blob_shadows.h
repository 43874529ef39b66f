#pragma once
// Blob shadows (SEEDS.md: "blob texture under the object"): each object standing on the ground
// darkens an ellipse of the ground with a soft round texture, nothing else. The cheapest of the
// viewer's shadows: no shadow on other objects or on the object itself, the shape only roughly
// the object's. The ellipse is where the object's vertices fall when pushed along the light
// onto the ground (their mean and spread), so the blob moves with the light as a shadow does.
#include <vector>

#include <Eigen/Core>

#include "geometry/ground_plane.h"
#include "geometry/obj.h"

namespace parallax {

// The objects on the ground: the connected pieces of the mesh above it, as vertex indices,
// largest first.
struct BlobCasters {
  std::vector<std::vector<int>> objects;
};

// Triangles with a corner higher than `tolerance` above the ground belong to objects; each
// object is a connected set of them. Keeps the `max_objects` largest of at least `min_share`
// of the vertices above the ground whose footprint (seen from straight above) is at most
// `max_radius` across its longer axis (two standard deviations): a wall or a building around
// the scene is no object a blob could stand for.
BlobCasters FindBlobCasters(const TriangleMesh& mesh, const GroundPlane& ground, float tolerance,
                            float max_radius, int max_objects = 16, double min_share = 0.005);

// One blob: the ellipse centre + s * axis_u + t * axis_v, s^2 + t^2 <= 1, on the ground.
struct Blob {
  Eigen::Vector3f centre, axis_u, axis_v;
};

// The blobs for a light as the shaders give it ((towards, 0) directional, (position, 1) point):
// per object, its vertices pushed along the light onto the ground; the ellipse holds about 95%
// of them (two standard deviations along each principal axis), at least `min_radius` across.
// No blob for a light at or below the horizon, or for vertices a point light is not above.
std::vector<Blob> PlaceBlobs(const TriangleMesh& mesh, const BlobCasters& casters, const GroundPlane& ground,
                             const Eigen::Vector4d& light, float min_radius);

// The blob's texture, `size` x `size` light visibilities (0.35 in the core, 1 outside the
// inscribed circle), row by row: dark to two thirds of the radius, then a smooth rim. It is
// multiplied into the frame, so the core keeps about the share of the color a real shadow
// keeps in ambient light.
std::vector<float> BlobTexture(int size);

}  // namespace parallax
