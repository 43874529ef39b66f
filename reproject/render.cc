#include "reproject/render.h"

#include <chrono>
#include <stdexcept>
#include <string>

#include <tbb/parallel_for.h>

namespace parallax {
namespace {

using Clock = std::chrono::steady_clock;

double MsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
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
  return Renderer(options).Render(sources, target);
}

RenderResult Renderer::Render(const std::vector<const SourceView*>& sources,
                              const TargetCamera& target) {
  const Clock::time_point start = Clock::now();
  const RenderOptions& options = options_;
  if (sources.empty()) throw std::invalid_argument("Render: no source views");
  for (size_t i = 0; i < sources.size(); ++i) {
    if (sources[i] == nullptr) {
      throw std::invalid_argument("Render: source " + std::to_string(i) + " is null");
    }
    CheckSourceView(*sources[i]);
  }
  Pinhole::From(target.camera);  // Rejects a distorted target before any work.

  RenderResult result;
  buffers_.resize(sources.size());
  scratch_.resize(sources.size());
  tbb::parallel_for(size_t{0}, sources.size(), [&](size_t i) {
    ForwardWarp(*sources[i], target, options.warp, &buffers_[i], &scratch_[i]);
  });
  result.timings.warp_ms = MsSince(start);

  Clock::time_point step = Clock::now();
  BlendResult blend = Blend(buffers_, options.blend);
  result.timings.blend_ms = MsSince(step);

  step = Clock::now();
  std::vector<ClassifySource> classify_sources;
  for (size_t i = 0; i < sources.size(); ++i) {
    classify_sources.push_back({sources[i]->Posed(), &sources[i]->depth, &scratch_[i].Background()});
  }
  result.classes = ClassifyPixels(blend, classify_sources, target, options.holes);
  result.metrics = ComputeHoleMetrics(result.classes);
  result.timings.classify_ms = MsSince(step);

  step = Clock::now();
  result.fill = FillHoles(result.classes, target.camera, options.fill, &blend);
  result.timings.fill_ms = MsSince(step);

  result.color = std::move(blend.color);
  result.depth = std::move(blend.depth);
  result.timings.total_ms = MsSince(start);
  return result;
}

}  // namespace parallax
