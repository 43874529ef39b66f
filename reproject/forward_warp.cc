#include "reproject/forward_warp.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "core/error.h"
#include "reproject/background.h"
#include "reproject/rasterizer.h"
#include "reproject/row_window.h"
#include "reproject/simd.h"
#include "reproject/warp_rows.h"
#include "core/check.h"

namespace parallax {
namespace {

using warp_internal::Corner;
using warp_internal::Finite;
using warp_internal::kFloatMax;
using warp_internal::Rasterizer;
using warp_internal::ContinuousRow;
using warp_internal::MakeSetup;
using warp_internal::PenaliseSilhouetteRow;
using warp_internal::ProjectRow;
using warp_internal::Vertices;
using warp_internal::WarpSetup;
using warp_internal::Allocate;
using warp_internal::BandScratch;
using warp_internal::kMaxBlock;
using warp_internal::RowWindow;
using warp_internal::kInvalid;
using warp_internal::kSky;
using warp_internal::kSurface;

}  // namespace

struct WarpScratch::Data {
  std::vector<warp_internal::BandScratch> bands;
  std::vector<uint8_t> background;  // MarkBackground, when the source has none to share.
  const std::vector<uint8_t>* background_used = nullptr;  // This or the source's; null: none.
  std::vector<size_t> stack;        // MarkBackground's flood fill.
  std::vector<float> ray_x;         // Per source column: (x + 0.5 - cx) / fx.
  std::vector<uint16_t> texture;    // SourceView::texture, when the source has none.
};

namespace {

// SourceView::texture of `color` (3 channels), values beyond a half's range clamped to it.
void MakeTexture(const Image& color, std::vector<uint16_t>* texture) {
  const size_t count = static_cast<size_t>(color.Width()) * static_cast<size_t>(color.Height());
  texture->resize(4 * count);
  const float* rgb = color.Pixels().data();
  uint16_t* out = texture->data();
  const simd::F4 low = simd::F4{} - WarpBuffer::kMaxHalf;
  for (size_t i = 0; i < count; ++i) {
    const simd::F4 value = {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2], 0.0f};
    warp_internal::StoreHalf4Clamped(out + 4 * i, value, low);
  }
}


class SourceWarper {
 public:
  SourceWarper(const SourceView& source, const WarpSetup& setup, RowWindow* rows,
               const ForwardWarpOptions& options, Rasterizer* raster)
      : source_(source), s_(setup), rows_(rows), vtx_(rows->Get()), options_(options),
        raster_(raster), width_(setup.src.width), height_(setup.src.height) {}

  // Blocks of kMaxBlock x kMaxBlock source pixels whose quads all join one surface are drawn
  // as one quad (a plane is exact under perspective, a curved surface within a small fraction
  // of a pixel), others split in four down to single quads: most of the image costs one
  // quad setup per 64 source pixels. Vertices next to a dropped triangle or on the source
  // border are splatted: the mesh stops at the last sample centre, half a pixel short of
  // where the pixel ends. Block row by block row, each followed by the splats of the vertex
  // rows it completed, in row-major order (z-test ties go the same way on every run).
  void Mesh() {
    int splatted = 0;  // Vertex rows [0, splatted) splatted.
    for (int y = 0; y + 1 < height_; y += kMaxBlock) {
      rows_->Through(y - 1, y + kMaxBlock);
      for (int x = 0; x + 1 < width_; x += kMaxBlock) Block(x, y, kMaxBlock);
      // Every quad on rows up to y + kMaxBlock - 1 is drawn (all of them after the last block
      // row): their marks are complete.
      const int complete = y + kMaxBlock + 1 < height_ ? y + kMaxBlock : height_;
      SplatEdges(splatted, complete);
      splatted = complete;
    }
    rows_->Through(splatted - 1, height_ - 1);
    SplatEdges(splatted, height_);
  }

  void Splats() {
    for (int y = 0; y < height_; ++y) {
      rows_->Through(y - 1, y + 1);
      for (int x = 0; x < width_; ++x) SplatVertex(x, y, false);
    }
  }

