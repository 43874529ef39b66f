#include "mvs/patch_match.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/hash.h"
#include "core/check.h"
#include "mvs/stereo_pyramid.h"

namespace parallax {
namespace {

constexpr float kInvalidCost = 2.0f;
constexpr int kMaxSources = 16;

// Deterministic per-pixel randomness: the same numbers whatever the thread schedule.
float Random(uint32_t seed, int x, int y, int iteration, int salt) {
  uint64_t h = seed * 0x9E3779B97F4A7C15ull;
  h ^= (static_cast<uint64_t>(x) << 32 | static_cast<uint32_t>(y)) * 0xC2B2AE3D27D4EB4Full;
  h ^= (static_cast<uint64_t>(iteration) << 8 | static_cast<uint64_t>(salt)) * 0x165667B19E3779F9ull;
  return UnitFloat(MixBits(h));
}

Eigen::Matrix3d Intrinsics(const Camera& camera) {
  Eigen::Matrix3d k;
  k << camera.FocalX(), 0, camera.PrincipalX(), 0, camera.FocalY(), camera.PrincipalY(), 0, 0, 1;
  return k;
}

void CheckPinhole(const Camera& camera, const GrayImage& image) {
  if (camera.model != CameraModel::kPinhole && camera.model != CameraModel::kSimplePinhole) {
    throw InternalError("PatchMatchStereo needs undistorted PINHOLE cameras, got " +
                        std::string(CameraModelName(camera.model)));
  }
  if (static_cast<uint64_t>(image.width) != camera.width ||
      static_cast<uint64_t>(image.height) != camera.height ||
      image.values.size() != static_cast<size_t>(image.width) * image.height) {
    throw InternalError("PatchMatchStereo: image size does not match its camera");
  }
}

float Bilinear(const GrayImage& image, float u, float v) {
  const int x0 = static_cast<int>(u), y0 = static_cast<int>(v);
  const float ax = u - static_cast<float>(x0), ay = v - static_cast<float>(y0);
  const float* row0 = image.values.data() + static_cast<size_t>(y0) * image.width + x0;
  const float* row1 = row0 + image.width;
  return (1 - ay) * ((1 - ax) * row0[0] + ax * row0[1]) + ay * ((1 - ax) * row1[0] + ax * row1[1]);
}

// The window's samples come in blocks of this many: the AVX2 cost takes eight at a time.
constexpr int kSampleBlock = 8;

// The sampling pattern of the matching window and its spatial weights, padded to whole
// blocks with copies of the first sample of weight 0 (inside the source exactly when it is).
struct WindowPattern {
  std::vector<float> dx, dy, spatial_weight;
  explicit WindowPattern(const PatchMatchOptions& options) {
    for (int y = -options.window_radius; y <= options.window_radius; y += options.window_step) {
      for (int x = -options.window_radius; x <= options.window_radius; x += options.window_step) {
        dx.push_back(static_cast<float>(x));
        dy.push_back(static_cast<float>(y));
        const float r2 = static_cast<float>(x * x + y * y);
        spatial_weight.push_back(
            std::exp(-r2 / (2 * options.sigma_spatial_px * options.sigma_spatial_px)));
      }
    }
    while (dx.size() % kSampleBlock != 0) {
      dx.push_back(dx[0]);
      dy.push_back(dy[0]);
      spatial_weight.push_back(0);
    }
  }
  int Size() const { return static_cast<int>(dx.size()); }
};

// The reference side of the NCC, computed once per pixel: normalised bilateral weights w,
// w * I, and the weighted mean and standard deviation of I.
struct ReferenceWindow {
  const float* weights;
  const float* weighted_values;
  float mean;
  float stddev;
};

class ReferenceWindows {
 public:
  ReferenceWindows(const GrayImage& image, const WindowPattern& pattern,
                   const PatchMatchOptions& options)
      : samples_(pattern.Size()), width_(image.width) {
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    weights_.resize(pixels * samples_);
    weighted_values_.resize(pixels * samples_);
    mean_.resize(pixels);
    stddev_.resize(pixels);
    tbb::parallel_for(0, image.height, [&](int y) {
      for (int x = 0; x < image.width; ++x) Compute(image, pattern, options, x, y);
    });
  }

