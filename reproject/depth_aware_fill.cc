#include "reproject/depth_aware_fill.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <tbb/parallel_for.h>

namespace parallax {
namespace {

constexpr int kMaxDirections = 16;

// The color of the background at infinity as an affine function of the target pixel's unit
// viewing ray, fitted by least squares to the pixels where background landed. Background is
// a function of direction alone, so where no source saw the sky (out of view above the
// sources' frames) this extrapolates its gradient instead of smearing the color of its edge
// (a linear model overshoots a sky that saturates towards the zenith; quadratic ones were
// unstable).
class SkyModel {
 public:
  SkyModel(const BlendResult& blend, const Pinhole& camera) : camera_(camera) {
    // Every other pixel of every other row is plenty for 4 unknowns per channel. The rows'
    // sums are taken in parallel and added in row order (the same fit on every run).
    const int width = blend.color.Width(), height = blend.color.Height();
    std::vector<Moments> rows(static_cast<size_t>((height + 1) / 2));
    tbb::parallel_for(0, static_cast<int>(rows.size()), [&](int row) {
      Moments& m = rows[static_cast<size_t>(row)];
      const int y = 2 * row;
      for (int x = 0; x < width; x += 2) {
        if (blend.Kind(x, y) != SampleKind::kBackground) continue;
        const Eigen::Vector3d ray = Ray(x, y);
        const Eigen::Vector3d rgb(blend.color.At(x, y, 0), blend.color.At(x, y, 1),
                                  blend.color.At(x, y, 2));
        ++m.count;
        m.ray += ray;
        m.ray_ray += ray * ray.transpose();
        m.rgb += rgb;
        m.ray_rgb += ray * rgb.transpose();
        m.max = m.max.cwiseMax(rgb);
      }
    });
    Moments sum;
    for (const Moments& row : rows) sum.Add(row);
    if (sum.count < kMinSamples) return;
    int below = 0;
    for (size_t row = 0; row < rows.size() && 2 * below < sum.count; ++row) {
      below += rows[row].count;
      median_row_ = 2 * static_cast<int>(row);
    }
    // The least-squares fit of rgb = c0 + C (ray - mean ray), from the sums: centred on the
    // mean ray, the constant and the gradient decouple. Rays are unit vectors, so the
    // centred second moments lose ~4 of double's 16 digits even over a patch of sky 0.01 rad
    // across.
    const double count = sum.count;
    mean_ray_ = sum.ray / count;
    Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
    normal(0, 0) = count;
    normal.bottomRightCorner<3, 3>() = sum.ray_ray - count * mean_ray_ * mean_ray_.transpose();
    Eigen::Matrix<double, 4, 3> rhs;
    rhs.row(0) = sum.rgb.transpose();
    rhs.bottomRows<3>() = sum.ray_rgb - mean_ray_ * sum.rgb.transpose();
    for (int c = 0; c < 3; ++c) max_[c] = std::max(max_[c], static_cast<float>(sum.max[c]));
    // A ridge on the gradient: over a patch of sky narrower than ~kMinSpreadRad the gradient
    // is not determined and the model stays close to the patch's mean color.
    for (int k = 1; k < 4; ++k) normal(k, k) += count * kMinSpreadRad * kMinSpreadRad;
    coefficients_ = normal.ldlt().solve(rhs);
    valid_ = coefficients_.allFinite();
  }

  // False when too little background landed to fit (then FillPixel averages neighbours).
  bool Valid() const { return valid_; }

  // The row with half the landed background above it: where the sky is, seen from this view.
  int MedianRow() const { return median_row_; }

  // Color at pixel (x, y), clamped to [0, max(1, brightest fitted value)] per channel (far
  // outside the fitted rays a linear model can run away; photos are at most 1).
  void ColorAt(int x, int y, float rgb[3]) const {
    const Eigen::Vector3d d = Ray(x, y) - mean_ray_;
    const Eigen::Vector4d f(1, d.x(), d.y(), d.z());
    for (int c = 0; c < 3; ++c) {
      rgb[c] = std::clamp(static_cast<float>(f.dot(coefficients_.col(c))), 0.0f, max_[c]);
    }
  }

 private:
  static constexpr int kMinSamples = 64;
  static constexpr double kMinSpreadRad = 0.01;

  // Sums over background samples of their unit rays and colors.
  struct Moments {
    int count = 0;
    Eigen::Vector3d ray = Eigen::Vector3d::Zero();
    Eigen::Matrix3d ray_ray = Eigen::Matrix3d::Zero();
    Eigen::Vector3d rgb = Eigen::Vector3d::Zero();
    Eigen::Matrix3d ray_rgb = Eigen::Matrix3d::Zero();
    Eigen::Vector3d max = Eigen::Vector3d::Zero();

