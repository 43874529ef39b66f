#pragma once
// Shared by the viewer tests and the viewer benchmark (parallax::viewer_testing): one headless
// GL context per process, synthetic scenes built from synth's shapes, and the ray-traced
// reference shadow mask.
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "geometry/raycaster.h"
#include "synth/ray_tracer.h"
#include "synth/scene.h"
#include "viewer/egl_context.h"
#include "viewer/renderer.h"
#include "eval/shadow_reference.h"
#include "viewer/viewer_scene.h"

namespace parallax::viewer_test {

// llvmpipe (LIBGL_ALWAYS_SOFTWARE=1, set by the context) for the whole test binary.
inline void EnsureGlContext() {
  static const auto context = std::make_unique<HeadlessGlContext>(true);
}

inline ObjectDesc Plane(double size, double z = 0) {
  ObjectDesc plane;
  plane.type = ShapeType::kPlane;
  plane.material = "m";
  plane.center = {0, 0, z};
  plane.size = {size, size, 0};
  return plane;
}

inline ObjectDesc Box(const Eigen::Vector3d& center, const Eigen::Vector3d& size, double yaw_deg = 0) {
  ObjectDesc box;
  box.type = ShapeType::kBox;
  box.material = "m";
  box.center = center;
  box.size = size;
  box.yaw_deg = yaw_deg;
  return box;
}

inline ObjectDesc Sphere(double radius) {
  ObjectDesc sphere;
  sphere.type = ShapeType::kSphere;
  sphere.material = "m";
  sphere.radius = radius;
  return sphere;
}

// The objects as one mesh with a grey 2x2 atlas, bounds and ground plane computed.
inline ViewerScene SceneFromObjects(const std::vector<ObjectDesc>& objects) {
  ViewerScene scene;
  for (const ObjectDesc& object : objects) {
    const TriangleMesh part = TessellateObject(object);
    const int base = static_cast<int>(scene.mesh.vertices.size());
    scene.mesh.vertices.insert(scene.mesh.vertices.end(), part.vertices.begin(), part.vertices.end());
    for (const Eigen::Vector3i& t : part.triangles) {
      scene.mesh.triangles.push_back(t + Eigen::Vector3i::Constant(base));
      for (int c = 0; c < 3; ++c) scene.mesh.corner_uvs.emplace_back(0.5f, 0.5f);
    }
  }
  scene.mesh.atlas = Image(2, 2, 3);
  for (float& v : scene.mesh.atlas.Pixels()) v = 0.7f;
  FinishViewerScene(scene);
  return scene;
}

// A 2 m box turned 20 degrees on a 10 m ground: the shadow tests' scene.
inline ViewerScene BoxOnGround() {
  return SceneFromObjects({Plane(10), Box({0.5, 0.2, 1}, {2, 2, 2}, 20)});
}

// SceneRenderer settings for shadow measurements: grey albedo, nothing but the mesh.
inline FrameSettings ShadowSettings(ShadowMode mode, const Eigen::Vector3d& light_direction) {
  FrameSettings settings;
  settings.shadows = mode;
  settings.texture = TextureMode::kShaded;
  settings.light.direction = light_direction;
  settings.show_cameras = false;
  settings.show_grid = false;
  return settings;
}

}  // namespace parallax::viewer_test