 private:
  size_t Index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  }
  float SourceDepth(size_t i) const { return source_.depth.Values()[i]; }
  uint8_t Kind(size_t i) const { return vtx_.kind[vtx_.At(i)]; }

  // Splats the marked vertices of rows [begin, end) (in the window with the rows beside them).
  void SplatEdges(int begin, int end) {
    for (int y = begin; y < end; ++y) {
      simd::ForEachMarked(vtx_.edges.get() + vtx_.At(Index(0, y)), width_,
                          [&](int x) { SplatVertex(x, y, true); });
    }
  }

  // A source pixel centre by index and coordinates, kept together: deriving the coordinates
  // from the index would cost two 64-bit divisions per corner.
  struct Sample {
    size_t i;
    int x, y;
  };
  Sample At(int x, int y) const { return {Index(x, y), x, y}; }

  Corner CornerAt(const Sample& p) const {
    const size_t v = vtx_.At(p.i);
    return {vtx_.u[v], vtx_.v[v], vtx_.inv_z[v], vtx_.angle[v],
            source_.color.Pixels().data() + 3 * p.i, static_cast<float>(p.x),
            static_cast<float>(p.y)};
  }

  // Marks a vertex for splatting.
  void MarkEdge(size_t i) { vtx_.edges[vtx_.At(i)] = 1; }

  // Relative inverse-depth deviation from the corners' blend within which a block is flat:
  // its samples land within ~kFlatTolerance x (disparity in pixels) of where they should.
  static constexpr float kFlatTolerance = 1e-3f;

  // kSurface when every quad of the side x side block at (x, y) (inside the image) is one
  // continuous surface and, for side > 1, the block is flat: a plane's inverse depth is
  // affine in the image, so the samples' must match the bilinear blend of the corners' (a
  // crease, such as a box's edge, would be cut off by the block's two triangles); tested at
  // the centre and the edge midpoints. kSky when
  // every quad is background. Else kInvalid.
  uint8_t BlockKind(int x, int y, int side) const {
    if (x + side >= width_ || y + side >= height_) return kInvalid;
    const uint8_t kind = vtx_.quads[vtx_.At(Index(x, y))];
    if (kind == kInvalid) return kInvalid;
    for (int r = y; r < y + side; ++r) {
      const uint8_t* row = vtx_.quads.get() + vtx_.At(Index(x, r));
      for (int c = 0; c < side; ++c) {
        if (row[c] != kind) return kInvalid;
      }
    }
    if (side == 1 || kind == kSky) return kind;
    // Inverse source depths (all > 0: one continuous surface).
    const auto inv = [&](int dx, int dy) { return 1.0f / SourceDepth(Index(x + dx, y + dy)); };
    const float i00 = inv(0, 0), i10 = inv(side, 0), i01 = inv(0, side), i11 = inv(side, side);
    // The centre and the edge midpoints: where a crease through the block shows most.
    const int half = side / 2;
    const float mid_top = 0.5f * (i00 + i10), mid_bottom = 0.5f * (i01 + i11);
    const float mid_left = 0.5f * (i00 + i01), mid_right = 0.5f * (i10 + i11);
    const float centre = 0.5f * (mid_top + mid_bottom);
    const auto off = [&](int dx, int dy, float expected) {
      return std::abs(inv(dx, dy) - expected) > kFlatTolerance * expected;
    };
    if (off(half, half, centre) || off(half, 0, mid_top) || off(half, side, mid_bottom) ||
        off(0, half, mid_left) || off(side, half, mid_right)) {
      return kInvalid;
    }
    return kind;
  }

