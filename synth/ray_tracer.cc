#include "synth/ray_tracer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "geometry/embree_scene.h"
#include "synth/texture.h"

namespace parallax {
namespace {

// Segments around a sphere or cylinder: the faceting error is r (1 - cos(pi / 128)) = 3e-4 r.
constexpr int kRoundSegments = 128;
// A cylinder's curved side: its first triangles, two per segment (TessellateCylinder).
constexpr int kCylinderSideTriangles = 2 * kRoundSegments;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

void AddQuad(TriangleMesh& mesh, int a, int b, int c, int d) {
  mesh.triangles.emplace_back(a, b, c);
  mesh.triangles.emplace_back(a, c, d);
}

TriangleMesh TessellatePlane(const ObjectDesc& object) {
  const Eigen::Vector3d n = object.normal;
  const Eigen::Vector3d reference =
      std::abs(n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = (reference - n * n.dot(reference)).normalized();
  const Eigen::Vector3d v = n.cross(u);
  TriangleMesh mesh;
  for (const auto& [su, sv] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    mesh.vertices.push_back((object.center + 0.5 * su * object.size.x() * u +
                             0.5 * sv * object.size.y() * v).cast<float>());
  }
  AddQuad(mesh, 0, 1, 2, 3);
  return mesh;
}

TriangleMesh TessellateBox(const ObjectDesc& object) {
  const Eigen::Matrix3d yaw =
      Eigen::AngleAxisd(object.yaw_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitZ())
          .toRotationMatrix();
  TriangleMesh mesh;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d sign((corner & 1) ? 0.5 : -0.5, (corner & 2) ? 0.5 : -0.5,
                               (corner & 4) ? 0.5 : -0.5);
    mesh.vertices.push_back(
        (object.center + yaw * sign.cwiseProduct(object.size)).cast<float>());
  }
  // Faces by corner bits (x = 1, y = 2, z = 4).
  AddQuad(mesh, 0, 1, 3, 2);  // z-
  AddQuad(mesh, 4, 5, 7, 6);  // z+
  AddQuad(mesh, 0, 1, 5, 4);  // y-
  AddQuad(mesh, 2, 3, 7, 6);  // y+
  AddQuad(mesh, 0, 2, 6, 4);  // x-
  AddQuad(mesh, 1, 3, 7, 5);  // x+
  return mesh;
}

TriangleMesh TessellateSphere(const ObjectDesc& object) {
  TriangleMesh mesh;
  const int rings = kRoundSegments / 2;
  for (int ring = 0; ring <= rings; ++ring) {
    const double polar = std::numbers::pi * ring / rings;
    for (int segment = 0; segment < kRoundSegments; ++segment) {
      const double azimuth = 2 * std::numbers::pi * segment / kRoundSegments;
      const Eigen::Vector3d direction(std::sin(polar) * std::cos(azimuth),
                                      std::sin(polar) * std::sin(azimuth), std::cos(polar));
      mesh.vertices.push_back((object.center + object.radius * direction).cast<float>());
    }
  }
  for (int ring = 0; ring < rings; ++ring) {
    for (int segment = 0; segment < kRoundSegments; ++segment) {
      const int next = (segment + 1) % kRoundSegments;
      AddQuad(mesh, ring * kRoundSegments + segment, ring * kRoundSegments + next,
              (ring + 1) * kRoundSegments + next, (ring + 1) * kRoundSegments + segment);
    }
  }
  return mesh;
}

TriangleMesh TessellateCylinder(const ObjectDesc& object) {
  TriangleMesh mesh;
  for (int level = 0; level < 2; ++level) {
    for (int segment = 0; segment < kRoundSegments; ++segment) {
      const double azimuth = 2 * std::numbers::pi * segment / kRoundSegments;
      mesh.vertices.push_back((object.center + Eigen::Vector3d(object.radius * std::cos(azimuth),
                                                               object.radius * std::sin(azimuth),
                                                               level * object.height))
                                  .cast<float>());
    }
  }
  for (int segment = 0; segment < kRoundSegments; ++segment) {
    const int next = (segment + 1) % kRoundSegments;
    AddQuad(mesh, segment, next, kRoundSegments + next, kRoundSegments + segment);
  }
  const int bottom_center = static_cast<int>(mesh.vertices.size());
  mesh.vertices.push_back(object.center.cast<float>());
  mesh.vertices.push_back((object.center + Eigen::Vector3d(0, 0, object.height)).cast<float>());
  for (int segment = 0; segment < kRoundSegments; ++segment) {
    const int next = (segment + 1) % kRoundSegments;
    mesh.triangles.emplace_back(bottom_center, next, segment);
    mesh.triangles.emplace_back(bottom_center + 1, kRoundSegments + segment,
                                kRoundSegments + next);
  }
  return mesh;
}

Eigen::Vector3f SkyColor(const SkyDesc& sky, const Eigen::Vector3d& direction) {
  const double elevation = std::max(0.0, direction.normalized().z());
  return sky.horizon + static_cast<float>(std::sqrt(elevation)) * (sky.zenith - sky.horizon);
}

RTCRayHit PrimaryRay(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction) {
  RTCRayHit ray{};
  ray.ray.org_x = origin.x();
  ray.ray.org_y = origin.y();
  ray.ray.org_z = origin.z();
  ray.ray.dir_x = direction.x();
  ray.ray.dir_y = direction.y();
  ray.ray.dir_z = direction.z();
  ray.ray.tnear = 0;
  ray.ray.tfar = kInfinity;
  ray.ray.mask = ~0u;
  ray.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  ray.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return ray;
}

// What a primary ray found: the surface point, its normal facing the ray, and its albedo.
struct SurfaceSample {
  bool hit = false;
  Eigen::Vector3d point;
  Eigen::Vector3d normal;
  Eigen::Vector3d view;  // Unit vector from the point towards the eye.
  Eigen::Vector3f albedo;
  const MaterialDesc* material = nullptr;
};

}  // namespace

TriangleMesh TessellateObject(const ObjectDesc& object) {
  switch (object.type) {
    case ShapeType::kPlane: return TessellatePlane(object);
    case ShapeType::kBox: return TessellateBox(object);
    case ShapeType::kSphere: return TessellateSphere(object);
    case ShapeType::kCylinder: return TessellateCylinder(object);
  }
  throw InternalError("unknown shape type");
}

struct RayTracer::Impl {
  const SceneDesc& scene;
  EmbreeScene embree{true};

