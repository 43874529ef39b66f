#include "mesh/texture.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <optional>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/error.h"
#include "core/image_sampling.h"
#include "geometry/raycaster.h"
#include "core/check.h"

namespace parallax {
namespace {

struct Candidate {
  int view = -1;
  float score = 0;
};
constexpr int kMaxCandidates = 8;
// How far beyond a photo's border a texel may lie and still take the border's color.
constexpr float kBorderPixels = 4;
using Candidates = std::array<Candidate, kMaxCandidates>;  // Best first; view -1 ends the list.

Eigen::Vector3f Centroid(const std::vector<Eigen::Vector3f>& vertices, const Eigen::Vector3i& t) {
  return (vertices[static_cast<size_t>(t[0])] + vertices[static_cast<size_t>(t[1])] +
          vertices[static_cast<size_t>(t[2])]) / 3.0f;
}

// Pixel position of a world point in a distortion-free camera; false behind it.
bool ProjectPinhole(const TextureView& view, const Eigen::Vector3f& world, Eigen::Vector2f& pixel,
                    float& depth) {
  const Eigen::Vector3d p = view.cam_from_world * world.cast<double>();
  if (!(p.z() > 0)) return false;
  pixel = Eigen::Vector2f(static_cast<float>(view.camera.FocalX() * p.x() / p.z() + view.camera.PrincipalX()),
                          static_cast<float>(view.camera.FocalY() * p.y() / p.z() + view.camera.PrincipalY()));
  depth = static_cast<float>(p.z());
  return pixel.allFinite();
}

bool Inside(const TextureView& view, const Eigen::Vector2f& pixel, float margin) {
  return pixel.x() >= margin && pixel.y() >= margin &&
         pixel.x() <= static_cast<float>(view.camera.width) - margin &&
         pixel.y() <= static_cast<float>(view.camera.height) - margin;
}

// Whether the pixel box [low, high] overlaps the photo.
bool Overlaps(const TextureView& view, const Eigen::Vector2f& low, const Eigen::Vector2f& high) {
  return high.x() >= 0 && high.y() >= 0 && low.x() <= static_cast<float>(view.camera.width) &&
         low.y() <= static_cast<float>(view.camera.height);
}

void Insert(Candidates& list, Candidate candidate, int limit) {
  for (int i = 0; i < limit; ++i) {
    if (list[static_cast<size_t>(i)].view < 0 || candidate.score > list[static_cast<size_t>(i)].score) {
      std::swap(list[static_cast<size_t>(i)], candidate);
      if (candidate.view < 0) return;
    }
  }
}

// For every triangle, the photos that see it unoccluded, best first. The score is the
// triangle's area in the photo's pixels, which falls with obliqueness and distance alike.
std::vector<Candidates> RankViews(const std::vector<Eigen::Vector3f>& vertices,
                                  const std::vector<Eigen::Vector3i>& triangles,
                                  const std::vector<TextureView>& views,
                                  const TextureOptions& options) {
  std::vector<Candidates> ranked(triangles.size());
  std::vector<Eigen::Vector3f> centroids(triangles.size());
  for (size_t t = 0; t < triangles.size(); ++t) centroids[t] = Centroid(vertices, triangles[t]);
  const MeshRaycaster raycaster(vertices, triangles);
  const float min_cos = static_cast<float>(std::cos(options.max_view_angle_deg * std::numbers::pi / 180));
  for (size_t v = 0; v < views.size(); ++v) {
    const TextureView& view = views[v];
    const Eigen::Vector3f eye = CameraCenter(view.cam_from_world).cast<float>();
    const std::vector<uint8_t> visible = raycaster.Visible(eye, centroids, 1e-3f);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles.size()),
                      [&](const tbb::blocked_range<size_t>& range) {
      for (size_t t = range.begin(); t < range.end(); ++t) {
        if (!visible[t]) continue;
        const Eigen::Vector3i& tri = triangles[t];
        // In view: every corner in front of the camera, and the triangle's bounding box
        // overlapping the photo (texels beyond its border take the border's color).
        std::array<Eigen::Vector2f, 3> pixels;
        bool in_front = true;
        for (int c = 0; c < 3 && in_front; ++c) {
          float depth = 0;
          in_front = ProjectPinhole(view, vertices[static_cast<size_t>(tri[c])],
                                    pixels[static_cast<size_t>(c)], depth);
        }
        if (!in_front || !Overlaps(view, pixels[0].cwiseMin(pixels[1]).cwiseMin(pixels[2]),
                                   pixels[0].cwiseMax(pixels[1]).cwiseMax(pixels[2]))) {
          continue;
        }
        const Eigen::Vector3f normal = (vertices[static_cast<size_t>(tri[1])] - vertices[static_cast<size_t>(tri[0])])
                                           .cross(vertices[static_cast<size_t>(tri[2])] - vertices[static_cast<size_t>(tri[0])]);
        const Eigen::Vector3f ray = centroids[t] - eye;
        const float norms = normal.norm() * ray.norm();
        if (!(norms > 0) || std::abs(normal.dot(ray)) < min_cos * norms) continue;
        const Eigen::Vector2f e1 = pixels[1] - pixels[0], e2 = pixels[2] - pixels[0];
        const float area = 0.5f * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
        Insert(ranked[t], {static_cast<int>(v), area}, options.max_views_per_triangle);
      }
    });
  }
  return ranked;
}

