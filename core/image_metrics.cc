#include "core/image_metrics.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace parallax {
namespace {

void CheckPair(const Image& image, const Image& reference) {
  if (image.Width() != reference.Width() || image.Height() != reference.Height() ||
      image.Channels() < 3 || reference.Channels() < 3) {
    throw InternalError("image metrics: need two RGB images of the same size");
  }
}

std::vector<double> Luma(const Image& image) {
  std::vector<double> luma(static_cast<size_t>(image.Width()) * static_cast<size_t>(image.Height()));
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      luma[static_cast<size_t>(y) * static_cast<size_t>(image.Width()) + static_cast<size_t>(x)] =
          0.2126 * static_cast<double>(image.At(x, y, 0)) + 0.7152 * static_cast<double>(image.At(x, y, 1)) +
          0.0722 * static_cast<double>(image.At(x, y, 2));
    }
  }
  return luma;
}

// Separable Gaussian blur with clamped borders.
std::vector<double> Blur(const std::vector<double>& values, int width, int height) {
  constexpr int kRadius = 5;
  constexpr double kSigma = 1.5;
  double kernel[2 * kRadius + 1];
  double sum = 0;
  for (int i = -kRadius; i <= kRadius; ++i) {
    kernel[i + kRadius] = std::exp(-0.5 * i * i / (kSigma * kSigma));
    sum += kernel[i + kRadius];
  }
  for (double& k : kernel) k /= sum;
  auto at = [&](const std::vector<double>& v, int x, int y) {
    return v[static_cast<size_t>(std::clamp(y, 0, height - 1)) * static_cast<size_t>(width) +
             static_cast<size_t>(std::clamp(x, 0, width - 1))];
  };
  std::vector<double> rows(values.size()), out(values.size());
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double total = 0;
      for (int i = -kRadius; i <= kRadius; ++i) total += kernel[i + kRadius] * at(values, x + i, y);
      rows[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = total;
    }
  }
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      double total = 0;
      for (int i = -kRadius; i <= kRadius; ++i) total += kernel[i + kRadius] * at(rows, x, y + i);
      out[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = total;
    }
  }
  return out;
}

}  // namespace

double Psnr(const Image& image, const Image& reference, const std::vector<uint8_t>& mask) {
  CheckPair(image, reference);
  double squared = 0;
  size_t pixels = 0;
  for (int y = 0; y < image.Height(); ++y) {
    for (int x = 0; x < image.Width(); ++x) {
      const size_t i = static_cast<size_t>(y) * static_cast<size_t>(image.Width()) + static_cast<size_t>(x);
      if (!mask.empty() && !mask[i]) continue;
      for (int c = 0; c < 3; ++c) {
        const double d = static_cast<double>(image.At(x, y, c)) - static_cast<double>(reference.At(x, y, c));
        squared += d * d;
      }
      ++pixels;
    }
  }
  if (pixels == 0) return 0;
  return -10 * std::log10(std::max(squared / (3.0 * static_cast<double>(pixels)), 1e-10));
}

double Ssim(const Image& image, const Image& reference) {
  CheckPair(image, reference);
  const int w = image.Width(), h = image.Height();
  const std::vector<double> a = Luma(image), b = Luma(reference);
  std::vector<double> aa(a.size()), bb(a.size()), ab(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    aa[i] = a[i] * a[i];
    bb[i] = b[i] * b[i];
    ab[i] = a[i] * b[i];
  }
  const std::vector<double> mu_a = Blur(a, w, h), mu_b = Blur(b, w, h);
  const std::vector<double> s_aa = Blur(aa, w, h), s_bb = Blur(bb, w, h), s_ab = Blur(ab, w, h);
  constexpr double kC1 = 0.01 * 0.01, kC2 = 0.03 * 0.03;
  double total = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double var_a = s_aa[i] - mu_a[i] * mu_a[i];
    const double var_b = s_bb[i] - mu_b[i] * mu_b[i];
    const double cov = s_ab[i] - mu_a[i] * mu_b[i];
    total += (2 * mu_a[i] * mu_b[i] + kC1) * (2 * cov + kC2) /
             ((mu_a[i] * mu_a[i] + mu_b[i] * mu_b[i] + kC1) * (var_a + var_b + kC2));
  }
  return a.empty() ? 0 : total / static_cast<double>(a.size());
}

}  // namespace parallax
