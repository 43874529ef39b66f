#include "synth/texture.h"

#include <algorithm>
#include <cmath>

namespace parallax {
namespace {

// Integer hash (a murmur3-style finaliser over the lattice coordinates) -> [0, 1).
float LatticeValue(int64_t x, int64_t y, int64_t z, uint32_t seed) {
  uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(seed) * 0x27D4EB2F165667C5ull;
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDull;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ull;
  h ^= h >> 33;
  return static_cast<float>(h >> 40) / static_cast<float>(1ull << 24);
}

double Quintic(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

}  // namespace

float ValueNoise(const Eigen::Vector3d& point, uint32_t seed) {
  const Eigen::Vector3d floor = point.array().floor();
  const Eigen::Vector3d fraction = point - floor;
  const int64_t x = static_cast<int64_t>(floor.x());
  const int64_t y = static_cast<int64_t>(floor.y());
  const int64_t z = static_cast<int64_t>(floor.z());
  const double u = Quintic(fraction.x()), v = Quintic(fraction.y()), w = Quintic(fraction.z());
  double result = 0;
  for (int corner = 0; corner < 8; ++corner) {
    const int dx = corner & 1, dy = (corner >> 1) & 1, dz = (corner >> 2) & 1;
    const double weight = (dx ? u : 1 - u) * (dy ? v : 1 - v) * (dz ? w : 1 - w);
    result += weight * static_cast<double>(LatticeValue(x + dx, y + dy, z + dz, seed));
  }
  return static_cast<float>(result);
}

float FractalNoise(const Eigen::Vector3d& point, double scale, int octaves, uint32_t seed) {
  double sum = 0, total_weight = 0, weight = 1, frequency = 1 / scale;
  for (int octave = 0; octave < octaves; ++octave) {
    // A different seed per octave keeps the layers' lattices from lining up.
    sum += weight * static_cast<double>(
        ValueNoise(point * frequency, seed + 1013u * static_cast<uint32_t>(octave)));
    total_weight += weight;
    weight *= 0.6;
    frequency *= 2;
  }
  return static_cast<float>(sum / total_weight);
}

Eigen::Vector3f EvaluateTexture(const TextureDesc& texture, const Eigen::Vector3d& point) {
  switch (texture.type) {
    case TextureType::kFbm: {
      const float noise = FractalNoise(point, texture.scale, texture.octaves, texture.seed);
      const float t = std::clamp(0.5f + texture.contrast * 2 * (noise - 0.5f), 0.0f, 1.0f);
      return texture.color_a + t * (texture.color_b - texture.color_a);
    }
    case TextureType::kChecker: {
      const Eigen::Vector3d cell = (point / texture.scale).array().floor();
      const int64_t parity =
          static_cast<int64_t>(cell.x()) + static_cast<int64_t>(cell.y()) +
          static_cast<int64_t>(cell.z());
      const Eigen::Vector3f base = (parity & 1) ? texture.color_b : texture.color_a;
      // Fine noise inside each cell gives matchers something besides the cell corners.
      const float detail =
          FractalNoise(point, texture.scale / 4, texture.octaves, texture.seed);
      return base * (0.6f + 0.8f * detail);
    }
  }
  return texture.color_a;
}

}  // namespace parallax
