#include "reproject/forward_warp.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "reproject/background.h"

namespace parallax {
namespace {

constexpr double kPi = 3.14159265358979323846;

enum VertexKind : uint8_t { kInvalid = 0, kSurface = 1, kSky = 2 };

}  // namespace

// Every source pixel centre mapped into the target once; triangles and splats share it.
struct Vertices {
  std::unique_ptr<float[]> u;       // Target pixel coordinates.
  std::unique_ptr<float[]> v;
  std::unique_ptr<float[]> inv_z;   // 1 / target z; 0 for background.
  std::unique_ptr<float[]> angle;   // WarpWeight::ray_angle_rad.
  std::unique_ptr<uint8_t[]> kind;  // VertexKind.
  size_t capacity = 0;
};

struct WarpScratch::Data {
  Vertices vertices;
  std::vector<uint8_t> background;  // MarkBackground.
  std::vector<size_t> stack;        // MarkBackground's flood fill.
  std::vector<uint8_t> edge;        // Mesh: vertices to splat.
  std::vector<float> ray_x;         // Per source column: (x + 0.5 - cx) / fx.
};

namespace {

// Everything the per-pixel loops need, in the float form they use.
struct WarpSetup {
  Pinhole src;
  Pinhole dst;
  float r[3][3];  // target_from_source rotation.
  float t[3];     // target_from_source translation: the source centre in the target frame.
  float min_view_cos;
  float max_depth_ratio;  // Between samples of one surface (mesh and splat footprints).
};

bool Finite(float value) { return std::abs(value) <= std::numeric_limits<float>::max(); }

// floor and ceil for values >= -1 by truncation: std::floor is a library call without SSE4.1,
// and these run several times per triangle.
int FloorClamped(float value) { return static_cast<int>(value + 1.0f) - 1; }
int CeilClamped(float value) {
  const int floor = FloorClamped(value);
  return static_cast<float>(floor) < value ? floor + 1 : floor;
}

WarpSetup MakeSetup(const SourceView& source, const PosedCamera& target,
                    const ForwardWarpOptions& options) {
  WarpSetup setup;
  setup.src = Pinhole::From(source.camera);
  setup.dst = Pinhole::From(target.camera);
  const Rigid3d target_from_source = RelativePose(source.cam_from_world, target.cam_from_world);
  const Eigen::Matrix3d rotation = target_from_source.rotation.toRotationMatrix();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) setup.r[i][j] = static_cast<float>(rotation(i, j));
    setup.t[i] = static_cast<float>(target_from_source.translation(i));
  }
  setup.min_view_cos = static_cast<float>(options.min_view_cos);
  const double slope = std::tan(options.max_slant_deg * kPi / 180.0);
  setup.max_depth_ratio = static_cast<float>(
      1.0 + slope * std::sqrt(2.0) / std::min(setup.src.fx, setup.src.fy));
  return setup;
}