  explicit Impl(const SceneDesc& scene_in) : scene(scene_in) {}

  SurfaceSample Surface(const RTCRayHit& ray, double focal_px) const;
  Eigen::Vector3f Shade(const SurfaceSample& surface, const float* light_visible) const;
  RTCRay ShadowRay(const SurfaceSample& surface, const LightDesc& light) const;
  void RenderRow(const Camera& camera, const Rigid3d& cam_from_world, int y,
                 RenderedView& view) const;
};

RayTracer::RayTracer(const SceneDesc& scene) : impl_(std::make_unique<Impl>(scene)) {
  for (const ObjectDesc& object : scene.objects) {
    const TriangleMesh mesh = TessellateObject(object);
    impl_->embree.Add(mesh.vertices, mesh.triangles);  // Ids count up from 0: the object index.
  }
  impl_->embree.Commit();
}

RayTracer::~RayTracer() = default;

SurfaceSample RayTracer::Impl::Surface(const RTCRayHit& ray, double focal_px) const {
  SurfaceSample surface;
  if (ray.hit.geomID == RTC_INVALID_GEOMETRY_ID) return surface;
  surface.hit = true;
  const Eigen::Vector3d origin(ray.ray.org_x, ray.ray.org_y, ray.ray.org_z);
  const Eigen::Vector3d direction(ray.ray.dir_x, ray.ray.dir_y, ray.ray.dir_z);
  surface.point = origin + static_cast<double>(ray.ray.tfar) * direction;
  surface.view = -direction.normalized();
  const ObjectDesc& object = scene.objects[ray.hit.geomID];
  const Eigen::Vector3d geometric_normal(ray.hit.Ng_x, ray.hit.Ng_y, ray.hit.Ng_z);
  // Smooth shading normals for the round shapes; facets keep their geometric normal.
  if (object.type == ShapeType::kSphere) {
    surface.normal = surface.point - object.center;
  } else if (object.type == ShapeType::kCylinder &&
             static_cast<int>(ray.hit.primID) < kCylinderSideTriangles) {
    surface.normal = surface.point - object.center;
    surface.normal.z() = 0;
  } else {
    surface.normal = geometric_normal;
  }
  surface.normal.normalize();
  if (surface.normal.dot(surface.view) < 0) surface.normal = -surface.normal;
  surface.material = &scene.materials.at(object.material);
  // One pixel's footprint on the surface, stretched by the viewing obliquity (capped).
  const double distance = static_cast<double>(ray.ray.tfar) * direction.norm();
  const double obliquity = std::max(0.2, std::abs(surface.normal.dot(surface.view)));
  surface.albedo = EvaluateTexture(surface.material->texture, surface.point,
                                   distance / focal_px / obliquity);
  return surface;
}

RTCRay RayTracer::Impl::ShadowRay(const SurfaceSample& surface, const LightDesc& light) const {
  Eigen::Vector3d to_light = -light.direction;
  float distance = kInfinity;
  if (light.type == LightType::kPoint) {
    to_light = light.position - surface.point;
    distance = static_cast<float>(to_light.norm());
    to_light /= to_light.norm();
  }
  // Offset along the normal, relative to the coordinates' magnitude, against self-hits.
  const double offset = 1e-4 * std::max(1.0, surface.point.cwiseAbs().maxCoeff());
  const Eigen::Vector3f origin = (surface.point + offset * surface.normal).cast<float>();
  const RTCRayHit primary = PrimaryRay(origin, to_light.cast<float>());
  RTCRay ray = primary.ray;
  ray.tfar = distance * (1 - 1e-4f);
  return ray;
}

Eigen::Vector3f RayTracer::Impl::Shade(const SurfaceSample& surface,
                                       const float* light_visible) const {
  Eigen::Vector3f diffuse = Eigen::Vector3f::Constant(scene.ambient);
  Eigen::Vector3f specular = Eigen::Vector3f::Zero();
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const LightDesc& light = scene.lights[i];
    Eigen::Vector3d to_light = -light.direction;
    float irradiance = light.intensity;
    if (light.type == LightType::kPoint) {
      to_light = light.position - surface.point;
      irradiance /= static_cast<float>(to_light.squaredNorm());
      to_light.normalize();
    }
    const double cosine = surface.normal.dot(to_light);
    if (cosine <= 0 || light_visible[i] == 0) continue;
    diffuse += (irradiance * static_cast<float>(cosine)) * light.color;
    const Eigen::Vector3d half = (to_light + surface.view).normalized();
    const double highlight =
        std::pow(std::max(0.0, surface.normal.dot(half)), surface.material->shininess);
    specular += (irradiance * surface.material->specular * static_cast<float>(highlight)) *
                light.color;
  }
  return surface.albedo.cwiseProduct(diffuse) + specular;
}

