#pragma once
// A rotation drawn uniformly (a normalised 4D Gaussian), for tests with random poses.
#include <random>

#include <Eigen/Geometry>

namespace parallax::test {

inline Eigen::Quaterniond RandomRotation(std::mt19937& random) {
  std::normal_distribution<double> normal;
  return Eigen::Quaterniond(normal(random), normal(random), normal(random), normal(random)).normalized();
}

}  // namespace parallax::test