  ReferenceWindow At(int x, int y) const {
    const size_t i = static_cast<size_t>(y) * width_ + x;
    return {&weights_[i * samples_], &weighted_values_[i * samples_], mean_[i], stddev_[i]};
  }

 private:
  void Compute(const GrayImage& image, const WindowPattern& pattern,
               const PatchMatchOptions& options, int x, int y) {
    const size_t i = static_cast<size_t>(y) * width_ + x;
    float* w = &weights_[i * samples_];
    float* wi = &weighted_values_[i * samples_];
    const float centre = image.At(x, y);
    float sum = 0;
    for (int k = 0; k < samples_; ++k) {
      // Samples outside the image are clamped to the border: the source sampling decides.
      const int sx = std::clamp(x + static_cast<int>(pattern.dx[k]), 0, image.width - 1);
      const int sy = std::clamp(y + static_cast<int>(pattern.dy[k]), 0, image.height - 1);
      const float value = image.At(sx, sy);
      const float difference = value - centre;
      w[k] = pattern.spatial_weight[k] *
             std::exp(-difference * difference / (2 * options.sigma_color * options.sigma_color));
      wi[k] = value;
      sum += w[k];
    }
    float mean = 0, mean_square = 0;
    for (int k = 0; k < samples_; ++k) {
      w[k] /= sum;
      mean += w[k] * wi[k];
      mean_square += w[k] * wi[k] * wi[k];
      wi[k] *= w[k];
    }
    mean_[i] = mean;
    stddev_[i] = std::sqrt(std::max(0.0f, mean_square - mean * mean));
  }

  int samples_;
  int width_;
  std::vector<float> weights_, weighted_values_, mean_, stddev_;
};

// Source-side constants: H(plane) = A + b m^T with m = K_r^-T n / rho.
struct SourceProjection {
  const GrayImage* image;
  Eigen::Matrix3f a;
  Eigen::Vector3f b;
  float max_u, max_v;  // Bilinear lookups need u < width - 1 after the -0.5 shift.
};

// 1 - NCC from the weighted sums over the window of J, J^2 and I J (weights summing to 1).
float CostFromSums(float sum_j, float sum_jj, float sum_ij, const ReferenceWindow& reference,
                   float min_std) {
  const float variance = sum_jj - sum_j * sum_j;
  if (!(variance > min_std * min_std)) return kInvalidCost;
  const float ncc = (sum_ij - reference.mean * sum_j) / (reference.stddev * std::sqrt(variance));
  return 1 - std::clamp(ncc, -1.0f, 1.0f);
}

// 1 - NCC of one source for a homography, given the reference window: one sample at a time.
float SourceCostPortable(const SourceProjection& source, const Eigen::Matrix3f& h, float px,
                         float py, const ReferenceWindow& reference, const WindowPattern& pattern,
                         float min_std) {
  const Eigen::Vector3f h0 = h * Eigen::Vector3f(px, py, 1);
  const Eigen::Vector3f hx = h.col(0), hy = h.col(1);
  float sum_j = 0, sum_jj = 0, sum_ij = 0;
  const int samples = pattern.Size();
  for (int k = 0; k < samples; ++k) {
    const Eigen::Vector3f p = h0 + pattern.dx[k] * hx + pattern.dy[k] * hy;
    if (!(p.z() > 1e-6f)) return kInvalidCost;
    const float u = p.x() / p.z() - 0.5f, v = p.y() / p.z() - 0.5f;
    if (!(u >= 0 && v >= 0 && u < source.max_u && v < source.max_v)) return kInvalidCost;
    const float j = Bilinear(*source.image, u, v);
    sum_j += reference.weights[k] * j;
    sum_jj += reference.weights[k] * j * j;
    sum_ij += reference.weighted_values[k] * j;
  }
  return CostFromSums(sum_j, sum_jj, sum_ij, reference, min_std);
}

#if defined(__AVX2__) && defined(__FMA__)
// The sum of the eight lanes.
float HorizontalSum(__m256 v) {
  const __m128 four = _mm_add_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1));
  const __m128 two = _mm_add_ps(four, _mm_movehl_ps(four, four));
  return _mm_cvtss_f32(_mm_add_ss(two, _mm_movehdup_ps(two)));
}