  void Block(int x, int y, int side) {
    if (x + 1 >= width_ || y + 1 >= height_) return;
    const uint8_t kind = BlockKind(x, y, side);
    if (kind != kInvalid) {
      const Corner a = CornerAt(At(x, y)), b = CornerAt(At(x + side, y));
      const Corner c = CornerAt(At(x, y + side)), d = CornerAt(At(x + side, y + side));
      const auto fside = static_cast<float>(side);
      // Not drawn where the target quad is not convex (seen edge-on): smaller blocks, or the
      // two triangles of a single quad, below.
      if (kind == kSurface ? raster_->TexturedBlock<false>(a, b, c, d, fside)
                           : raster_->TexturedBlock<true>(a, b, c, d, fside)) {
        return;
      }
    }
    if (side > 1) {
      const int half = side / 2;
      Block(x, y, half);
      Block(x + half, y, half);
      Block(x, y + half, half);
      Block(x + half, y + half, half);
      return;
    }
    const Sample p00 = At(x, y), p10 = At(x + 1, y), p01 = At(x, y + 1), p11 = At(x + 1, y + 1);
    Triangle(p00, p10, p01);
    Triangle(p10, p11, p01);
  }

  // Two samples of one surface (or both background).
  bool Continuous(size_t i, size_t j) const {
    if (Kind(i) != Kind(j)) return false;
    if (Kind(i) == kSky) return true;
    const float a = SourceDepth(i), b = SourceDepth(j);
    return std::max(a, b) <= s_.max_depth_ratio * std::min(a, b);
  }

  void Triangle(const Sample& a, const Sample& b, const Sample& c) {
    const uint8_t ka = Kind(a.i), kb = Kind(b.i), kc = Kind(c.i);
    if (ka == kInvalid && kb == kInvalid && kc == kInvalid) return;
    if (ka == kb && kb == kc) {
      if (ka == kSky) {
        raster_->BackgroundTriangle(CornerAt(a), CornerAt(b), CornerAt(c));
        return;
      }
      const float da = SourceDepth(a.i), db = SourceDepth(b.i), dc = SourceDepth(c.i);
      if (std::max({da, db, dc}) <= s_.max_depth_ratio * std::min({da, db, dc})) {
        raster_->SurfaceTriangle(CornerAt(a), CornerAt(b), CornerAt(c));
        return;
      }
    }
    MarkEdge(a.i);
    MarkEdge(b.i);
    MarkEdge(c.i);
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
      d[0] = static_cast<float>(sign) * (vtx_.u[vtx_.At(j)] - vtx_.u[vtx_.At(i)]);
      d[1] = static_cast<float>(sign) * (vtx_.v[vtx_.At(j)] - vtx_.v[vtx_.At(i)]);
      return true;
    }
    return false;
  }

  // Whether sample j lies beyond surface sample i, seen from the source: sky, unknown depth,
  // or a surface farther than one surface's depth ratio. Unknown depth counts so that an
  // occluder beside estimated depth's eroded edges still shrinks, though nothing on the far
  // side of that gap grows to meet it.
  bool Beyond(size_t i, size_t j) const {
    return Kind(j) != kSurface || SourceDepth(j) > s_.max_depth_ratio * SourceDepth(i);
  }

  // The share of its footprint a vertex is splatted with: outline_splat_share on the near
  // side of an outline (a surface sample with something Beyond it among its eight neighbours),
  // and what that gives up added on the far side (a sample Beyond a surface neighbour), so
  // that the two still meet: the outline moves towards the near side, no crack opens. 1
  // elsewhere, and where a sample is both (a step of a steep slope, or a sliver between a
  // nearer and a farther surface) or has something Beyond it on opposite sides (a structure
  // one sample wide, a pole or a wire, which a smaller footprint would let fall between pixel
  // centres).
  float OutlineShare(int x, int y) const {
    const size_t i = Index(x, y);
    const bool surface = Kind(i) == kSurface;
    bool near_side = false, far_side = false;
    for (int ny = std::max(0, y - 1); ny <= std::min(height_ - 1, y + 1); ++ny) {
      for (int nx = std::max(0, x - 1); nx <= std::min(width_ - 1, x + 1); ++nx) {
        const size_t j = Index(nx, ny);
        near_side = near_side || (surface && Beyond(i, j));
        far_side = far_side || (Kind(j) == kSurface && Beyond(j, i));
      }
    }
    if (near_side == far_side) return 1.0f;
    // Opposite neighbours inside the image, both Beyond.
    const auto beyond_both = [&](int dx, int dy) {
      const int ax = x - dx, ay = y - dy, bx = x + dx, by = y + dy;
      return ax >= 0 && ay >= 0 && bx < width_ && by < height_ && Beyond(i, Index(ax, ay)) &&
             Beyond(i, Index(bx, by));
    };
    if (near_side && (beyond_both(1, 0) || beyond_both(0, 1))) return 1.0f;
    const auto share = static_cast<float>(options_.outline_splat_share);
    return near_side ? share : 2.0f - share;
  }

  // Splats the vertex with its footprint (its magnification, with overlap; OutlineShare of it
  // for a mesh's edge vertex, at most max_splat_px across).
  void SplatVertex(int x, int y, bool mesh_edge) {
    const size_t i = Index(x, y);
    if (Kind(i) == kInvalid) return;
    const bool background = Kind(i) == kSky;
    // Fallback without a neighbour: magnification of a fronto-parallel patch.
    const float depth_ratio = background ? 1.0f : SourceDepth(i) * vtx_.inv_z[vtx_.At(i)];
    float du[2] = {static_cast<float>(s_.dst.fx / s_.src.fx) * depth_ratio, 0};
    float dv[2] = {0, static_cast<float>(s_.dst.fy / s_.src.fy) * depth_ratio};
    Derivative(x, y, 1, 0, du);
    Derivative(x, y, 0, 1, dv);
    const float overlap = static_cast<float>(options_.splat_overlap);
    const float max_px = static_cast<float>(options_.max_splat_px);
    const float share = mesh_edge ? OutlineShare(x, y) : 1.0f;
    const auto extent = [&](float across) {
      return std::min(share * std::clamp(overlap * across, 1.0f, max_px), max_px);
    };
    const float extent_u = extent(std::abs(du[0]) + std::abs(dv[0]));
    const float extent_v = extent(std::abs(du[1]) + std::abs(dv[1]));
    float stretch = std::abs(du[0] * dv[1] - du[1] * dv[0]);
    if (!Finite(stretch)) stretch = max_px * max_px;
    raster_->Splat(CornerAt({i, x, y}), 0.5f * extent_u, 0.5f * extent_v, stretch, background);
  }

  const SourceView& source_;
  const WarpSetup& s_;
  RowWindow* rows_;
  Vertices& vtx_;
  const ForwardWarpOptions& options_;
  Rasterizer* raster_;
  int width_;
  int height_;
};

}  // namespace

