#pragma once

namespace parallax {

// One knob for every stage: what `--quality` trades between error and run time. Each stage
// documents what each level means for it.
enum class Quality { kFast, kBalanced, kBest };

// "fast", "balanced", "best": the name --quality takes.
inline const char* QualityName(Quality quality) {
  switch (quality) {
    case Quality::kFast: return "fast";
    case Quality::kBalanced: return "balanced";
    case Quality::kBest: return "best";
  }
  return "balanced";
}

}  // namespace parallax