void RayTracer::Impl::RenderRow(const Camera& camera, const Rigid3d& cam_from_world, int y,
                                RenderedView& view) const {
  const int width = camera.width;
  const int samples = scene.image.supersampling;
  const int per_pixel = samples * samples + 1;  // Sub-samples, then the pixel-centre ray.
  const Eigen::Matrix3d world_from_cam = cam_from_world.rotation.conjugate().toRotationMatrix();
  const Eigen::Vector3f eye = CameraCenter(cam_from_world).cast<float>();

  // Rays with z = 1 in the camera frame: the hit distance t is the z-depth.
  std::vector<RTCRayHit> rays;
  rays.reserve(static_cast<size_t>(width) * per_pixel);
  for (int x = 0; x < width; ++x) {
    for (int s = 0; s < per_pixel; ++s) {
      const bool centre = s == samples * samples;
      const double px = x + (centre ? 0.5 : (s % samples + 0.5) / samples);
      const double py = y + (centre ? 0.5 : (s / samples + 0.5) / samples);
      const Eigen::Vector3d ray_in_cam = *camera.Unproject({px, py});
      rays.push_back(PrimaryRay(eye, (world_from_cam * ray_in_cam).cast<float>()));
    }
  }
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  rtcIntersect1M(embree.Handle(), &context, rays.data(), static_cast<unsigned>(rays.size()),
                 sizeof(RTCRayHit));

  std::vector<SurfaceSample> surfaces(rays.size());
  const size_t num_lights = scene.lights.size();
  std::vector<RTCRay> shadow_rays(rays.size() * num_lights);
  for (size_t i = 0; i < rays.size(); ++i) {
    surfaces[i] = Surface(rays[i], camera.FocalX());
    for (size_t l = 0; l < num_lights; ++l) {
      // A miss gets a ray that is already "done" (tnear > tfar) so the batch stays aligned.
      RTCRay& shadow = shadow_rays[i * num_lights + l];
      if (surfaces[i].hit) {
        shadow = ShadowRay(surfaces[i], scene.lights[l]);
      } else {
        shadow = PrimaryRay(eye, Eigen::Vector3f::UnitZ()).ray;
        shadow.tnear = 1;
        shadow.tfar = 0;
      }
    }
  }
  rtcInitIntersectContext(&context);
  rtcOccluded1M(embree.Handle(), &context, shadow_rays.data(),
                static_cast<unsigned>(shadow_rays.size()), sizeof(RTCRay));

  std::vector<float> light_visible(num_lights);
  for (int x = 0; x < width; ++x) {
    Eigen::Vector3f color = Eigen::Vector3f::Zero();
    for (int s = 0; s < per_pixel; ++s) {
      const size_t i = static_cast<size_t>(x) * per_pixel + s;
      const SurfaceSample& surface = surfaces[i];
      if (s == samples * samples) {  // Centre ray: depth and normal.
        if (surface.hit) {
          view.depth.At(x, y) = rays[i].ray.tfar;
          const Eigen::Vector3d normal_in_cam = cam_from_world.rotation * surface.normal;
          for (int c = 0; c < 3; ++c) view.normal.At(x, y, c) = static_cast<float>(normal_in_cam[c]);
        }
        continue;
      }
      for (size_t l = 0; l < num_lights; ++l) {
        // rtcOccluded sets tfar to -inf when something blocks the light.
        light_visible[l] = shadow_rays[i * num_lights + l].tfar >= 0 ? 1.0f : 0.0f;
      }
      const Eigen::Vector3d direction(rays[i].ray.dir_x, rays[i].ray.dir_y, rays[i].ray.dir_z);
      color += surface.hit ? Shade(surface, light_visible.data()) : SkyColor(scene.sky, direction);
    }
    color /= static_cast<float>(samples * samples);
    for (int c = 0; c < 3; ++c) view.color.At(x, y, c) = color[c];
  }
}

RenderedView RayTracer::Render(const Camera& camera, const Rigid3d& cam_from_world) const {
  camera.Check();
  if (camera.HasDistortion()) throw InternalError("RayTracer renders pinhole cameras");
  const int width = static_cast<int>(camera.width);
  const int height = static_cast<int>(camera.height);
  RenderedView view{Image(width, height, 3), DepthMap(width, height), Image(width, height, 3)};
  // Whole rows per task: threads never share the cache lines they write.
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 2), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y != rows.end(); ++y) impl_->RenderRow(camera, cam_from_world, y, view);
  });
  return view;
}

}  // namespace parallax