void ForwardWarpOptions::Check() const {
  RequireOption(max_slant_deg > 0 && max_slant_deg < 90, "ForwardWarpOptions.max_slant_deg", max_slant_deg, "(0, 90)");
  RequireOption(max_splat_px >= 1 && max_splat_px <= 64, "ForwardWarpOptions.max_splat_px", max_splat_px, "[1, 64]");
  RequireOption(splat_overlap >= 1 && splat_overlap <= 2, "ForwardWarpOptions.splat_overlap", splat_overlap, "[1, 2]");
  RequireOption(min_view_cos > 0 && min_view_cos < 1, "ForwardWarpOptions.min_view_cos", min_view_cos, "(0, 1)");
  RequireOption(background_max_step > 0 && std::isfinite(background_max_step),
                "ForwardWarpOptions.background_max_step", background_max_step, "> 0");
  RequireOption(angle_epsilon_rad > 0 && std::isfinite(angle_epsilon_rad), "ForwardWarpOptions.angle_epsilon_rad",
                angle_epsilon_rad, "> 0");
  RequireOption(silhouette_angle_rad >= 0 && std::isfinite(silhouette_angle_rad),
                "ForwardWarpOptions.silhouette_angle_rad", silhouette_angle_rad, ">= 0");
  RequireOption(outline_splat_share > 0 && outline_splat_share <= 1, "ForwardWarpOptions.outline_splat_share",
                outline_splat_share, "(0, 1]");
}

void WarpBuffer::Reset(int width, int height) {
  if (width < 0 || height < 0) {
    throw InternalError("WarpBuffer: negative size " + std::to_string(width) + "x" +
                        std::to_string(height));
  }
  width_ = width;
  height_ = height;
  const size_t count = Size();
  if (count > capacity_) {
    Allocate(&depth_, count);
    Allocate(&color_weight_, 4 * count);
    capacity_ = count;
  }
  std::fill(depth_.get(), depth_.get() + count, 0.0f);
}

