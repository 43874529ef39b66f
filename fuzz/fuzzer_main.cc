// libFuzzer entry point of one target; PARALLAX_FUZZ_TARGET names it (fuzz/CMakeLists.txt).
#include "fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const parallax::fuzz::TargetFunction run =
      parallax::fuzz::FindTarget(PARALLAX_FUZZ_TARGET).run;
  run(data, size);
  return 0;
}