// For eight offsets into `values`, the float at each and the one after it: lane k of `left` is
// values[offsets[k]], of `right` values[offsets[k] + 1]. Eight 8-byte loads and two shuffles,
// faster than two gathers on AMD's Zen 3; inlined, or the call spills every vector.
[[gnu::always_inline]] inline void LoadPairs(const float* values, const int32_t* offsets,
                                             __m256* left, __m256* right) {
  const auto two_pairs = [&](int a, int b) {  // [a, a + 1, b, b + 1]
    const __m128 low = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(values + offsets[a])));
    return _mm_loadh_pi(low, reinterpret_cast<const __m64*>(values + offsets[b]));
  };
  // Lanes 0-3 from samples 0-3, lanes 4-7 from samples 4-7: _mm256_shuffle_ps stays within them.
  const __m256 even = _mm256_set_m128(two_pairs(4, 5), two_pairs(0, 1));
  const __m256 odd = _mm256_set_m128(two_pairs(6, 7), two_pairs(2, 3));
  *left = _mm256_shuffle_ps(even, odd, _MM_SHUFFLE(2, 0, 2, 0));
  *right = _mm256_shuffle_ps(even, odd, _MM_SHUFFLE(3, 1, 3, 1));
}

// SourceCostPortable eight samples at a time (a block of the pattern); the same arithmetic,
// rounded in another order.
float SourceCostAvx2(const SourceProjection& source, const Eigen::Matrix3f& h, float px, float py,
                     const ReferenceWindow& reference, const WindowPattern& pattern,
                     float min_std) {
  const Eigen::Vector3f h0 = h * Eigen::Vector3f(px, py, 1);
  // Row r of the projection of sample (dx, dy): h0[r] + dx h(r, 0) + dy h(r, 1).
  const auto project = [&](int r, __m256 dx, __m256 dy) {
    return _mm256_fmadd_ps(dy, _mm256_set1_ps(h(r, 1)),
                           _mm256_fmadd_ps(dx, _mm256_set1_ps(h(r, 0)), _mm256_set1_ps(h0[r])));
  };
  const float* values = source.image->values.data();
  const int width = source.image->width;
  const __m256 half = _mm256_set1_ps(0.5f), zero = _mm256_setzero_ps();
  __m256 sum_j = zero, sum_jj = zero, sum_ij = zero;
  for (int k = 0; k < pattern.Size(); k += kSampleBlock) {
    const __m256 dx = _mm256_loadu_ps(&pattern.dx[k]), dy = _mm256_loadu_ps(&pattern.dy[k]);
    const __m256 z = project(2, dx, dy);
    if (_mm256_movemask_ps(_mm256_cmp_ps(z, _mm256_set1_ps(1e-6f), _CMP_GT_OQ)) != 0xff) {
      return kInvalidCost;
    }
    const __m256 u = _mm256_sub_ps(_mm256_div_ps(project(0, dx, dy), z), half);
    const __m256 v = _mm256_sub_ps(_mm256_div_ps(project(1, dx, dy), z), half);
    const __m256 inside = _mm256_and_ps(
        _mm256_and_ps(_mm256_cmp_ps(u, zero, _CMP_GE_OQ), _mm256_cmp_ps(v, zero, _CMP_GE_OQ)),
        _mm256_and_ps(_mm256_cmp_ps(u, _mm256_set1_ps(source.max_u), _CMP_LT_OQ),
                      _mm256_cmp_ps(v, _mm256_set1_ps(source.max_v), _CMP_LT_OQ)));
    if (_mm256_movemask_ps(inside) != 0xff) return kInvalidCost;
    const __m256i x0 = _mm256_cvttps_epi32(u), y0 = _mm256_cvttps_epi32(v);  // u, v >= 0.
    const __m256 ax = _mm256_sub_ps(u, _mm256_cvtepi32_ps(x0));
    const __m256 ay = _mm256_sub_ps(v, _mm256_cvtepi32_ps(y0));
    alignas(32) int32_t offsets[kSampleBlock];  // Of the top-left corners of the lookups.
    _mm256_store_si256(reinterpret_cast<__m256i*>(offsets),
                       _mm256_add_epi32(_mm256_mullo_epi32(y0, _mm256_set1_epi32(width)), x0));
    __m256 j00, j01, j10, j11;
    LoadPairs(values, offsets, &j00, &j01);
    LoadPairs(values + width, offsets, &j10, &j11);
    const __m256 top = _mm256_fmadd_ps(ax, _mm256_sub_ps(j01, j00), j00);
    const __m256 bottom = _mm256_fmadd_ps(ax, _mm256_sub_ps(j11, j10), j10);
    const __m256 j = _mm256_fmadd_ps(ay, _mm256_sub_ps(bottom, top), top);
    const __m256 weighted_j = _mm256_mul_ps(_mm256_loadu_ps(&reference.weights[k]), j);
    sum_j = _mm256_add_ps(sum_j, weighted_j);
    sum_jj = _mm256_fmadd_ps(weighted_j, j, sum_jj);
    sum_ij = _mm256_fmadd_ps(_mm256_loadu_ps(&reference.weighted_values[k]), j, sum_ij);
  }
  return CostFromSums(HorizontalSum(sum_j), HorizontalSum(sum_jj), HorizontalSum(sum_ij),
                      reference, min_std);
}
#endif

