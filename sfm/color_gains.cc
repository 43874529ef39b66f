#include "sfm/color_gains.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <vector>

#include "core/check.h"
#include "core/image.h"
#include "core/statistics.h"

namespace parallax {
namespace fs = std::filesystem;
namespace {

// Linear values outside this range are too dark (noise, quantisation) or clipped.
constexpr float kDarkest = 0.01f;
constexpr float kBrightest = 0.9f;
constexpr int kIterations = 8;

struct Observation {
  size_t photo = 0;
  size_t point = 0;
  std::array<float, 3> log_color;
};

// The mean linear color of the 5x5 pixels around `xy` (COLMAP pixels: centres at +0.5), when
// every channel is usable.
std::optional<std::array<float, 3>> MeanColor(const Image& linear, const Eigen::Vector2d& xy) {
  const int cx = static_cast<int>(std::floor(xy.x())), cy = static_cast<int>(std::floor(xy.y()));
  if (cx < 2 || cy < 2 || cx + 2 >= linear.Width() || cy + 2 >= linear.Height()) return std::nullopt;
  std::array<float, 3> sum{0, 0, 0};
  for (int y = cy - 2; y <= cy + 2; ++y) {
    for (int x = cx - 2; x <= cx + 2; ++x) {
      for (int c = 0; c < 3; ++c) sum[static_cast<size_t>(c)] += linear.At(x, y, c);
    }
  }
  for (float& value : sum) {
    value /= 25;
    if (value < kDarkest || value > kBrightest) return std::nullopt;
  }
  return sum;
}

std::vector<Observation> Observe(const SparseModel& model, const fs::path& images_dir) {
  std::map<uint64_t, size_t> point_index;
  for (const Point3D& point : model.Points3D()) {
    if (point.track.size() >= 2) point_index.emplace(point.id, point_index.size());
  }
  std::vector<Observation> observations;
  for (size_t photo = 0; photo < model.Images().size(); ++photo) {
    const SparseImage& image = model.Images()[photo];
    Image linear = SrgbToLinear(ReadImage(images_dir / image.name));
    if (linear.Channels() < 3) continue;  // Grey photos: no white balance to correct.
    for (const Point2D& point : image.points2d) {
      const auto index = point_index.find(point.point3d_id);
      if (index == point_index.end()) continue;
      if (const auto color = MeanColor(linear, point.xy)) {
        Observation observation{photo, index->second, {}};
        for (size_t c = 0; c < 3; ++c) observation.log_color[c] = std::log((*color)[c]);
        observations.push_back(observation);
      }
    }
  }
  return observations;
}

// log(color) = point_log[p] - photo_log_gain[i], per channel: alternating medians.
std::vector<float> SolveLogGains(const std::vector<Observation>& observations, size_t photos, size_t points,
                                 size_t channel) {
  std::vector<float> log_gain(photos, 0), point_log(points, 0);
  std::vector<std::vector<double>> residuals;
  for (int iteration = 0; iteration < kIterations; ++iteration) {
    residuals.assign(points, {});
    for (const Observation& o : observations) residuals[o.point].push_back(o.log_color[channel] + log_gain[o.photo]);
    for (size_t p = 0; p < points; ++p) {
      if (!residuals[p].empty()) point_log[p] = static_cast<float>(Median(residuals[p]));
    }
    residuals.assign(photos, {});
    for (const Observation& o : observations) residuals[o.photo].push_back(point_log[o.point] - o.log_color[channel]);
    double mean = 0;
    size_t counted = 0;
    for (size_t i = 0; i < photos; ++i) {
      if (residuals[i].empty()) continue;
      log_gain[i] = static_cast<float>(Median(residuals[i]));
      mean += static_cast<double>(log_gain[i]);
      ++counted;
    }
    mean /= static_cast<double>(std::max<size_t>(1, counted));
    for (size_t i = 0; i < photos; ++i) {
      if (!residuals[i].empty()) log_gain[i] -= static_cast<float>(mean);
    }
  }
  return log_gain;
}

}  // namespace

void ColorGainsOptions::Check() const {
  RequireOption(min_observations >= 1, "ColorGainsOptions.min_observations", min_observations, ">= 1");
  RequireOption(max_gain >= 1, "ColorGainsOptions.max_gain", max_gain, ">= 1");
}

ColorGainsEstimate EstimateColorGains(const SparseModel& model, const fs::path& images_dir,
                                      const ColorGainsOptions& options) {
  options.Check();
  const std::vector<Observation> observations = Observe(model, images_dir);
  const size_t photos = model.Images().size();
  size_t points = 0;
  for (const Observation& o : observations) points = std::max(points, o.point + 1);
  std::vector<int> usable(photos, 0);
  for (const Observation& o : observations) ++usable[o.photo];
  std::array<std::vector<float>, 3> log_gains;
  for (size_t c = 0; c < 3; ++c) log_gains[c] = SolveLogGains(observations, photos, points, c);

  ColorGainsEstimate estimate;
  float lowest = options.max_gain, highest = 1 / options.max_gain;
  for (size_t i = 0; i < photos; ++i) {
    if (usable[i] < options.min_observations) {
      ++estimate.photos_without_gain;
      continue;
    }
    RgbGain gain;
    for (size_t c = 0; c < 3; ++c) {
      gain[c] = std::clamp(std::exp(log_gains[c][i]), 1 / options.max_gain, options.max_gain);
      lowest = std::min(lowest, gain[c]);
      highest = std::max(highest, gain[c]);
    }
    estimate.gains.by_photo[model.Images()[i].name] = gain;
  }
  char note[160];
  std::snprintf(note, sizeof note, "%zu photos from %zu observations: gains %.3f to %.3f; %d photos kept 1 (too few usable points)",
                estimate.gains.by_photo.size(), observations.size(), estimate.gains.by_photo.empty() ? 1.0 : static_cast<double>(lowest),
                estimate.gains.by_photo.empty() ? 1.0 : static_cast<double>(highest), estimate.photos_without_gain);
  estimate.note = note;
  return estimate;
}

}  // namespace parallax