// Median over textured triangles of the longest edge in the best photo, in pixels.
double MedianEdgePixels(const std::vector<Eigen::Vector3f>& vertices,
                        const std::vector<Eigen::Vector3i>& triangles,
                        const std::vector<TextureView>& views,
                        const std::vector<Candidates>& ranked) {
  std::vector<float> edges;
  for (size_t t = 0; t < triangles.size(); ++t) {
    if (ranked[t][0].view < 0) continue;
    const TextureView& view = views[static_cast<size_t>(ranked[t][0].view)];
    std::array<Eigen::Vector2f, 3> pixels;
    float depth = 0;
    for (int c = 0; c < 3; ++c) {
      ProjectPinhole(view, vertices[static_cast<size_t>(triangles[t][c])], pixels[static_cast<size_t>(c)], depth);
    }
    edges.push_back(std::max({(pixels[1] - pixels[0]).norm(), (pixels[2] - pixels[0]).norm(),
                              (pixels[2] - pixels[1]).norm()}));
  }
  if (edges.empty()) return 0;
  std::nth_element(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2), edges.end());
  return static_cast<double>(edges[edges.size() / 2]);
}

// Triangles in pairs, a pair to a cell of (texels + 5) x (texels + 2) texels: the first in the
// cell's lower left, its legs along the cell's edges, the second turned half a turn in the upper
// right. Each has a texel of margin to the cell's edges and three texels of gap to the other
// along the diagonal, so bilinear filtering at a point of one triangle reads only texels of its
// own side (in cell texels (i, j), the first's are those with i + j <= texels + 2), and every
// texel shows its side's triangle, at its nearest point. Half a square per triangle, where one
// triangle to a square cell left the other half unused.
struct AtlasLayout {
  int texels = 0;  // Along each triangle's legs.
  int columns = 0, rows = 0;

  int CellWidth() const { return texels + 5; }
  int CellHeight() const { return texels + 2; }
  int Width() const { return columns * CellWidth(); }
  int Height() const { return rows * CellHeight(); }
  int LongerSide() const { return std::max(Width(), Height()); }
  // Where texel (i, j) of triangle t's cell lies from t's corner 0 along its two legs, in texels;
  // none when the texel belongs to the other triangle of the cell.
  std::optional<Eigen::Vector2i> PlaceOnLegs(size_t t, int i, int j) const {
    const bool second = t % 2 == 1;
    if ((i + j > texels + 2) != second) return std::nullopt;
    return second ? Eigen::Vector2i(CellWidth() - 1 - i, CellHeight() - 1 - j) : Eigen::Vector2i(i, j);
  }
  // Corner c of triangle t in atlas texels (x right, y down); corner 0 is where its legs meet.
  Eigen::Vector2f Corner(size_t t, int c) const {
    const bool second = t % 2 == 1;
    const Eigen::Vector2f cell = CellOrigin(t).cast<float>();
    const Eigen::Vector2f origin = cell + (second ? Eigen::Vector2f(static_cast<float>(texels + 4), static_cast<float>(texels + 1))
                                                  : Eigen::Vector2f(1, 1));
    const float leg = second ? -static_cast<float>(texels) : static_cast<float>(texels);
    return c == 0 ? origin : c == 1 ? origin + Eigen::Vector2f(leg, 0) : origin + Eigen::Vector2f(0, leg);
  }
  // The atlas pixel of texel (i, j) of triangle t's cell.
  size_t TexelIndex(size_t t, int i, int j) const {
    const Eigen::Vector2i texel = CellOrigin(t) + Eigen::Vector2i(i, j);
    return static_cast<size_t>(texel.y()) * static_cast<size_t>(Width()) + static_cast<size_t>(texel.x());
  }