float SourceCost(const SourceProjection& source, const Eigen::Matrix3f& h, float px, float py,
                 const ReferenceWindow& reference, const WindowPattern& pattern, float min_std,
                 [[maybe_unused]] CostKernel kernel = CostKernel::kFastest) {
#if defined(__AVX2__) && defined(__FMA__)
  if (kernel == CostKernel::kFastest) {
    return SourceCostAvx2(source, h, px, py, reference, pattern, min_std);
  }
#endif
  return SourceCostPortable(source, h, px, py, reference, pattern, min_std);
}

class PatchMatcher {
 public:
  // `initial` (may be null) proposes a plane per pixel, e.g. from a coarser pyramid level;
  // pixels without one (depth 0) start from a random plane.
  PatchMatcher(const StereoView& reference, const std::vector<const StereoView*>& sources,
               const PatchMatchOptions& options, const DepthNormalMap* initial)
      : initial_(initial),
        options_(options),
        pattern_(options),
        windows_(reference.image, pattern_, options),
        width_(reference.image.width),
        height_(reference.image.height),
        inverse_min_(static_cast<float>(1 / options.max_depth)),
        inverse_max_(static_cast<float>(1 / options.min_depth)),
        min_cos_normal_(static_cast<float>(std::cos(options.max_normal_angle_deg * std::numbers::pi / 180))),
        best_views_(std::min(options.best_views, static_cast<int>(sources.size()))) {
    const Eigen::Matrix3d k_ref = Intrinsics(reference.camera);
    k_ref_inverse_ = k_ref.inverse().cast<float>();
    for (const StereoView* source : sources) {
      const Rigid3d source_from_ref = RelativePose(reference.cam_from_world, source->cam_from_world);
      const Eigen::Matrix3d k_source = Intrinsics(source->camera);
      sources_.push_back(
          {&source->image,
           (k_source * source_from_ref.rotation.toRotationMatrix() * k_ref.inverse()).cast<float>(),
           (k_source * source_from_ref.translation).cast<float>(),
           static_cast<float>(source->image.width - 1), static_cast<float>(source->image.height - 1)});
    }
    const size_t pixels = static_cast<size_t>(width_) * height_;
    result_.depth = DepthMap(width_, height_);
    result_.normal.assign(pixels * 3, 0.0f);
    result_.cost.assign(pixels, kInvalidCost);
  }

  DepthNormalMap Run() {
    ForEachPixel(-1, [&](int x, int y) { Initialise(x, y); });
    for (int iteration = 0; iteration < options_.iterations; ++iteration) {
      for (int color = 0; color < 2; ++color) {
        ForEachPixel(color, [&](int x, int y) { Improve(x, y, iteration); });
      }
    }
    // Keep only confident depths.
    for (size_t i = 0; i < result_.cost.size(); ++i) {
      if (result_.cost[i] > options_.max_cost) {
        result_.depth.Values()[i] = 0;
        std::fill_n(&result_.normal[3 * i], 3, 0.0f);
      }
    }
    return std::move(result_);
  }

 private:
  struct Plane {
    float depth;
    Eigen::Vector3f normal;
  };

  // Calls f(x, y) on every pixel of one checkerboard color (-1: all), rows in parallel.
  template <typename F>
  void ForEachPixel(int color, const F& f) {
    tbb::parallel_for(tbb::blocked_range<int>(0, height_, 4), [&](const tbb::blocked_range<int>& rows) {
      for (int y = rows.begin(); y != rows.end(); ++y) {
        const int start = color < 0 ? 0 : (y + color) % 2;
        const int step = color < 0 ? 1 : 2;
        for (int x = start; x < width_; x += step) f(x, y);
      }
    });
  }