// Maps one source row into the target. Surfaces are lifted at their depth; background pixels
// are rotated only (a direction has no position, so the baseline does not move it).
void ProjectRow(const WarpSetup& s, const SourceView& source,
                const std::vector<uint8_t>& background, const std::vector<float>& ray_x, int y,
                Vertices* out) {
  const int width = s.src.width;
  const float ray_y = static_cast<float>((y + 0.5 - s.src.cy) / s.src.fy);
  // Rotated source ray (x, y, 1) = ray_x * column 0 + base.
  const float base[3] = {ray_y * s.r[0][1] + s.r[0][2], ray_y * s.r[1][1] + s.r[1][2],
                         ray_y * s.r[2][1] + s.r[2][2]};
  const float fx = static_cast<float>(s.dst.fx), fy = static_cast<float>(s.dst.fy);
  const float cx = static_cast<float>(s.dst.cx), cy = static_cast<float>(s.dst.cy);
  const size_t row = static_cast<size_t>(y) * static_cast<size_t>(width);
  for (int x = 0; x < width; ++x) {
    const size_t i = row + static_cast<size_t>(x);
    const float dir[3] = {ray_x[static_cast<size_t>(x)] * s.r[0][0] + base[0],
                          ray_x[static_cast<size_t>(x)] * s.r[1][0] + base[1],
                          ray_x[static_cast<size_t>(x)] * s.r[2][0] + base[2]};
    const float depth = source.depth.At(x, y);
    out->kind[i] = kInvalid;
    float p[3];
    float angle = 0;
    uint8_t kind = kInvalid;
    if (depth > 0 && Finite(depth)) {
      for (int k = 0; k < 3; ++k) p[k] = depth * dir[k] + s.t[k];
      const float norm_p = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      const float norm_dir = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
      if (!(p[2] > s.min_view_cos * norm_p) || !Finite(norm_p)) continue;
      // Chord between the unit rays from the target centre (p) and the source centre (dir).
      float chord2 = 0;
      for (int k = 0; k < 3; ++k) {
        const float diff = p[k] / norm_p - dir[k] / norm_dir;
        chord2 += diff * diff;
      }
      angle = std::sqrt(chord2);
      kind = kSurface;
    } else if (depth == 0 && !background.empty() && background[i] != 0) {
      for (int k = 0; k < 3; ++k) p[k] = dir[k];
      const float norm_p = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
      if (!(p[2] > s.min_view_cos * norm_p)) continue;
      kind = kSky;
    } else {
      continue;
    }
    const float inv_z = 1.0f / p[2];
    const float u = fx * p[0] * inv_z + cx;
    const float v = fy * p[1] * inv_z + cy;
    if (!Finite(u) || !Finite(v) || !Finite(inv_z)) continue;
    out->u[i] = u;
    out->v[i] = v;
    out->inv_z[i] = kind == kSurface ? inv_z : 0.0f;
    out->angle[i] = angle;
    out->kind[i] = kind;
  }
}

// A vertex as the rasteriser reads it.
struct Corner {
  float u, v, inv_z, angle;
  const float* rgb;
};

// Writes samples of one source into the target buffer (z-test: nearest surface wins;
// background only where nothing is).
class Rasterizer {
 public:
  Rasterizer(WarpBuffer* buffer, int32_t source_index)
      : width_(buffer->Width()),
        height_(buffer->Height()),
        depth_(buffer->MutableDepth()),
        color_(buffer->MutableColor()),
        weight_(buffer->MutableWeight()),
        source_(source_index) {}

