#include "reproject/row_window.h"

#include <stdexcept>
#include <string>

namespace parallax::warp_internal {

RowWindow::RowWindow(const WarpSetup& setup, const SourceView& source, const uint8_t* background,
                     const float* ray_x, const ForwardWarpOptions& options, BandScratch* band)
    : s_(setup), source_(source), background_(background), ray_x_(ray_x),
      mesh_(options.method == WarpMethod::kMesh),
      penalty_(static_cast<float>(options.silhouette_angle_rad)), band_(band) {
  const auto width = static_cast<size_t>(s_.src.width);
  Vertices& vertices = band_->vertices;
  const size_t count = static_cast<size_t>(kRows) * width;
  if (count > vertices.capacity) {
    Allocate(&vertices.u, count);
    Allocate(&vertices.v, count);
    Allocate(&vertices.inv_z, count);
    Allocate(&vertices.angle, count);
    Allocate(&vertices.kind, count);
    Allocate(&vertices.quads, count);
    Allocate(&vertices.edges, count);
    vertices.capacity = count;
  }
  vertices.offset = 0;
  if (mesh_) band_->silhouette_marks.resize(width);
}

void RowWindow::Through(int first, int last) {
  const int height = s_.src.height;
  last = std::min(last, height - 1);
  for (; complete_ <= last; ++complete_) {
    // The quads of row r join the kinds of rows r and r + 1; its penalties read quads
    // r - 1 and r.
    for (; projected_ <= std::min(complete_ + 1, height - 1); ++projected_) {
      if (projected_ - first_ >= kRows) Slide(first);
      ProjectRow(s_, source_, background_, ray_x_, projected_, &band_->vertices);
      if (mesh_) MarkBorder(projected_);
    }
    if (!mesh_) continue;
    ContinuousRow(source_, s_, complete_, &band_->vertices);
    if (penalty_ > 0) {
      PenaliseSilhouetteRow(s_, penalty_, complete_, band_->silhouette_marks.data(),
                            &band_->vertices);
    }
  }
}

void RowWindow::MarkBorder(int y) {
  const int width = s_.src.width;
  if (width == 0) return;
  uint8_t* edges = band_->vertices.edges.get() +
                   band_->vertices.At(static_cast<size_t>(y) * static_cast<size_t>(width));
  const bool border_row = y == 0 || y == s_.src.height - 1;
  std::fill(edges, edges + width, static_cast<uint8_t>(border_row ? 1 : 0));
  edges[0] = 1;
  edges[width - 1] = 1;
}

void RowWindow::Slide(int first) {
  first = std::max(first, first_);
  if (projected_ - first >= kRows) {
    throw std::logic_error("RowWindow: more than " + std::to_string(kRows) + " rows at once");
  }
  const auto width = static_cast<size_t>(s_.src.width);
  const size_t from = static_cast<size_t>(first - first_) * width;
  const size_t kept = static_cast<size_t>(projected_ - first) * width;
  Vertices& vertices = band_->vertices;
  const auto slide = [&](auto& array) {
    std::copy(array.get() + from, array.get() + from + kept, array.get());
  };
  slide(vertices.u);
  slide(vertices.v);
  slide(vertices.inv_z);
  slide(vertices.angle);
  slide(vertices.kind);
  slide(vertices.quads);
  slide(vertices.edges);
  first_ = first;
  vertices.offset = static_cast<size_t>(first) * width;
}

}  // namespace parallax::warp_internal
