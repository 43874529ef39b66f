// Google Benchmark of SIFT matching (sfm/feature_matching.h): one pair of photos with `n`
// random descriptors each; balanced quality keeps up to 4,096 features a photo
// (~5,900 with their second orientations), best 8,192.
#include <random>
#include <vector>

#include <benchmark/benchmark.h>

#include "sfm/feature_matching.h"

namespace parallax {
namespace {

// `count` descriptors of random bytes: the time does not depend on the values.
std::vector<uint8_t> RandomDescriptors(int count, std::mt19937& random) {
  std::uniform_int_distribution<int> byte(0, 90);
  std::vector<uint8_t> descriptors(static_cast<size_t>(count) * kSiftDimensions);
  for (uint8_t& value : descriptors) value = static_cast<uint8_t>(byte(random));
  return descriptors;
}

void BM_MatchSiftFeatures(benchmark::State& state) {
  const int count = static_cast<int>(state.range(0));
  std::mt19937 random(1);
  const std::vector<uint8_t> first = RandomDescriptors(count, random);
  const std::vector<uint8_t> second = RandomDescriptors(count, random);
  for (auto _ : state) {
    benchmark::DoNotOptimize(MatchSiftFeatures({first.data(), count}, {second.data(), count}));
  }
  state.counters["pairs_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                                     benchmark::Counter::kIsRate);
}
BENCHMARK(BM_MatchSiftFeatures)->Arg(2048)->Arg(5900)->Arg(12000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace parallax

BENCHMARK_MAIN();