  // Perspective-correct: inverse depth is affine in the image, attributes / z too.
  void SurfaceTriangle(const Corner& a, const Corner& b, const Corner& c) {
    Box box;
    float inv_area;
    if (!Setup(a, b, c, &box, &inv_area)) return;
    const float stretch = Stretch(inv_area);
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) ShadeSurface(a, b, c, x, y, inv_area, stretch);
    }
  }

  // Triangles (a, b, c) and (b, d, c) of one quad of a continuous surface. Most quads cover
  // zero or one pixel centre, so the bounding box is tested before any triangle setup, and a
  // centre inside the first triangle is not tested against the second.
  void SurfaceQuad(const Corner& a, const Corner& b, const Corner& c, const Corner& d) {
    Box box;
    if (!Clip(std::min(std::min(a.u, b.u), std::min(c.u, d.u)),
              std::max(std::max(a.u, b.u), std::max(c.u, d.u)),
              std::min(std::min(a.v, b.v), std::min(c.v, d.v)),
              std::max(std::max(a.v, b.v), std::max(c.v, d.v)), &box)) {
      return;
    }
    const float area_1 = Area2(a, b, c), area_2 = Area2(b, d, c);
    const bool valid_1 = std::abs(area_1) > kMinArea2, valid_2 = std::abs(area_2) > kMinArea2;
    const float inv_1 = valid_1 ? 1.0f / area_1 : 0.0f, inv_2 = valid_2 ? 1.0f / area_2 : 0.0f;
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) {
        if (!(valid_1 && ShadeSurface(a, b, c, x, y, inv_1, std::abs(area_1))) && valid_2) {
          ShadeSurface(b, d, c, x, y, inv_2, std::abs(area_2));
        }
      }
    }
  }

  // Directions: screen-affine interpolation (no depth); never covers a surface.
  void BackgroundTriangle(const Corner& a, const Corner& b, const Corner& c) {
    Box box;
    float inv_area;
    if (!Setup(a, b, c, &box, &inv_area)) return;
    const float stretch = Stretch(inv_area);
    for (int y = box.y0; y <= box.y1; ++y) {
      const float pv = static_cast<float>(y) + 0.5f;
      for (int x = box.x0; x <= box.x1; ++x) {
        const float pu = static_cast<float>(x) + 0.5f;
        float w[3];
        if (!Barycentric(a, b, c, pu, pv, inv_area, w)) continue;
        const size_t i = Index(x, y);
        if (depth_[i] != 0) continue;
        Write(i, WarpBuffer::kBackground, w, a, b, c, stretch);
      }
    }
  }

  // A square footprint of half-size (half_u, half_v) pixels around the corner.
  void Splat(const Corner& a, float half_u, float half_v, float stretch, bool background) {
    Box box;
    if (!Clip(a.u - half_u, a.u + half_u, a.v - half_v, a.v + half_v, &box)) return;
    const float z = background ? WarpBuffer::kBackground : 1.0f / a.inv_z;
    if (!background && !Finite(z)) return;
    const float q[3] = {1, 0, 0};
    for (int y = box.y0; y <= box.y1; ++y) {
      for (int x = box.x0; x <= box.x1; ++x) {
        const size_t i = Index(x, y);
        if (background ? depth_[i] != 0 : (depth_[i] != 0 && !(z < depth_[i]))) continue;
        Write(i, z, q, a, a, a, stretch);
      }
    }
  }

 private:
  struct Box {
    int x0, x1, y0, y1;
  };

  // Twice the signed area of a triangle below which it is degenerate (pixels squared).
  static constexpr float kMinArea2 = 1e-12f;

  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  }

  // Source triangles have area 1/2, so the area ratio is twice the target area: |area2|.
  static float Stretch(float inv_area) { return std::abs(1.0f / inv_area); }

  static float Area2(const Corner& a, const Corner& b, const Corner& c) {
    return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
  }

  // Writes pixel (x, y) from the triangle when its centre lies inside and passes the z-test;
  // returns whether the centre lies inside.
  // `stretch` is the triangle's WarpWeight::stretch.
  bool ShadeSurface(const Corner& a, const Corner& b, const Corner& c, int x, int y,
                    float inv_area, float stretch) {
    float w[3];
    if (!Barycentric(a, b, c, static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f,
                     inv_area, w)) {
      return false;
    }
    const float inv_z = w[0] * a.inv_z + w[1] * b.inv_z + w[2] * c.inv_z;
    if (!(inv_z > 0)) return true;
    const float z = 1.0f / inv_z;
    const size_t i = Index(x, y);
    if ((depth_[i] != 0 && !(z < depth_[i])) || !Finite(z)) return true;
    const float q[3] = {w[0] * a.inv_z * z, w[1] * b.inv_z * z, w[2] * c.inv_z * z};
    Write(i, z, q, a, b, c, stretch);
    return true;
  }

  // Pixels whose centres lie in [u0, u1] x [v0, v1], clipped to the image. Coordinates are
  // clamped as floats before the integer conversion so far-off vertices cannot overflow it.
  bool Clip(float u0, float u1, float v0, float v1, Box* box) const {
    const float w = static_cast<float>(width_), h = static_cast<float>(height_);
    box->x0 = std::max(0, CeilClamped(std::clamp(u0 - 0.5f, -1.0f, w)));
    box->x1 = std::min(width_ - 1, FloorClamped(std::clamp(u1 - 0.5f, -1.0f, w)));
    box->y0 = std::max(0, CeilClamped(std::clamp(v0 - 0.5f, -1.0f, h)));
    box->y1 = std::min(height_ - 1, FloorClamped(std::clamp(v1 - 0.5f, -1.0f, h)));
    return box->x0 <= box->x1 && box->y0 <= box->y1;
  }

  bool Setup(const Corner& a, const Corner& b, const Corner& c, Box* box,
             float* inv_area) const {
    const float area2 = Area2(a, b, c);
    if (!(std::abs(area2) > kMinArea2) || !Finite(area2)) return false;
    if (!Clip(std::min({a.u, b.u, c.u}), std::max({a.u, b.u, c.u}),
              std::min({a.v, b.v, c.v}), std::max({a.v, b.v, c.v}), box)) {
      return false;
    }
    *inv_area = 1.0f / area2;
    return true;
  }

  // Barycentric weights of the pixel centre; false outside the triangle. Edges are inclusive
  // (with a hair of slack) so that no centre on a shared edge falls between two triangles.
  static bool Barycentric(const Corner& a, const Corner& b, const Corner& c, float pu, float pv,
                          float inv_area, float w[3]) {
    constexpr float kSlack = -1e-5f;
    w[0] = ((b.u - pu) * (c.v - pv) - (b.v - pv) * (c.u - pu)) * inv_area;
    w[1] = ((c.u - pu) * (a.v - pv) - (c.v - pv) * (a.u - pu)) * inv_area;
    w[2] = 1.0f - w[0] - w[1];
    return w[0] >= kSlack && w[1] >= kSlack && w[2] >= kSlack;
  }

  void Write(size_t i, float depth, const float q[3], const Corner& a, const Corner& b,
             const Corner& c, float stretch) {
    depth_[i] = depth;
    for (int k = 0; k < 3; ++k) color_[3 * i + k] = q[0] * a.rgb[k] + q[1] * b.rgb[k] + q[2] * c.rgb[k];
    weight_[i] = WarpWeight{source_, q[0] * a.angle + q[1] * b.angle + q[2] * c.angle, stretch};
  }

  int width_;
  int height_;
  float* depth_;
  float* color_;
  WarpWeight* weight_;
  int32_t source_;
};