    void Add(const Moments& other) {
      count += other.count;
      ray += other.ray;
      ray_ray += other.ray_ray;
      rgb += other.rgb;
      ray_rgb += other.ray_rgb;
      max = max.cwiseMax(other.max);
    }
  };

  Eigen::Vector3d Ray(int x, int y) const { return camera_.PixelRay(x, y).normalized(); }

  Pinhole camera_;
  Eigen::Vector3d mean_ray_ = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 4, 3> coefficients_ = Eigen::Matrix<double, 4, 3>::Zero();
  float max_[3] = {1, 1, 1};
  int median_row_ = 0;
  bool valid_ = false;
};

struct Candidate {
  float depth;  // +inf for background.
  float distance_px;
  const float* rgb;
};

class DepthAwareFiller {
 public:
  DepthAwareFiller(const FillOptions& options, const SkyModel& sky, BlendResult* blend)
      : blend_(*blend), sky_(sky), width_(blend->color.Width()), height_(blend->color.Height()),
        count_(options.directions), tolerance_(static_cast<float>(options.background_tolerance)),
        hole_sky_directions_(static_cast<int>(std::ceil(options.hole_sky_share * count_))) {
    MeasureSteps();
    MeasureDistances();
  }

  // How many directions must find background at infinity for it to be the background side of
  // pixel (x, y) of class c. Out of view: one (background is the farthest of all) at or above
  // the sky's median row, else more than there are: beside the sources' frames a wall or the
  // ground goes on, and one far patch of sky must not paint them (below the sky, background
  // only where no surface is found). For a hole, where the ray reaches something the sources
  // see behind what is in front of it, hole_sky_share of them where it is open to the sky,
  // else more than there are (sky next to a disoccluded wall top would win as "farthest").
  int SkyDirections(PixelClass c, bool open_to_sky, int y) const {
    if (!IsHole(c)) return y <= sky_.MedianRow() ? 1 : count_ + 1;
    return open_to_sky ? hole_sky_directions_ : count_ + 1;
  }

  // The nearest columns with a sample on either side of a pixel in its row (-1 and the width
  // where there is none): the marches along the row (directions 0 and pi) become one lookup
  // each, as the row is walked (FillRow). An out-of-view band across the image left them to
  // cross it pixel by pixel (the distance field lets no march along the band's edge jump),
  // 40% of the fill of a view looking up.
  struct RowSamples {
    int left, right;
  };

  // Fills the pixels of row y that ShouldFill (they have no sample); returns how many it
  // filled.
  int FillRow(const ClassMap& classes, const FillOptions& options, int y) {
    const SampleKind* kind = blend_.kind.data() + Index(0, y);
    RowSamples row{-1, -1};
    int filled = 0;
    for (int x = 0; x < width_; ++x) {
      if (kind[x] != SampleKind::kNone) {
        row.left = x;
        continue;
      }
      const PixelClass pixel_class = classes.At(x, y);
      if (!ShouldFill(pixel_class, options)) continue;
      if (row.right <= x) {  // The first pixel of a run without samples.
        row.right = x + 1;
        while (row.right < width_ && kind[row.right] == SampleKind::kNone) ++row.right;
      }
      const int sky_directions = SkyDirections(pixel_class, classes.OpenToSky(x, y), y);
      if (FillPixel(x, y, sky_directions, row)) ++filled;
    }
    return filled;
  }

  // Reads only pixels with samples and writes only the pixel itself (which has none), so rows
  // can be filled in parallel in place. `row`: the samples beside the pixel in its row.
  // Background at infinity is the background side once `sky_directions` directions find it
  // (SkyDirections).
  bool FillPixel(int x, int y, int sky_directions, const RowSamples& row) {
    std::array<Candidate, kMaxDirections> candidates;
    int found = 0, skies = 0;
    float farthest = 0, farthest_surface = 0;
    for (int k = 0; k < count_; ++k) {
      Candidate* candidate = &candidates[static_cast<size_t>(found)];
      if (!Find(k, x, y, row, candidate)) continue;
      const float depth = candidate->depth;
      if (std::isinf(depth)) {
        // Background is the farthest of all, and where it is taken the sky model alone gives
        // the color: the other directions cannot change the result.
        if (++skies >= sky_directions && sky_.Valid()) {
          WriteBackground(x, y);
          return true;
        }
      } else {
        farthest_surface = std::max(farthest_surface, depth);
      }
      farthest = std::max(farthest, depth);
      ++found;
    }
    if (found == 0) return false;
    if (skies < sky_directions && farthest_surface > 0) farthest = farthest_surface;
    const bool background = std::isinf(farthest);
    const float limit = background ? farthest : farthest * (1.0f - tolerance_);
    float rgb[3] = {0, 0, 0}, depth = 0, weight = 0;
    for (int k = 0; k < found; ++k) {
      const Candidate& c = candidates[static_cast<size_t>(k)];
      if (!(c.depth >= limit) || (!background && std::isinf(c.depth))) continue;
      const float w = 1.0f / c.distance_px;
      for (int ch = 0; ch < 3; ++ch) rgb[ch] += w * c.rgb[ch];
      if (!background) depth += w * c.depth;
      weight += w;
    }
    if (background && sky_.Valid()) {
      WriteBackground(x, y);
      return true;
    }
    const size_t i = Index(x, y);
    float* out = blend_.color.Pixels().data() + 3 * i;
    for (int ch = 0; ch < 3; ++ch) out[ch] = rgb[ch] / weight;
    blend_.depth.Values()[i] = background ? 0.0f : depth / weight;
    return true;
  }

