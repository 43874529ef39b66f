#pragma once
// Procedural solid textures: color as a function of the 3D surface point, so every object is
// textured without UV coordinates and every view of a point sees the same color.
#include <Eigen/Core>

#include "synth/scene.h"

namespace parallax {

// 3D value noise in [0, 1], smooth (quintic interpolation), deterministic in (point, seed).
float ValueNoise(const Eigen::Vector3d& point, uint32_t seed);

// Sum of `octaves` noise layers, each half the size and 0.6 times the weight of the previous;
// in [0, 1]. `scale` is the size of the largest layer in scene units. Layers finer than
// `footprint` (the size one pixel covers on the surface, scene units) are faded out, as a
// mip-map would: without that they alias, differently in every view.
float FractalNoise(const Eigen::Vector3d& point, double scale, int octaves, uint32_t seed,
                   double footprint = 0);

// Linear-RGB albedo of the texture at a world point seen with a pixel `footprint`.
Eigen::Vector3f EvaluateTexture(const TextureDesc& texture, const Eigen::Vector3d& point,
                                double footprint = 0);

}  // namespace parallax