class SourceWarper {
 public:
  SourceWarper(const SourceView& source, const WarpSetup& setup, const Vertices& vertices,
               const ForwardWarpOptions& options, Rasterizer* raster)
      : source_(source), s_(setup), vtx_(vertices), options_(options), raster_(raster),
        width_(setup.src.width), height_(setup.src.height) {}

    // Vertices next to a dropped triangle or on the source border are splatted afterwards:
  // the mesh stops at the last sample centre, half a pixel short of where the pixel ends.
  void Mesh(std::vector<uint8_t>* edge_scratch) {
    const size_t count = static_cast<size_t>(width_) * static_cast<size_t>(height_);
    std::vector<uint8_t>& edge = *edge_scratch;
    edge.assign(count, 0);
    for (int y = 0; y + 1 < height_; ++y) {
      for (int x = 0; x + 1 < width_; ++x) {
        const size_t i00 = Index(x, y), i10 = i00 + 1;
        const size_t i01 = i00 + static_cast<size_t>(width_), i11 = i01 + 1;
        if (!ContinuousQuad(i00, i10, i01, i11)) {
          Triangle(i00, i10, i01, &edge);
          Triangle(i10, i11, i01, &edge);
          continue;
        }
        raster_->SurfaceQuad(CornerAt(i00), CornerAt(i10), CornerAt(i01), CornerAt(i11));
      }
    }
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        const bool border = x == 0 || y == 0 || x + 1 == width_ || y + 1 == height_;
        if (border || edge[Index(x, y)] != 0) SplatVertex(x, y);
      }
    }
  }

  void Splats() {
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) SplatVertex(x, y);
    }
  }

 private:
  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  }
  float SourceDepth(size_t i) const { return source_.depth.Values()[i]; }

  Corner CornerAt(size_t i) const {
    return {vtx_.u[i], vtx_.v[i], vtx_.inv_z[i], vtx_.angle[i],
            source_.color.Pixels().data() + 3 * i};
  }

  // Two samples of one surface (or both background).
  bool Continuous(size_t i, size_t j) const {
    if (vtx_.kind[i] != vtx_.kind[j]) return false;
    if (vtx_.kind[i] == kSky) return true;
    const float a = SourceDepth(i), b = SourceDepth(j);
    return std::max(a, b) <= s_.max_depth_ratio * std::min(a, b);
  }

  // The common case: four samples of one surface.
  bool ContinuousQuad(size_t a, size_t b, size_t c, size_t d) const {
    if ((vtx_.kind[a] & vtx_.kind[b] & vtx_.kind[c] & vtx_.kind[d]) != kSurface) return false;
    const float da = SourceDepth(a), db = SourceDepth(b), dc = SourceDepth(c), dd = SourceDepth(d);
    return std::max(std::max(da, db), std::max(dc, dd)) <=
           s_.max_depth_ratio * std::min(std::min(da, db), std::min(dc, dd));
  }

  void Triangle(size_t a, size_t b, size_t c, std::vector<uint8_t>* edge) {
    const uint8_t ka = vtx_.kind[a], kb = vtx_.kind[b], kc = vtx_.kind[c];
    if (ka == kInvalid && kb == kInvalid && kc == kInvalid) return;
    if (ka == kb && kb == kc) {
      if (ka == kSky) {
        raster_->BackgroundTriangle(CornerAt(a), CornerAt(b), CornerAt(c));
        return;
      }
      const float da = SourceDepth(a), db = SourceDepth(b), dc = SourceDepth(c);
      if (std::max({da, db, dc}) <= s_.max_depth_ratio * std::min({da, db, dc})) {
        raster_->SurfaceTriangle(CornerAt(a), CornerAt(b), CornerAt(c));
        return;
      }
    }
    (*edge)[a] = (*edge)[b] = (*edge)[c] = 1;
  }

  // Local magnification from the neighbour in `step` direction (or the opposite one), as the
  // target-pixel offset of one source pixel; false when neither neighbour is on this surface.
  bool Derivative(int x, int y, int step_x, int step_y, float d[2]) const {
    const size_t i = Index(x, y);
    for (int sign : {1, -1}) {
      const int nx = x + sign * step_x, ny = y + sign * step_y;
      if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
      const size_t j = Index(nx, ny);
      if (!Continuous(i, j)) continue;
      d[0] = static_cast<float>(sign) * (vtx_.u[j] - vtx_.u[i]);
      d[1] = static_cast<float>(sign) * (vtx_.v[j] - vtx_.v[i]);
      return true;
    }
    return false;
  }

  void SplatVertex(int x, int y) {
    const size_t i = Index(x, y);
    if (vtx_.kind[i] == kInvalid) return;
    const bool background = vtx_.kind[i] == kSky;
    // Fallback without a neighbour: magnification of a fronto-parallel patch.
    const float depth_ratio = background ? 1.0f : SourceDepth(i) * vtx_.inv_z[i];
    float du[2] = {static_cast<float>(s_.dst.fx / s_.src.fx) * depth_ratio, 0};
    float dv[2] = {0, static_cast<float>(s_.dst.fy / s_.src.fy) * depth_ratio};
    Derivative(x, y, 1, 0, du);
    Derivative(x, y, 0, 1, dv);
    const float overlap = static_cast<float>(options_.splat_overlap);
    const float max_px = static_cast<float>(options_.max_splat_px);
    const float extent_u = std::clamp(overlap * (std::abs(du[0]) + std::abs(dv[0])), 1.0f, max_px);
    const float extent_v = std::clamp(overlap * (std::abs(du[1]) + std::abs(dv[1])), 1.0f, max_px);
    float stretch = std::abs(du[0] * dv[1] - du[1] * dv[0]);
    if (!Finite(stretch)) stretch = max_px * max_px;
    raster_->Splat(CornerAt(i), 0.5f * extent_u, 0.5f * extent_v, stretch, background);
  }

  const SourceView& source_;
  const WarpSetup& s_;
  const Vertices& vtx_;
  const ForwardWarpOptions& options_;
  Rasterizer* raster_;
  int width_;
  int height_;
};