  Eigen::Vector3f Ray(int x, int y) const {
    return k_ref_inverse_ * Eigen::Vector3f(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, 1);
  }

  size_t Index(int x, int y) const { return static_cast<size_t>(y) * width_ + x; }

  bool Textured(int x, int y) const {
    return windows_.At(x, y).stddev >= options_.min_texture_std;
  }

  float Cost(int x, int y, const Plane& plane) const {
    const Eigen::Vector3f ray = Ray(x, y);
    const float n_dot_ray = plane.normal.dot(ray);
    const float rho = plane.depth * n_dot_ray;
    const Eigen::Vector3f m = k_ref_inverse_.transpose() * plane.normal / rho;
    const ReferenceWindow window = windows_.At(x, y);
    std::array<float, kMaxSources> costs;
    const int n = static_cast<int>(sources_.size());
    for (int s = 0; s < n; ++s) {
      const Eigen::Matrix3f h = sources_[s].a + sources_[s].b * m.transpose();
      costs[s] = SourceCost(sources_[s], h, static_cast<float>(x) + 0.5f,
                            static_cast<float>(y) + 0.5f, window, pattern_,
                            options_.min_texture_std);
    }
    // Occlusion-aware: only the best views count.
    std::partial_sort(costs.begin(), costs.begin() + best_views_, costs.begin() + n);
    float sum = 0;
    for (int s = 0; s < best_views_; ++s) sum += costs[s];
    return sum / static_cast<float>(best_views_);
  }

  Eigen::Vector3f RandomNormal(int x, int y, int iteration, int salt) const {
    const Eigen::Vector3f view = -Ray(x, y).normalized();
    for (int attempt = 0; attempt < 8; ++attempt) {
      // Uniform direction on the sphere, flipped towards the camera.
      const float z = 2 * Random(options_.seed, x, y, iteration, salt + 2 * attempt) - 1;
      const float phi = 2 * std::numbers::pi_v<float> * Random(options_.seed, x, y, iteration, salt + 2 * attempt + 1);
      const float r = std::sqrt(std::max(0.0f, 1 - z * z));
      Eigen::Vector3f normal(r * std::cos(phi), r * std::sin(phi), z);
      if (normal.dot(view) < 0) normal = -normal;
      if (normal.dot(view) >= min_cos_normal_) return normal;
    }
    return view;
  }

  float RandomDepth(int x, int y, int iteration, int salt) const {
    const float inverse = inverse_min_ + Random(options_.seed, x, y, iteration, salt) * (inverse_max_ - inverse_min_);
    return 1 / inverse;
  }

  bool Acceptable(int x, int y, const Plane& plane) const {
    if (!(plane.depth >= 1 / inverse_max_ && plane.depth <= 1 / inverse_min_)) return false;
    return plane.normal.dot(-Ray(x, y).normalized()) >= min_cos_normal_;
  }

  void Store(int x, int y, const Plane& plane, float cost) {
    const size_t i = Index(x, y);
    result_.depth.Values()[i] = plane.depth;
    std::copy_n(plane.normal.data(), 3, &result_.normal[3 * i]);
    result_.cost[i] = cost;
  }

  Plane StoredPlane(int x, int y) const {
    const size_t i = Index(x, y);
    return {result_.depth.Values()[i], Eigen::Vector3f(&result_.normal[3 * i])};
  }

  void Initialise(int x, int y) {
    if (!Textured(x, y)) return;  // Stays at depth 0, cost 2.
    if (initial_ && initial_->depth.At(x, y) > 0) {
      const size_t i = Index(x, y);
      const Plane proposed{initial_->depth.At(x, y), Eigen::Vector3f(&initial_->normal[3 * i])};
      if (Acceptable(x, y, proposed)) {
        Store(x, y, proposed, Cost(x, y, proposed));
        return;
      }
    }
    const Plane random{RandomDepth(x, y, -1, 0), RandomNormal(x, y, -1, 1)};
    Store(x, y, random, Cost(x, y, random));
  }

