#pragma once
// The rows of a source a warp band works on (internal to reproject/: forward_warp.cc): the
// band's scratch, and the window of vertex rows its walk reads, prepared in row order.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

#include "reproject/forward_warp.h"
#include "reproject/view.h"
#include "reproject/warp_rows.h"

namespace parallax::warp_internal {

template <typename T>
inline void Allocate(PixelArray<T>* array, size_t count) {
  // Per-pixel arrays of a megabyte and more start on a huge page and are advised to use them
  // (Linux): a warp writes and reads them scattered across the image, missing the TLB with
  // 4 KB pages.
  constexpr size_t kHugePage = size_t{2} << 20;
  const size_t bytes = count * sizeof(T);
  if (bytes < (size_t{1} << 20)) {
    array->reset(static_cast<T*>(std::malloc(std::max<size_t>(bytes, 1))));
  } else {
    const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
    array->reset(static_cast<T*>(std::aligned_alloc(kHugePage, rounded)));
#if defined(__linux__)
    if (*array) madvise(array->get(), rounded, MADV_HUGEPAGE);
#endif
  }
  if (!*array) throw std::bad_alloc();
}

// What each band of a warp prepares and marks for itself (every band walks the whole source).
struct BandScratch {
  Vertices vertices;
  std::vector<uint8_t> silhouette_marks;  // Mesh: PenaliseSilhouetteRow's, one row.
};

// The side of the largest blocks of the mesh (SourceWarper::Mesh), the grid they start on.
// 8: as accurate as 4 and 16 on the courtyard's novel views.
constexpr int kMaxBlock = 8;

// A band's vertices (with, for a mesh, the quads and silhouette penalties), prepared in source
// row order as its walk reaches them, and only the few rows the walk reads at a time kept:
// they stay in cache, where a whole source's vertices (~5 MB at 640x480), prepared first,
// came back from memory out of a cache that the other thread's warp shares.
class RowWindow {
 public:
  // A block row of the mesh reads the vertex rows from the one above it to the one below it
  // (its splats and the quads of its last row): kMaxBlock + 3.
  static constexpr int kRows = kMaxBlock + 3;

  RowWindow(const WarpSetup& setup, const SourceView& source, const uint8_t* background,
            const float* ray_x, const ForwardWarpOptions& options, BandScratch* band);

  Vertices& Get() { return band_->vertices; }

  // Vertex rows first to last (clamped to the image) prepared and in the window: projected,
  // and for a mesh with the quads below them and their silhouette penalties. Rows above
  // `first` may leave the window. Throws std::logic_error when more rows than kRows are asked
  // for at once.
  void Through(int first, int last);

 private:
  // The edge marks of row y: the image border only, so far.
  void MarkBorder(int y);
  // Moves the projected rows from `first` on to the start of the window.
  void Slide(int first);

  const WarpSetup& s_;
  const SourceView& source_;
  const uint8_t* background_;
  const float* ray_x_;
  bool mesh_;
  float penalty_;
  BandScratch* band_;
  int first_ = 0;      // The window's first row.
  int projected_ = 0;  // Rows projected: [0, projected_).
  int complete_ = 0;   // Rows prepared: [0, complete_).
};

}  // namespace parallax::warp_internal