template <typename T>
void Allocate(std::unique_ptr<T[]>* array, size_t count) {
  *array = std::make_unique_for_overwrite<T[]>(count);
}

}  // namespace

void ForwardWarpOptions::Check() const {
  const auto fail = [](const std::string& field, double value, const std::string& expected) {
    throw std::invalid_argument("ForwardWarpOptions." + field + " = " + std::to_string(value) +
                                ": expected " + expected);
  };
  if (!(max_slant_deg > 0 && max_slant_deg < 90)) fail("max_slant_deg", max_slant_deg, "(0, 90)");
  if (!(max_splat_px >= 1 && max_splat_px <= 64)) fail("max_splat_px", max_splat_px, "[1, 64]");
  if (!(splat_overlap >= 1 && splat_overlap <= 2)) fail("splat_overlap", splat_overlap, "[1, 2]");
  if (!(min_view_cos > 0 && min_view_cos < 1)) fail("min_view_cos", min_view_cos, "(0, 1)");
}

void WarpBuffer::Reset(int width, int height) {
  if (width < 0 || height < 0) {
    throw std::invalid_argument("WarpBuffer: negative size " + std::to_string(width) + "x" +
                                std::to_string(height));
  }
  width_ = width;
  height_ = height;
  const size_t count = Size();
  if (count > capacity_) {
    Allocate(&depth_, count);
    Allocate(&color_, 3 * count);
    Allocate(&weight_, count);
    capacity_ = count;
  }
  std::fill(depth_.get(), depth_.get() + count, 0.0f);
}

