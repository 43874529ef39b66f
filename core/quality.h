#pragma once

namespace parallax {

// One knob for every stage: what `--quality` trades between error and run time. Each stage
// documents what each level means for it.
enum class Quality { kFast, kBalanced, kBest };

}  // namespace parallax
