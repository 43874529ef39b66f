#include "reproject/source_selection.h"

#include <algorithm>
#include <numbers>

#include <gtest/gtest.h>

#include "core/error.h"

namespace parallax {
namespace {

// Cameras on a circle of radius 5 around the origin, looking at it.
PosedCamera RingCamera(double angle_deg) {
  const Camera camera = MakePinholeCamera(1, 320, 240, 280, 280, 160, 120);
  const double a = angle_deg * std::numbers::pi / 180;
  return {camera, LookAt({5 * std::cos(a), 5 * std::sin(a), 1}, {0, 0, 0}, {0, 0, 1})};
}

TEST(SelectSources, PicksTheNearestViewsOnARing) {
  std::vector<PosedCamera> sources;
  for (int k = 0; k < 12; ++k) sources.push_back(RingCamera(30.0 * k));
  SourceSelectionOptions options;
  options.num_sources = 2;
  const std::vector<int> chosen = SelectSources(sources, RingCamera(40), options);
  ASSERT_EQ(chosen.size(), 2u);
  EXPECT_EQ(chosen[0], 1);  // 30 degrees, 10 away.
  EXPECT_EQ(chosen[1], 2);  // 60 degrees, 20 away.
}

TEST(SelectSources, NeverReturnsSourcesThatCannotContribute) {
  const PosedCamera target = RingCamera(0);
  std::vector<PosedCamera> sources = {RingCamera(180)};  // Faces the target across the scene.
  // Behind the target, looking away from the scene.
  sources.push_back({target.camera, LookAt({6, 0, 1}, {12, 0, 1}, {0, 0, 1})});
  sources.push_back(RingCamera(20));
  SourceSelectionOptions options;
  options.num_sources = 3;
  const std::vector<int> chosen = SelectSources(sources, target, options);
  EXPECT_EQ(chosen, std::vector<int>({2, 0}));
  const std::vector<SourceScore> scores = ScoreSources(sources, target, options);
  EXPECT_EQ(scores[1].overlap, 0);
  EXPECT_GT(scores[2].score, scores[0].score);
}

TEST(SelectSources, DiversityPrefersANewDirectionOverANearDuplicate) {
  // Two sources 0.5 degrees apart next to the target, a third 25 degrees away on the other side.
  const std::vector<PosedCamera> sources = {RingCamera(10), RingCamera(10.5), RingCamera(-25)};
  SourceSelectionOptions options;
  options.num_sources = 2;
  options.diversity_angle_deg = 0;
  EXPECT_EQ(SelectSources(sources, RingCamera(0), options), std::vector<int>({0, 1}));
  options.diversity_angle_deg = 10;
  EXPECT_EQ(SelectSources(sources, RingCamera(0), options), std::vector<int>({0, 2}));
  options.diversity_angle_deg = -1;
  EXPECT_THROW(options.Check(), UsageError);
}

TEST(SelectSources, RejectsBadOptions) {
  SourceSelectionOptions options;
  options.num_sources = 0;
  EXPECT_THROW(SelectSources({RingCamera(0)}, RingCamera(10), options), UsageError);
}

}  // namespace
}  // namespace parallax
