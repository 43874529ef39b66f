#pragma once
// Embree 3 ray tracer for synthetic scenes: the ground truth every stage is measured against.
#include <memory>
#include <vector>

#include "core/camera.h"
#include "core/depth_map.h"
#include "core/image.h"
#include "core/pose.h"
#include "geometry/triangle_mesh.h"
#include "synth/scene.h"

namespace parallax {

struct RenderedView {
  Image color;     // Linear RGB, supersampled.
  DepthMap depth;  // z-depth at pixel centres; 0 for sky.
  Image normal;    // Camera-frame unit normal facing the camera (3 channels); 0 for sky.
};

class RayTracer {
 public:
  // Tessellates and uploads the scene. Throws std::runtime_error if Embree reports an error.
  explicit RayTracer(const SceneDesc& scene);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  // Renders one view with all threads of the calling TBB arena. Deterministic: each pixel
  // depends only on its own rays, whatever the thread count. `camera` must be PINHOLE or
  // SIMPLE_PINHOLE.
  RenderedView Render(const Camera& camera, const Rigid3d& cam_from_world) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Triangle mesh of one object (world coordinates), as handed to Embree; a cylinder's curved
// side comes first.
TriangleMesh TessellateObject(const ObjectDesc& object);

}  // namespace parallax