  void Improve(int x, int y, int iteration) {
    if (!Textured(x, y)) return;
    Plane best = StoredPlane(x, y);
    float best_cost = result_.cost[Index(x, y)];
    auto consider = [&](const Plane& candidate) {
      // Converged neighbourhoods propose the plane this pixel already has: skip the rescoring.
      if (std::abs(candidate.depth - best.depth) <= 1e-6f * best.depth &&
          candidate.normal.dot(best.normal) >= 1 - 1e-7f) {
        return;
      }
      if (!Acceptable(x, y, candidate)) return;
      const float cost = Cost(x, y, candidate);
      if (cost < best_cost) {
        best_cost = cost;
        best = candidate;
      }
    };
    // Propagation: in each direction, the plane of the neighbour of the other color (an odd
    // number of pixels away, up to the reach) that fits its own pixel best, extended to this
    // one. One candidate a direction, the most promising of several, as ACMH (Xu and Tao,
    // CVPR 2019) chooses its own.
    const std::array<std::pair<int, int>, 4> directions = {{{-1, 0}, {1, 0}, {0, -1}, {0, 1}}};
    const Eigen::Vector3f ray = Ray(x, y);
    for (const auto& [dx, dy] : directions) {
      int chosen_x = -1, chosen_y = -1;
      float chosen_cost = 0;
      for (int step = 1; step <= options_.propagation_reach; step += 2) {
        const int nx = x + step * dx, ny = y + step * dy;
        if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) break;
        const size_t i = Index(nx, ny);
        if (result_.depth.Values()[i] > 0 && (chosen_x < 0 || result_.cost[i] < chosen_cost)) {
          chosen_x = nx;
          chosen_y = ny;
          chosen_cost = result_.cost[i];
        }
      }
      if (chosen_x < 0) continue;
      const Plane neighbour = StoredPlane(chosen_x, chosen_y);
      const float rho = neighbour.depth * neighbour.normal.dot(Ray(chosen_x, chosen_y));
      consider({rho / neighbour.normal.dot(ray), neighbour.normal});
    }
    // Random refinement, narrowing with each iteration; plus one fresh random guess.
    const float amplitude = std::ldexp(1.0f, -(iteration + 1));  // 2^-(iteration + 1), exactly.
    const float inverse = 1 / best.depth + (Random(options_.seed, x, y, iteration, 20) - 0.5f) *
                                               amplitude * (inverse_max_ - inverse_min_);
    if (inverse > 0) consider({1 / inverse, best.normal});
    const Eigen::Vector3f tilted =
        (best.normal + amplitude * RandomNormal(x, y, iteration, 30)).normalized();
    consider({best.depth, tilted});
    // A fresh random plane helps where nothing good has arrived yet; below the coarsest
    // level the pyramid has already proposed one, and this is wasted work.
    if (!initial_) consider({RandomDepth(x, y, iteration, 40), RandomNormal(x, y, iteration, 50)});
    Store(x, y, best, best_cost);
  }

  const DepthNormalMap* initial_;
  const PatchMatchOptions& options_;
  WindowPattern pattern_;
  ReferenceWindows windows_;
  int width_, height_;
  float inverse_min_, inverse_max_;
  float min_cos_normal_;
  int best_views_;
  Eigen::Matrix3f k_ref_inverse_;
  std::vector<SourceProjection> sources_;
  DepthNormalMap result_;
};

// Coarse to fine: the coarser levels find the surfaces cheaply and over long distances, the
// finer ones refine them.
DepthNormalMap PatchMatchLevel(const StereoView& reference,
                               const std::vector<const StereoView*>& sources,
                               const PatchMatchOptions& options, int levels) {
  std::optional<DepthNormalMap> initial;
  const int min_size = 4 * options.window_radius + 8;
  if (levels > 1 && reference.image.width / 2 >= min_size && reference.image.height / 2 >= min_size) {
    const StereoView coarse_reference = HalfResolution(reference);
    std::vector<StereoView> coarse_sources;
    coarse_sources.reserve(sources.size());
    for (const StereoView* source : sources) coarse_sources.push_back(HalfResolution(*source));
    std::vector<const StereoView*> coarse_pointers;
    for (const StereoView& source : coarse_sources) coarse_pointers.push_back(&source);
    PatchMatchOptions coarse_options = options;
    coarse_options.max_cost = 2;  // Keep every plane as a proposal; this level scores them.
    const DepthNormalMap coarse =
        PatchMatchLevel(coarse_reference, coarse_pointers, coarse_options, levels - 1);
    initial = UpsamplePlanes(coarse, coarse_reference.camera, reference.camera, kInvalidCost);
  }
  return PatchMatcher(reference, sources, options, initial ? &*initial : nullptr).Run();
}

}  // namespace