 private:
  struct Step {
    int dx, dy;      // Pixel offset.
    ptrdiff_t di;    // The same as an index offset: dy * width + dx.
    float distance;  // Steps of one pixel that reach the pixel first.
  };

  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  }

  // The sky model's color at (x, y), with depth 0 (background at infinity).
  void WriteBackground(int x, int y) {
    const size_t i = Index(x, y);
    sky_.ColorAt(x, y, blend_.color.Pixels().data() + 3 * i);
    blend_.depth.Values()[i] = 0.0f;
  }

  // The nearest sample from (x, y) in direction k: along the row (k = 0 and the opposite one)
  // looked up in `row`, else marched to.
  bool Find(int k, int x, int y, const RowSamples& row, Candidate* out) const {
    if (k == 0) return InRow(x, y, row.right, out);
    if (2 * k == count_) return InRow(x, y, row.left, out);
    const auto direction = static_cast<size_t>(k);
    return March(x, y, &steps_[direction * static_cast<size_t>(max_steps_)], step_counts_[direction], out);
  }

  // `steps`: the direction's `count` pixel offsets (MeasureSteps). Not inlined: inside
  // FillRow, with more live there than registers, the loop kept its state on the stack.
  [[gnu::noinline]] bool March(int x, int y, const Step* steps, int count, Candidate* out) const {
    const auto start = static_cast<ptrdiff_t>(Index(x, y));
    for (int step = 1; step < count; ++step) {
      // Unsigned, a negative coordinate is past the width too: one test per axis.
      const auto ix = static_cast<unsigned>(x + steps[step].dx);
      const auto iy = static_cast<unsigned>(y + steps[step].dy);
      if (ix >= static_cast<unsigned>(width_) || iy >= static_cast<unsigned>(height_)) return false;
      const auto j = static_cast<size_t>(start + steps[step].di);
      if (blend_.kind[j] == SampleKind::kNone) {
        // A step moves at most one pixel along each axis, so the next kBlock * distance - 4
        // steps stay in blocks without samples (distance_); one fewer leaves a step to spare
        // for rounding. Passing them untested, the march finds what it would step by step.
        const int distance = distance_[BlockIndex(static_cast<int>(ix / kBlock),
                                                  static_cast<int>(iy / kBlock))];
        if (distance > 1) step += kBlock * distance - 5;
        continue;
      }
      CandidateAt(j, steps[step].distance, out);
      return true;
    }
    return false;  // Past the last step, outside the image from any pixel.
  }

  // The sample at `column` of row y as the candidate of a march along the row from x; false
  // outside the image (the row has none on that side).
  bool InRow(int x, int y, int column, Candidate* out) const {
    if (column < 0 || column >= width_) return false;
    CandidateAt(Index(column, y), static_cast<float>(std::abs(column - x)), out);
    return true;
  }

  // Sample j, distance_px from the pixel being filled.
  void CandidateAt(size_t j, float distance_px, Candidate* out) const {
    out->depth = blend_.kind[j] == SampleKind::kBackground ? std::numeric_limits<float>::infinity()
                                                           : blend_.depth.Values()[j];
    out->distance_px = distance_px;
    out->rgb = blend_.color.Pixels().data() + 3 * j;
  }

