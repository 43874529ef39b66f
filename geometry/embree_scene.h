#pragma once
// One Embree device and scene of triangle meshes, released together: what the ray caster and
// synth's ray tracer trace against.
#include <string>
#include <vector>

#include <Eigen/Core>
#include <embree3/rtcore.h>

namespace parallax {

class EmbreeScene {
 public:
  // Robust traversal (no missed edges between triangles); `high_quality` builds a better BVH,
  // slower to build. Throws std::runtime_error if Embree fails.
  explicit EmbreeScene(bool high_quality = false);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Adds a mesh; geometry ids count up from 0 in the order of the calls. Call before Commit.
  // Throws std::runtime_error if Embree fails.
  unsigned Add(const std::vector<Eigen::Vector3f>& vertices,
               const std::vector<Eigen::Vector3i>& triangles);
  // Builds the acceleration structure. Throws std::runtime_error if Embree fails.
  void Commit();

  RTCScene Handle() const { return scene_; }

 private:
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  std::string error_;  // Recorded by the device's callback; never thrown through Embree.
};

}  // namespace parallax
