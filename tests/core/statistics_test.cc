#include "core/statistics.h"

#include <gtest/gtest.h>

namespace parallax {
namespace {

TEST(Statistics, MedianAveragesTheTwoMiddleValuesOfAnEvenCount) {
  EXPECT_EQ(Median({}), 0);
  EXPECT_EQ(Median({3}), 3);
  EXPECT_EQ(Median({5, 1, 3}), 3);
  EXPECT_EQ(Median({4, 1, 3, 2}), 2.5);
}

TEST(Statistics, UpperMedianIsAlwaysOneOfTheValues) {
  EXPECT_EQ(UpperMedian({}), 0);
  EXPECT_EQ(UpperMedian({5, 1, 3}), 3);
  EXPECT_EQ(UpperMedian({4, 1, 3, 2}), 3);
}

}  // namespace
}  // namespace parallax