  // steps_: per direction k, the pixels reached by steps of one pixel from a pixel's centre,
  // as offsets from the pixel: after s steps (floor(0.5 + s cos), floor(0.5 + s sin)), the
  // same from every pixel, each pixel once (a diagonal reaches one every 1.4 steps), with
  // the step that reaches it first; step_counts_[k] of them. A march then reads a table
  // instead of stepping in float, and tests each pixel once. After max_steps_ steps a march
  // has left the image whichever pixel it started from (every direction moves at least
  // cos(45 deg) of a pixel per step along one axis).
  void MeasureSteps() {
    max_steps_ = static_cast<int>(std::ceil(std::max(width_, height_) * std::sqrt(2.0))) + 2;
    steps_.resize(static_cast<size_t>(count_) * static_cast<size_t>(max_steps_));
    step_counts_.assign(static_cast<size_t>(count_), 0);
    for (int k = 0; k < count_; ++k) {
      const double angle = 2 * std::numbers::pi * k / count_;
      const auto dx = static_cast<float>(std::cos(angle)), dy = static_cast<float>(std::sin(angle));
      Step* steps = &steps_[static_cast<size_t>(k) * static_cast<size_t>(max_steps_)];
      int& count = step_counts_[static_cast<size_t>(k)];
      for (int s = 0; s < max_steps_; ++s) {
        const auto fs = static_cast<float>(s);
        const int step_x = static_cast<int>(std::floor(0.5f + fs * dx));
        const int step_y = static_cast<int>(std::floor(0.5f + fs * dy));
        if (count > 0 && steps[count - 1].dx == step_x && steps[count - 1].dy == step_y) continue;
        steps[count++] = {step_x, step_y, static_cast<ptrdiff_t>(step_y) * width_ + step_x, fs};
      }
    }
  }

  size_t BlockIndex(int bx, int by) const {
    return static_cast<size_t>(by) * static_cast<size_t>(blocks_x_) + static_cast<size_t>(bx);
  }

  // distance_: per kBlock x kBlock block, the chessboard distance in blocks to the nearest
  // block with a sample (0 for one; capped), by the two-pass chamfer transform with unit
  // steps, which is exact for it. Lets a march cross an empty region (out of view above the
  // scene) in a few jumps, for a transform 16 times smaller than the image.
  void MeasureDistances() {
    blocks_x_ = (width_ + kBlock - 1) / kBlock;
    const int blocks_y = (height_ + kBlock - 1) / kBlock;
    constexpr uint32_t kFar = std::numeric_limits<uint16_t>::max();
    distance_.assign(static_cast<size_t>(blocks_x_) * static_cast<size_t>(blocks_y), kFar);
    tbb::parallel_for(0, blocks_y, [&](int by) {
      uint16_t* blocks = distance_.data() + BlockIndex(0, by);
      for (int y = by * kBlock; y < std::min(height_, (by + 1) * kBlock); ++y) {
        const SampleKind* kind = blend_.kind.data() + Index(0, y);
        for (int x = 0; x < width_; ++x) {
          if (kind[x] != SampleKind::kNone) blocks[x / kBlock] = 0;
        }
      }
    });
    const auto at = [&](int bx, int by) -> uint32_t {
      const bool inside = bx >= 0 && by >= 0 && bx < blocks_x_ && by < blocks_y;
      return inside ? distance_[BlockIndex(bx, by)] : kFar;
    };
    // One more than the nearest of four neighbours: forward from those above and to the
    // left (s = 1), then back from those below and to the right (s = -1).
    const auto relax = [&](int bx, int by, int s) {
      uint16_t& d = distance_[BlockIndex(bx, by)];
      const uint32_t nearest =
          std::min({at(bx - s, by), at(bx - s, by - s), at(bx, by - s), at(bx + s, by - s)});
      d = static_cast<uint16_t>(std::min<uint32_t>(d, std::min(kFar, nearest + 1)));
    };
    for (int by = 0; by < blocks_y; ++by) {
      for (int bx = 0; bx < blocks_x_; ++bx) relax(bx, by, 1);
    }
    for (int by = blocks_y - 1; by >= 0; --by) {
      for (int bx = blocks_x_ - 1; bx >= 0; --bx) relax(bx, by, -1);
    }
  }

  static constexpr int kBlock = 4;

  BlendResult& blend_;
  const SkyModel& sky_;
  int width_;
  int height_;
  int count_;
  float tolerance_;
  int hole_sky_directions_;
  int max_steps_ = 0;
  std::vector<Step> steps_;
  std::vector<int> step_counts_;
  int blocks_x_ = 0;
  std::vector<uint16_t> distance_;
};

}  // namespace

int FillDepthAware(const ClassMap& classes, const Pinhole& camera, const FillOptions& options,
                   BlendResult* blend) {
  const SkyModel sky(*blend, camera);
  DepthAwareFiller filler(options, sky, blend);
  std::vector<int> filled_per_row(static_cast<size_t>(classes.height), 0);
  tbb::parallel_for(0, classes.height, [&](int y) {
    filled_per_row[static_cast<size_t>(y)] = filler.FillRow(classes, options, y);
  });
  int filled = 0;
  for (int n : filled_per_row) filled += n;
  return filled;
}

}  // namespace parallax
