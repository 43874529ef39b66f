#include "synth/texture.h"

#include <algorithm>
#include <cmath>

#include "core/hash.h"

namespace parallax {
namespace {

// Integer hash (a murmur3-style finaliser over the lattice coordinates) -> [0, 1).
float LatticeValue(int64_t x, int64_t y, int64_t z, uint32_t seed) {
  uint64_t h = static_cast<uint64_t>(x) * 0x9E3779B97F4A7C15ull;
  h ^= static_cast<uint64_t>(y) * 0xC2B2AE3D27D4EB4Full + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(z) * 0x165667B19E3779F9ull + (h << 6) + (h >> 2);
  h ^= static_cast<uint64_t>(seed) * 0x27D4EB2F165667C5ull;
  return UnitFloat(MixBits(h));
}

// Pushes noise (centred on 0.5, spread ~0.1) towards 0 and 1 by `contrast` (the slope at
// 0.5 is 2 * contrast). A tanh rather than a clamp: saturated regions keep their fine detail,
// compressed, instead of turning into flat blobs that no stereo matcher can use.
float Stretch(float noise, float contrast) {
  return 0.5f + 0.5f * std::tanh(4 * contrast * (noise - 0.5f));
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

float FractalNoise(const Eigen::Vector3d& point, double scale, int octaves, uint32_t seed,
                   double footprint) {
  double sum = 0, total_weight = 0, weight = 1, frequency = 1 / scale;
  for (int octave = 0; octave < octaves; ++octave) {
    // Octaves finer than the pixel footprint would alias, differently in every view: fade
    // them out between two footprints and one, leaving their mean (0.5) in their place.
    const double wavelength = 1 / frequency;
    const double kept = std::clamp(wavelength / footprint - 1, 0.0, 1.0);
    // A different seed per octave keeps the layers' lattices from lining up.
    const double noise = kept > 0 ? static_cast<double>(ValueNoise(
                                        point * frequency, seed + 1013u * static_cast<uint32_t>(octave)))
                                  : 0.5;
    sum += weight * (kept * noise + (1 - kept) * 0.5);
    total_weight += weight;
    weight *= 0.6;
    frequency *= 2;
  }
  return static_cast<float>(sum / total_weight);
}

Eigen::Vector3f EvaluateTexture(const TextureDesc& texture, const Eigen::Vector3d& point,
                                double footprint) {
  switch (texture.type) {
    case TextureType::kFbm: {
      const float t = Stretch(FractalNoise(point, texture.scale, texture.octaves, texture.seed, footprint),
                              texture.contrast);
      return texture.color_a + t * (texture.color_b - texture.color_a);
    }
    case TextureType::kChecker: {
      // Cells are centred on the lattice points: axis-aligned surfaces through the origin
      // (the ground z = 0) then lie mid-cell, not on a cell boundary where float rounding of
      // the hit point would flip the parity from pixel to pixel.
      const Eigen::Vector3d cell = (point / texture.scale).array() + 0.5;
      const Eigen::Vector3d cell_index = cell.array().floor();
      const int64_t parity =
          static_cast<int64_t>(cell_index.x()) + static_cast<int64_t>(cell_index.y()) +
          static_cast<int64_t>(cell_index.z());
      const Eigen::Vector3f base = (parity & 1) ? texture.color_b : texture.color_a;
      // Fine noise inside each cell gives matchers something besides the cell corners.
      const float detail = Stretch(
          FractalNoise(point, texture.scale / 4, texture.octaves, texture.seed, footprint),
          texture.contrast);
      return base * (0.5f + detail);
    }
  }
  return texture.color_a;
}

}  // namespace parallax
