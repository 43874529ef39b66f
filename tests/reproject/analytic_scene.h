#pragma once
// Scenes of planes and axis-aligned boxes, ray cast at pixel centres into color and z-depth,
// so reproject tests have exact ground truth without files.
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/camera.h"
#include "core/image.h"
#include "core/pose.h"
#include "reproject/holes.h"
#include "reproject/view.h"

namespace parallax::test {

using ColorFn = std::function<Eigen::Vector3f(const Eigen::Vector3d&)>;

struct Plane {
  Eigen::Vector3d normal;  // Unit.
  double offset = 0;       // normal . x = offset.
  ColorFn color;
};

struct Box {
  Eigen::Vector3d min;
  Eigen::Vector3d max;
  ColorFn color;
};

struct Hit {
  double t = 0;  // Along the ray; with a direction of camera-z 1, the z-depth.
  Eigen::Vector3d point;
  Eigen::Vector3f color;
  bool box = false;
};

struct Scene {
  std::vector<Plane> planes;
  std::vector<Box> boxes;
  ColorFn sky;  // Of the unit world direction; null: black.

  std::optional<Hit> Intersect(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                               double t_min = 1e-9) const {
    std::optional<Hit> best;
    const auto consider = [&](double t, bool box, const ColorFn& color) {
      if (!(t > t_min) || (best && t >= best->t)) return;
      const Eigen::Vector3d point = origin + t * dir;
      best = Hit{t, point, color(point), box};
    };
    for (const Plane& plane : planes) {
      const double denom = plane.normal.dot(dir);
      if (std::abs(denom) < 1e-15) continue;
      consider((plane.offset - plane.normal.dot(origin)) / denom, false, plane.color);
    }
    for (const Box& box : boxes) {
      double enter = -std::numeric_limits<double>::infinity();
      double leave = std::numeric_limits<double>::infinity();
      for (int k = 0; k < 3; ++k) {
        if (std::abs(dir(k)) < 1e-15) {
          if (origin(k) < box.min(k) || origin(k) > box.max(k)) enter = leave + 1;
          continue;
        }
        const double a = (box.min(k) - origin(k)) / dir(k), b = (box.max(k) - origin(k)) / dir(k);
        enter = std::max(enter, std::min(a, b));
        leave = std::min(leave, std::max(a, b));
      }
      if (enter <= leave) consider(enter, true, box.color);
    }
    return best;
  }

  // Whether something lies strictly between a and b.
  bool Occluded(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    const std::optional<Hit> hit = Intersect(a, b - a, 1e-9);
    return hit && hit->t < 1 - 1e-9;
  }
};

// The world ray through a pixel centre, scaled so its camera-frame z is 1.
inline Eigen::Vector3d PixelRay(const PosedCamera& camera, double x, double y) {
  const Eigen::Vector3d in_cam((x + 0.5 - camera.camera.PrincipalX()) / camera.camera.FocalX(),
                               (y + 0.5 - camera.camera.PrincipalY()) / camera.camera.FocalY(), 1);
  return camera.cam_from_world.rotation.inverse() * in_cam;
}

inline SourceView RenderView(const Scene& scene, const PosedCamera& camera,
                             const std::string& name = "view") {
  SourceView view;
  view.name = name;
  view.camera = camera.camera;
  view.cam_from_world = camera.cam_from_world;
  const int width = static_cast<int>(camera.camera.width);
  const int height = static_cast<int>(camera.camera.height);
  view.color = Image(width, height, 3);
  view.depth = DepthMap(width, height);
  const Eigen::Vector3d origin = CameraCenter(camera.cam_from_world);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Eigen::Vector3d dir = PixelRay(camera, x, y);
      const std::optional<Hit> hit = scene.Intersect(origin, dir);
      Eigen::Vector3f color = Eigen::Vector3f::Zero();
      if (hit) {
        view.depth.At(x, y) = static_cast<float>(hit->t);
        color = hit->color;
      } else if (scene.sky) {
        color = scene.sky(dir.normalized());
      }
      for (int c = 0; c < 3; ++c) view.color.At(x, y, c) = color(c);
    }
  }
  return view;
}

// A camera at `center` with the world's axes (looking along +z).
inline PosedCamera CameraAt(const Camera& camera, const Eigen::Vector3d& center,
                            const Eigen::Quaterniond& cam_from_world_rotation =
                                Eigen::Quaterniond::Identity()) {
  return {camera, Rigid3d(cam_from_world_rotation, -(cam_from_world_rotation * center))};
}

// A smooth texture of the given world period around a base color (linear RGB).
inline ColorFn WavyTexture(const Eigen::Vector3f& base, double period) {
  return [base, period](const Eigen::Vector3d& p) {
    const double w = 2 * std::numbers::pi / period;
    return Eigen::Vector3f(
        base(0) + static_cast<float>(0.15 * std::sin(w * p.x()) * std::cos(0.7 * w * p.y())),
        base(1) + static_cast<float>(0.15 * std::cos(w * p.y() + 0.3)),
        base(2) + static_cast<float>(0.1 * std::sin(w * (p.x() + p.y()))));
  };
}

inline Plane WallAt(double z, const ColorFn& color) { return {Eigen::Vector3d::UnitZ(), z, color}; }

// PSNR in dB between two linear images compared in sRGB [0, 1], over pixels where `use` is
// true; +inf when they are equal there.
inline double PsnrSrgb(const Image& a, const Image& b, const std::function<bool(int, int)>& use) {
  double sum = 0;
  long count = 0;
  for (int y = 0; y < a.Height(); ++y) {
    for (int x = 0; x < a.Width(); ++x) {
      if (!use(x, y)) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = LinearToSrgb(std::clamp(a.At(x, y, c), 0.0f, 1.0f)) -
                         LinearToSrgb(std::clamp(b.At(x, y, c), 0.0f, 1.0f));
        sum += d * d;
        ++count;
      }
    }
  }
  if (count == 0 || sum == 0) return std::numeric_limits<double>::infinity();
  return 10 * std::log10(static_cast<double>(count) / sum);
}

inline long CountClass(const ClassMap& map, PixelClass c) {
  return std::count(map.classes.begin(), map.classes.end(), c);
}

}  // namespace parallax::test