std::array<float, 3> WarpBuffer::Color(size_t i) const {
  const simd::F4 rgbw = simd::LoadHalf4(color_weight_.get() + 4 * i);
  return {rgbw[0], rgbw[1], rgbw[2]};
}

float WarpBuffer::Weight(size_t i) const { return simd::LoadHalf4(color_weight_.get() + 4 * i)[3]; }

WarpScratch::WarpScratch() : data_(std::make_unique<Data>()) {}
WarpScratch::~WarpScratch() = default;
WarpScratch::WarpScratch(WarpScratch&&) noexcept = default;
WarpScratch& WarpScratch::operator=(WarpScratch&&) noexcept = default;
const std::vector<uint8_t>& WarpScratch::Background() const {
  static const std::vector<uint8_t> kNone;
  return data_->background_used != nullptr ? *data_->background_used : kNone;
}

void PrepareSource(SourceView* source, const ForwardWarpOptions& options, const RgbGain& gain) {
  options.Check();
  CheckSourceView(*source);
  if (options.background_at_infinity) {
    const auto step = static_cast<float>(options.background_max_step);
    source->background = MarkBackground(source->depth, source->color, step);
    source->background_step = step;
  }
  ApplyGain(gain, source->color);
  MakeTexture(source->color, &source->texture);
}

void ForwardWarp(const SourceView& source, const PosedCamera& target,
                 const ForwardWarpOptions& options, WarpBuffer* buffer, WarpScratch* scratch,
                 int bands) {
  options.Check();
  CheckSourceView(source);
  WarpScratch local;
  WarpScratch::Data& data = (scratch != nullptr ? scratch : &local)->Get();
  const WarpSetup setup = MakeSetup(source, target, options);
  buffer->Reset(setup.dst.width, setup.dst.height);

  const int width = setup.src.width, height = setup.src.height;
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height);
  data.background_used = nullptr;
  if (options.background_at_infinity) {
    const auto step = static_cast<float>(options.background_max_step);
    if (source.background.size() == count && source.background_step == step) {
      data.background_used = &source.background;
    } else {
      MarkBackground(source.depth, source.color, step, &data.background, &data.stack);
      data.background_used = &data.background;
    }
  }
  const std::vector<uint16_t>* texture = &source.texture;
  if (texture->size() != 4 * count) {
    MakeTexture(source.color, &data.texture);
    texture = &data.texture;
  }
  data.ray_x.resize(static_cast<size_t>(width));
  for (int x = 0; x < width; ++x) {
    data.ray_x[static_cast<size_t>(x)] = static_cast<float>((x + 0.5 - setup.src.cx) / setup.src.fx);
  }
  const uint8_t* background =
      data.background_used != nullptr ? data.background_used->data() : nullptr;

  // Triangles from anywhere in the source can land on any target pixel: each band of target
  // rows walks the whole mesh (or every splat), preparing its own rows, and draws what lands
  // in its rows, in the same order as one band would (the same z-test ties, the same output).
  const int band_count = std::clamp(bands, 1, std::max(1, setup.dst.height));
  const auto band_scratch = static_cast<size_t>(band_count);
  if (data.bands.size() < band_scratch) data.bands.resize(band_scratch);
  tbb::parallel_for(0, band_count, [&](int band) {
    BandScratch& own = data.bands[static_cast<size_t>(band)];
    RowWindow rows(setup, source, background, data.ray_x.data(), options, &own);
    const int target_rows = setup.dst.height;
    Rasterizer raster(buffer, texture->data(), width, height, options,
                      band * target_rows / band_count, (band + 1) * target_rows / band_count);
    SourceWarper warper(source, setup, &rows, options, &raster);
    if (options.method == WarpMethod::kMesh) {
      warper.Mesh();
    } else {
      warper.Splats();
    }
  });
}

}  // namespace parallax
