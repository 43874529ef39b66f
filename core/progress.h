#pragma once
// Libraries never print: long work reports progress through this interface, which the CLI
// renders as a progress line and tests leave silent.
#include <cstdint>
#include <string_view>

namespace parallax {

class Progress {
 public:
  virtual ~Progress() = default;
  // `done` of `total` units of `stage` are complete. Called from the thread that runs the
  // stage, never concurrently.
  virtual void Update(std::string_view stage, int64_t done, int64_t total) = 0;
  // Something the user should know now, as it is found (a file set aside), rather than in the
  // summary at the end, which a failing run never reaches. Ignored unless overridden.
  virtual void Warn(std::string_view /*message*/) {}
};

class SilentProgress final : public Progress {
 public:
  void Update(std::string_view, int64_t, int64_t) override {}
};

}  // namespace parallax
