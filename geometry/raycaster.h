#pragma once
// Embree ray casting against a triangle mesh of the reconstruction: which triangle each pixel
// of a camera sees (to render a textured mesh), and whether a point is visible from a camera
// (to texture a triangle only from photos that see it).
#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/pose.h"

namespace parallax {

struct RayHit {
  int triangle = -1;  // -1: the ray hit nothing.
  float depth = 0;    // z-depth in the camera.
  float u = 0, v = 0; // Barycentric weights of corners 1 and 2 (corner 0 gets 1 - u - v).
};

class MeshRaycaster {
 public:
  // Throws std::runtime_error if Embree fails.
  MeshRaycaster(const std::vector<Eigen::Vector3f>& vertices,
                const std::vector<Eigen::Vector3i>& triangles);
  ~MeshRaycaster();
  MeshRaycaster(const MeshRaycaster&) = delete;
  MeshRaycaster& operator=(const MeshRaycaster&) = delete;

  // One ray through each pixel centre of `camera`, through its distortion (a pixel where it
  // cannot be inverted hits nothing), row-major. All threads.
  std::vector<RayHit> CastPixels(const Camera& camera, const Rigid3d& cam_from_world) const;

  // For each point, whether the open segment from `eye` to it (shortened by `tolerance` of its
  // length at the point's end, so the surface the point lies on does not hide it) is free.
  // All threads.
  std::vector<uint8_t> Visible(const Eigen::Vector3f& eye,
                               const std::vector<Eigen::Vector3f>& points,
                               float tolerance) const;

  // For each origin, whether the segment from it along `direction` for `length` is free (a
  // shadow ray towards a directional light). All threads.
  std::vector<uint8_t> Unoccluded(const std::vector<Eigen::Vector3f>& origins,
                                  const Eigen::Vector3f& direction, float length) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace parallax
