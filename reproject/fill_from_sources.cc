#include "reproject/fill_from_sources.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"

namespace parallax {
namespace {

// A source's depth within this share of the point's depth sees the same surface.
constexpr double kSameSurface = 0.05;
// Angles below this weigh alike: sources this close to the target's ray are equally good.
constexpr double kMinAngleRad = 0.02;

// One source in the form the per-pixel loop uses.
struct Lookup {
  Pinhole pinhole;
  Eigen::Matrix3d rotation;  // source_from_world.
  Eigen::Vector3d translation;
  Eigen::Vector3d centre;  // In the world.
  const FillSource* source;

  bool IsSky(int x, int y) const {
    const std::vector<uint8_t>* sky = source->background;
    if (sky == nullptr || sky->empty()) return false;
    return (*sky)[static_cast<size_t>(y) * static_cast<size_t>(pinhole.width) + static_cast<size_t>(x)] != 0;
  }

  // Adds the source's color of world point `point` to rgb with its weight, when the source
  // saw that point; `target_ray`: unit direction from the target's centre to the point.
  void Add(const Eigen::Vector3d& point, const Eigen::Vector3d& target_ray, double rgb[3],
           double* weight) const {
    const Eigen::Vector3d local = rotation * point + translation;
    if (!(local.z() > 0)) return;
    const double u = pinhole.fx * local.x() / local.z() + pinhole.cx;
    const double v = pinhole.fy * local.y() / local.z() + pinhole.cy;
    // Bilinear taps at pixel centres: the point must lie between four of them.
    const double fu = u - 0.5, fv = v - 0.5;
    if (!(fu >= 0 && fv >= 0 && fu < pinhole.width - 1 && fv < pinhole.height - 1)) return;
    const int x = static_cast<int>(fu), y = static_cast<int>(fv);
    const int nx = static_cast<int>(u), ny = static_cast<int>(v);
    const double seen = source->depth->At(nx, ny);
    if (seen > 0 ? std::abs(seen - local.z()) > kSameSurface * local.z() : IsSky(nx, ny)) return;
    const double angle = std::acos(std::clamp(target_ray.dot((point - centre).normalized()), -1.0, 1.0));
    const double w = 1 / (kMinAngleRad + angle);
    const double ax = fu - x, ay = fv - y;
    const Image& color = *source->color;
    const auto at = [&](int px, int py, int c) { return static_cast<double>(color.At(px, py, c)); };
    for (int c = 0; c < 3; ++c) {
      const double top = (1 - ax) * at(x, y, c) + ax * at(x + 1, y, c);
      const double bottom = (1 - ax) * at(x, y + 1, c) + ax * at(x + 1, y + 1, c);
      rgb[c] += w * ((1 - ay) * top + ay * bottom);
    }
    *weight += w;
  }
};

Lookup MakeLookup(const FillSource& source, size_t index) {
  if (source.color == nullptr || source.depth == nullptr) {
    throw InternalError("FillFromSources: source " + std::to_string(index) +
                        " has no color or depth");
  }
  Lookup lookup{Pinhole::From(source.camera.camera), source.camera.cam_from_world.rotation.toRotationMatrix(),
                source.camera.cam_from_world.translation, {}, &source};
  const int width = lookup.pinhole.width, height = lookup.pinhole.height;
  if (source.color->Width() != width || source.color->Height() != height || source.color->Channels() != 3 ||
      source.depth->Width() != width || source.depth->Height() != height) {
    throw InternalError("FillFromSources: source " + std::to_string(index) +
                        ": color or depth not of its camera's size");
  }
  lookup.centre = -(lookup.rotation.transpose() * lookup.translation);
  return lookup;
}

}  // namespace

FillFromSourcesSummary FillFromSources(const ClassMap& classes, const PosedCamera& target,
                                       std::span<const FillSource> sources, BlendResult* blend) {
  const int width = blend->color.Width(), height = blend->color.Height();
  if (classes.width != width || classes.height != height) {
    throw InternalError("FillFromSources: class map of another size than the blend");
  }
  std::vector<Lookup> lookups;
  for (size_t i = 0; i < sources.size(); ++i) lookups.push_back(MakeLookup(sources[i], i));
  const Pinhole camera = Pinhole::From(target.camera);
  const Eigen::Matrix3d world_from_cam = target.cam_from_world.rotation.toRotationMatrix().transpose();
  const Eigen::Vector3d centre = -(world_from_cam * target.cam_from_world.translation);
  std::atomic<int> colored{0};
  tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
    int count = 0;
    for (int y = rows.begin(); y < rows.end(); ++y) {
      for (int x = 0; x < width; ++x) {
        const float depth = blend->depth.At(x, y);
        if (!IsHole(classes.At(x, y)) || !(depth > 0)) continue;
        const Eigen::Vector3d ray = world_from_cam * camera.PixelRay(x, y);
        const Eigen::Vector3d point = centre + depth * ray;
        const Eigen::Vector3d unit_ray = ray.normalized();
        double rgb[3] = {0, 0, 0}, weight = 0;
        for (const Lookup& lookup : lookups) lookup.Add(point, unit_ray, rgb, &weight);
        if (!(weight > 0)) continue;
        for (int c = 0; c < 3; ++c) blend->color.At(x, y, c) = static_cast<float>(rgb[c] / weight);
        ++count;
      }
    }
    colored += count;
  });
  return {colored.load()};
}

}  // namespace parallax