 private:
  Eigen::Vector2i CellOrigin(size_t t) const {
    const auto cell = static_cast<int>(t / 2);
    return {cell % columns * CellWidth(), cell / columns * CellHeight()};
  }
};

// About as many texels down as across.
AtlasLayout LayoutFor(size_t triangles, int texels) {
  AtlasLayout layout;
  layout.texels = texels;
  const double cells = std::max(1.0, std::ceil(static_cast<double>(triangles) / 2));
  layout.columns = std::max(1, static_cast<int>(std::ceil(std::sqrt(cells * layout.CellHeight() / layout.CellWidth()))));
  layout.rows = static_cast<int>(std::ceil(cells / layout.columns));
  return layout;
}

// For each view, the triangles that rank it and with what weight: (score / best score)^exponent.
std::vector<std::vector<std::pair<size_t, float>>> UsesPerView(const std::vector<Candidates>& ranked, size_t views,
                                                               double blend_exponent) {
  std::vector<std::vector<std::pair<size_t, float>>> uses(views);
  for (size_t t = 0; t < ranked.size(); ++t) {
    for (const Candidate& candidate : ranked[t]) {
      if (candidate.view < 0) break;
      const double ratio = static_cast<double>(candidate.score / ranked[t][0].score);
      uses[static_cast<size_t>(candidate.view)].emplace_back(t, static_cast<float>(std::pow(ratio, blend_exponent)));
    }
  }
  return uses;
}

// The views' photos, one at a time: each photo's weighted samples added to the texels of the
// triangles that ranked it (in the atlas itself), then the texels divided by their weights.
class TexelAccumulator {
 public:
  explicit TexelAccumulator(Image& atlas)
      : atlas_(atlas), weights_(static_cast<size_t>(atlas.Width()) * static_cast<size_t>(atlas.Height()), 0.0f) {}

  void Add(size_t texel, const Eigen::Vector3f& color, float weight) {
    float* sum = &atlas_.Pixels()[3 * texel];
    for (int c = 0; c < 3; ++c) sum[c] += weight * color[c];
    weights_[texel] += weight;
  }
  // The atlas in sRGB: the weighted means, mid-grey where no photo contributed.
  void Finish() {
    tbb::parallel_for(tbb::blocked_range<size_t>(0, weights_.size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t texel = range.begin(); texel < range.end(); ++texel) {
        float* color = &atlas_.Pixels()[3 * texel];
        const float weight = weights_[texel];
        for (int c = 0; c < 3; ++c) {
          const float linear = weight > 0 ? color[c] / weight : SrgbToLinear(0.5f);
          color[c] = std::clamp(LinearToSrgb(linear), 0.0f, 1.0f);
        }
      }
    });
  }

 private:
  Image& atlas_;
  std::vector<float> weights_;
};

Image ColorOf(const TextureView& view) {
  Image color = view.color.Pixels().empty() && view.load_color ? view.load_color() : view.color;
  if (static_cast<uint64_t>(color.Width()) != view.camera.width ||
      static_cast<uint64_t>(color.Height()) != view.camera.height || color.Channels() < 3) {
    throw InternalError("texture: a view's photo is not an RGB image of its camera's size");
  }
  return color;
}

}  // namespace

void TextureOptions::Check() const {
  RequireOption(min_texels_per_edge >= 1, "TextureOptions.min_texels_per_edge", min_texels_per_edge, ">= 1");
  RequireOption(max_texels_per_edge >= min_texels_per_edge, "TextureOptions.max_texels_per_edge",
                max_texels_per_edge, ">= min_texels_per_edge");
  RequireOption(max_views_per_triangle >= 1 && max_views_per_triangle <= kMaxCandidates,
                "TextureOptions.max_views_per_triangle", max_views_per_triangle,
                "[1, " + std::to_string(kMaxCandidates) + "]");
  RequireOption(blend_exponent >= 0, "TextureOptions.blend_exponent", blend_exponent, ">= 0");
  RequireOption(max_view_angle_deg > 0 && max_view_angle_deg < 90, "TextureOptions.max_view_angle_deg",
                max_view_angle_deg, "(0, 90)");
}

