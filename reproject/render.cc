#include "reproject/render.h"

#include <algorithm>
#include <chrono>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include "core/elapsed.h"
#include "core/error.h"
#include "reproject/fill_from_sources.h"

namespace parallax {
namespace {

using Clock = std::chrono::steady_clock;

// Bands of target rows each of `warps` concurrent warps draws in parallel: enough for every
// thread to have one. A band walks the whole source mesh, so a warp drawn in two bands costs
// more CPU in all: worth it only where threads would otherwise wait (one source with two
// threads: the render's hole sources).
int BandsPerWarp(size_t warps) {
  const auto threads = static_cast<size_t>(tbb::this_task_arena::max_concurrency());
  return static_cast<int>(std::max<size_t>(1, threads / std::max<size_t>(1, warps)));
}

}  // namespace

void RenderOptions::Check() const {
  warp.Check();
  blend.Check();
  holes.Check();
  fill.Check();
}

Renderer::Renderer(const RenderOptions& options) : options_(options) { options_.Check(); }

RenderResult Render(const std::vector<const SourceView*>& sources, const TargetCamera& target,
                    const RenderOptions& options) {
  RenderResult result;
  Renderer(options).Render(sources, target, &result);
  return result;
}

void Renderer::Render(const std::vector<const SourceView*>& sources, const TargetCamera& target,
                      RenderResult* result) {
  const Clock::time_point start = Clock::now();
  if (sources.empty()) throw InternalError("Render: no source views");
  for (size_t i = 0; i < sources.size(); ++i) {
    if (sources[i] == nullptr) {
      throw InternalError("Render: source " + std::to_string(i) + " is null");
    }
    CheckSourceView(*sources[i]);
  }
  Pinhole::From(target.camera);  // Rejects a distorted target before any work.
  sources_ = sources;
  target_ = target;
  KeepBuffers(sources.size());
  // One task per source, taken by whichever thread is free: the default partitioner splits
  // four sources into two fixed pairs in selection order, and the best sources, which cover
  // most of the target, cost the most.
  const int bands = BandsPerWarp(sources.size());
  tbb::parallel_for(
      tbb::blocked_range<size_t>(0, sources.size(), 1),
      [&](const tbb::blocked_range<size_t>& range) {
        for (size_t i = range.begin(); i < range.end(); ++i) {
          ForwardWarp(*sources[i], target, options_.warp, &buffers_[i], &scratch_[i], bands);
        }
      },
      tbb::simple_partitioner());
  Finish(start, MsSince(start), result);
}

void Renderer::RenderWithOneMore(const SourceView& source, RenderResult* result) {
  const Clock::time_point start = Clock::now();
  if (sources_.empty()) throw std::logic_error("Renderer::RenderWithOneMore before Render");
  CheckSourceView(source);
  const size_t added = sources_.size();
  KeepBuffers(added + 1);
  ForwardWarp(source, target_, options_.warp, &buffers_[added], &scratch_[added], BandsPerWarp(1));
  sources_.push_back(&source);  // Only once warped: a throw leaves the last render's state.
  Finish(start, MsSince(start), result);
}

void Renderer::KeepBuffers(size_t count) {
  if (buffers_.size() >= count) return;
  buffers_.resize(count);
  scratch_.resize(count);
}

void Renderer::Finish(Clock::time_point start, double warp_ms, RenderResult* result) {
  RenderTimings timings;
  timings.warp_ms = warp_ms;
  Clock::time_point step = Clock::now();
  Blend(std::span<const WarpBuffer>(buffers_).first(sources_.size()), options_.blend, &blend_);
  timings.blend_ms = MsSince(step);

  step = Clock::now();
  std::vector<ClassifySource> classify_sources;
  for (size_t i = 0; i < sources_.size(); ++i) {
    classify_sources.push_back({sources_[i]->Posed(), &sources_[i]->depth, &scratch_[i].Background()});
  }
  ClassMap classes = ClassifyPixels(blend_, classify_sources, target_, options_.holes);
  const HoleMetrics metrics = ComputeHoleMetrics(classes);
  timings.classify_ms = MsSince(step);

  step = Clock::now();
  const FillSummary fill = FillHoles(classes, target_.camera, options_.fill, &blend_);
  if (options_.fill.from_sources && options_.fill.method == FillMethod::kDepthAware) {
    std::vector<FillSource> fill_sources;
    for (size_t i = 0; i < sources_.size(); ++i) {
      fill_sources.push_back({sources_[i]->Posed(), &sources_[i]->color, &sources_[i]->depth,
                              &scratch_[i].Background()});
    }
    FillFromSources(classes, target_, fill_sources, &blend_);
  }
  timings.fill_ms = MsSince(step);

  // Nothing above touched *result: a throw leaves it as it was.
  std::swap(result->color, blend_.color);
  std::swap(result->depth, blend_.depth);
  result->classes = std::move(classes);
  result->metrics = metrics;
  result->fill = fill;
  result->timings = timings;
  result->timings.total_ms = MsSince(start);
}

}  // namespace parallax
