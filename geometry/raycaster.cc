#include "geometry/raycaster.h"

#include <limits>
#include <optional>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/embree_scene.h"

namespace parallax {

struct MeshRaycaster::Impl {
  EmbreeScene embree;
};

MeshRaycaster::MeshRaycaster(const std::vector<Eigen::Vector3f>& vertices,
                             const std::vector<Eigen::Vector3i>& triangles)
    : impl_(std::make_unique<Impl>()) {
  if (!triangles.empty()) impl_->embree.Add(vertices, triangles);
  impl_->embree.Commit();
}

MeshRaycaster::~MeshRaycaster() = default;

namespace {

RTCRay MakeRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float tfar) {
  RTCRay ray{};
  ray.org_x = origin.x();
  ray.org_y = origin.y();
  ray.org_z = origin.z();
  ray.dir_x = direction.x();
  ray.dir_y = direction.y();
  ray.dir_z = direction.z();
  ray.tnear = 0;
  ray.tfar = tfar;
  ray.mask = ~0u;
  return ray;
}

}  // namespace

std::vector<RayHit> MeshRaycaster::CastPixels(const Camera& camera,
                                              const Rigid3d& cam_from_world) const {
  const int width = static_cast<int>(camera.width), height = static_cast<int>(camera.height);
  std::vector<RayHit> hits(static_cast<size_t>(width) * height);
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3f eye = CameraCenter(cam_from_world).cast<float>();
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    std::vector<RTCRayHit> rays(static_cast<size_t>(width));
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        // z = 1 in the camera frame: the hit distance is the z-depth. A pixel whose distortion
        // cannot be inverted gets an inactive ray (tfar < tnear), which hits nothing.
        const std::optional<Eigen::Vector3d> in_cam = camera.Unproject(Eigen::Vector2d(x + 0.5, y + 0.5));
        RTCRayHit& ray = rays[static_cast<size_t>(x)];
        constexpr float kInfinity = std::numeric_limits<float>::infinity();
        ray.ray = MakeRay(eye, (world_from_cam * in_cam.value_or(Eigen::Vector3d::UnitZ())).cast<float>(),
                          in_cam ? kInfinity : -kInfinity);
        ray.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        ray.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
      }
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      rtcIntersect1M(impl_->embree.Handle(), &context, rays.data(), static_cast<unsigned>(width),
                     sizeof(RTCRayHit));
      for (int x = 0; x < width; ++x) {
        const RTCRayHit& ray = rays[static_cast<size_t>(x)];
        if (ray.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
        hits[static_cast<size_t>(y) * width + x] = {static_cast<int>(ray.hit.primID),
                                                    ray.ray.tfar, ray.hit.u, ray.hit.v};
      }
    }
  });
  return hits;
}

namespace {

// Whether each of `count` segments (ray i from make_segment(i), t in [0, tfar]) is free of the
// mesh, in batches over all threads.
template <typename MakeSegment>
std::vector<uint8_t> FreeSegments(RTCScene scene, size_t count, const MakeSegment& make_segment) {
  std::vector<uint8_t> free(count, 0);
  constexpr size_t kBatch = 1024;
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, kBatch), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<RTCRay> rays(range.size());
    for (size_t i = range.begin(); i < range.end(); ++i) rays[i - range.begin()] = make_segment(i);
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcOccluded1M(scene, &context, rays.data(), static_cast<unsigned>(rays.size()), sizeof(RTCRay));
    for (size_t i = range.begin(); i < range.end(); ++i) {
      // rtcOccluded sets tfar to -inf when something blocks the segment.
      free[i] = rays[i - range.begin()].tfar >= 0 ? 1 : 0;
    }
  });
  return free;
}

}  // namespace

std::vector<uint8_t> MeshRaycaster::Visible(const Eigen::Vector3f& eye,
                                            const std::vector<Eigen::Vector3f>& points,
                                            float tolerance) const {
  // Direction = the whole segment, so t runs from 0 (eye) to 1 (point).
  return FreeSegments(impl_->embree.Handle(), points.size(),
                      [&](size_t i) { return MakeRay(eye, points[i] - eye, 1.0f - tolerance); });
}

std::vector<uint8_t> MeshRaycaster::Unoccluded(const std::vector<Eigen::Vector3f>& origins,
                                               const Eigen::Vector3f& direction, float length) const {
  const Eigen::Vector3f unit = direction.normalized();
  return FreeSegments(impl_->embree.Handle(), origins.size(), [&](size_t i) { return MakeRay(origins[i], unit, length); });
}

}  // namespace parallax