void PatchMatchOptions::Check() const {
  RequireOption(window_radius >= 1 && window_radius <= 15, "PatchMatchOptions.window_radius", window_radius, "[1, 15]");
  RequireOption(window_step >= 1 && window_step <= window_radius, "PatchMatchOptions.window_step", window_step,
                "[1, window_radius]");
  RequireOption(iterations >= 0, "PatchMatchOptions.iterations", iterations, ">= 0");
  RequireOption(pyramid_levels >= 1 && pyramid_levels <= 6, "PatchMatchOptions.pyramid_levels", pyramid_levels, "[1, 6]");
  RequireOption(propagation_reach >= 1 && propagation_reach % 2 == 1, "PatchMatchOptions.propagation_reach",
                propagation_reach, "odd and >= 1 (red-black propagation)");
  RequireOption(sigma_color > 0, "PatchMatchOptions.sigma_color", sigma_color, "> 0");
  RequireOption(sigma_spatial_px > 0, "PatchMatchOptions.sigma_spatial_px", sigma_spatial_px, "> 0");
  RequireOption(best_views >= 1, "PatchMatchOptions.best_views", best_views, ">= 1");
  RequireOption(min_texture_std > 0, "PatchMatchOptions.min_texture_std", min_texture_std, "> 0");
  RequireOption(max_cost > 0 && max_cost <= 2, "PatchMatchOptions.max_cost", max_cost, "(0, 2]");
  RequireOption(min_depth > 0, "PatchMatchOptions.min_depth", min_depth, "> 0");
  RequireOption(max_depth > min_depth && std::isfinite(max_depth), "PatchMatchOptions.max_depth", max_depth,
                "finite and > min_depth");
  RequireOption(max_normal_angle_deg > 0 && max_normal_angle_deg < 90, "PatchMatchOptions.max_normal_angle_deg",
                max_normal_angle_deg, "(0, 90)");
}

Eigen::Matrix3d PlaneHomography(const Camera& reference, const Camera& source,
                                const Rigid3d& source_from_reference, const Eigen::Vector3d& normal,
                                double rho) {
  const Eigen::Matrix3d k_ref = Intrinsics(reference);
  return Intrinsics(source) *
         (source_from_reference.rotation.toRotationMatrix() +
          source_from_reference.translation * normal.transpose() / rho) *
         k_ref.inverse();
}

float WindowCost(const GrayImage& reference, int x, int y, const GrayImage& source,
                 const Eigen::Matrix3d& homography, const PatchMatchOptions& options,
                 CostKernel kernel) {
  const WindowPattern pattern(options);
  const ReferenceWindows windows(reference, pattern, options);
  const ReferenceWindow window = windows.At(x, y);
  if (window.stddev < options.min_texture_std) return kInvalidCost;
  const SourceProjection projection{&source, {}, {}, static_cast<float>(source.width - 1),
                                    static_cast<float>(source.height - 1)};
  return SourceCost(projection, homography.cast<float>(), static_cast<float>(x) + 0.5f,
                    static_cast<float>(y) + 0.5f, window, pattern, options.min_texture_std, kernel);
}

double InverseDepthSample(double min_depth, double max_depth, double fraction) {
  return 1 / (1 / max_depth + fraction * (1 / min_depth - 1 / max_depth));
}

DepthNormalMap PatchMatchStereo(const StereoView& reference,
                                const std::vector<const StereoView*>& sources,
                                const PatchMatchOptions& options) {
  options.Check();
  if (sources.empty() || sources.size() > kMaxSources) {
    throw InternalError("PatchMatchStereo needs 1 to 16 source views, got " +
                        std::to_string(sources.size()));
  }
  CheckPinhole(reference.camera, reference.image);
  for (const StereoView* source : sources) CheckPinhole(source->camera, source->image);
  return PatchMatchLevel(reference, sources, options, options.pyramid_levels);
}

}  // namespace parallax