TriangleMesh TextureMesh(const std::vector<Eigen::Vector3f>& vertices,
                         const std::vector<Eigen::Vector3i>& triangles,
                         const std::vector<TextureView>& views, const TextureOptions& options,
                         TextureSummary& summary) {
  options.Check();
  for (const TextureView& view : views) {
    if (view.camera.HasDistortion()) throw InternalError("texture: views must be distortion-free");
  }
  // Which triangles rank each photo, with their weights; the ranking itself is freed before the
  // atlas is made.
  std::vector<std::vector<std::pair<size_t, float>>> uses;
  double median_edge_pixels = 0;
  {
    const std::vector<Candidates> ranked = RankViews(vertices, triangles, views, options);
    median_edge_pixels = MedianEdgePixels(vertices, triangles, views, ranked);
    uses = UsesPerView(ranked, views.size(), options.blend_exponent);
    summary.untextured_triangles = static_cast<size_t>(
        std::count_if(ranked.begin(), ranked.end(), [](const Candidates& c) { return c[0].view < 0; }));
  }

  int texels = std::clamp(static_cast<int>(std::ceil(median_edge_pixels)), options.min_texels_per_edge,
                          options.max_texels_per_edge);
  while (texels > options.min_texels_per_edge && LayoutFor(triangles.size(), texels).LongerSide() > options.max_atlas_size) {
    --texels;
  }
  const AtlasLayout layout = LayoutFor(triangles.size(), texels);
  summary.texels_per_edge = texels;

  TriangleMesh mesh;
  mesh.vertices = vertices;
  mesh.triangles = triangles;
  mesh.atlas = Image(layout.Width(), layout.Height(), 3);
  mesh.corner_uvs.resize(3 * triangles.size());
  const float width = static_cast<float>(mesh.atlas.Width());
  const float height = static_cast<float>(mesh.atlas.Height());
  for (size_t t = 0; t < triangles.size(); ++t) {
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector2f corner = layout.Corner(t, c);
      mesh.corner_uvs[3 * t + static_cast<size_t>(c)] = Eigen::Vector2f(corner.x() / width, 1.0f - corner.y() / height);
    }
  }
  // The surface point a texel of triangle t shows, given by its place (i, j) from the
  // triangle's first corner along its legs: texels outside the triangle take its nearest point.
  const auto texel_point = [&](size_t t, int i, int j) {
    const Eigen::Vector3i& tri = triangles[t];
    const Eigen::Vector3f& v0 = vertices[static_cast<size_t>(tri[0])];
    const float leg = static_cast<float>(texels);
    float a = std::max(0.0f, (static_cast<float>(i) - 0.5f) / leg);
    float b = std::max(0.0f, (static_cast<float>(j) - 0.5f) / leg);
    if (a + b > 1) {
      const float sum = a + b;
      a /= sum;
      b /= sum;
    }
    return Eigen::Vector3f(v0 + a * (vertices[static_cast<size_t>(tri[1])] - v0) +
                           b * (vertices[static_cast<size_t>(tri[2])] - v0));
  };
  TexelAccumulator texels_sum(mesh.atlas);
  for (size_t v = 0; v < views.size(); ++v) {
    if (uses[v].empty()) continue;
    const TextureView& view = views[v];
    const Image color = ColorOf(view);
    // Triangles own disjoint cells: in parallel without contention.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, uses[v].size()), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t u = range.begin(); u < range.end(); ++u) {
        const auto [t, weight] = uses[v][u];
        for (int j = 0; j < layout.CellHeight(); ++j) {
          for (int i = 0; i < layout.CellWidth(); ++i) {
            const std::optional<Eigen::Vector2i> place = layout.PlaceOnLegs(t, i, j);
            if (!place) continue;
            Eigen::Vector2f pixel;
            float depth = 0;
            if (!ProjectPinhole(view, texel_point(t, place->x(), place->y()), pixel, depth) ||
                !Inside(view, pixel, -kBorderPixels)) {
              continue;
            }
            texels_sum.Add(layout.TexelIndex(t, i, j), SampleBilinear(color, pixel), weight);
          }
        }
      }
    });
  }
  texels_sum.Finish();
  return mesh;
}

}  // namespace parallax