WarpScratch::WarpScratch() : data_(std::make_unique<Data>()) {}
WarpScratch::~WarpScratch() = default;
WarpScratch::WarpScratch(WarpScratch&&) noexcept = default;
WarpScratch& WarpScratch::operator=(WarpScratch&&) noexcept = default;

void ForwardWarp(const SourceView& source, int source_index, const PosedCamera& target,
                 const ForwardWarpOptions& options, WarpBuffer* buffer, WarpScratch* scratch) {
  options.Check();
  CheckSourceView(source);
  WarpScratch local;
  WarpScratch::Data& data = (scratch != nullptr ? scratch : &local)->Get();
  const WarpSetup setup = MakeSetup(source, target, options);
  buffer->Reset(setup.dst.width, setup.dst.height);

  const int width = setup.src.width, height = setup.src.height;
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (options.background_at_infinity) {
    MarkBackground(source.depth, &data.background, &data.stack);
  } else {
    data.background.clear();
  }
  data.ray_x.resize(static_cast<size_t>(width));
  for (int x = 0; x < width; ++x) {
    data.ray_x[static_cast<size_t>(x)] = static_cast<float>((x + 0.5 - setup.src.cx) / setup.src.fx);
  }
  Vertices& vertices = data.vertices;
  if (count > vertices.capacity) {
    Allocate(&vertices.u, count);
    Allocate(&vertices.v, count);
    Allocate(&vertices.inv_z, count);
    Allocate(&vertices.angle, count);
    Allocate(&vertices.kind, count);
    vertices.capacity = count;
  }
  tbb::parallel_for(tbb::blocked_range<int>(0, height, 16), [&](const tbb::blocked_range<int>& rows) {
    for (int y = rows.begin(); y < rows.end(); ++y) {
      ProjectRow(setup, source, data.background, data.ray_x, y, &vertices);
    }
  });

  // Rasterisation of one source is serial: triangles from anywhere in the source can land on
  // any target pixel. Sources run in parallel into their own buffers (see Render).
  Rasterizer raster(buffer, source_index);
  SourceWarper warper(source, setup, vertices, options, &raster);
  if (options.method == WarpMethod::kMesh) {
    warper.Mesh(&data.edge);
  } else {
    warper.Splats();
  }
}

}  // namespace parallax
