#pragma once
// Order statistics shared by the stages. Each takes its values by copy (it reorders them).
#include <vector>

namespace parallax {

// The median: the middle value, or the mean of the two middle values of an even count.
// 0 for no values.
double Median(std::vector<double> values);

// The value at index size/2 of the sorted values (the upper of the two middle values of an
// even count): always one of the values. 0 for no values.
double UpperMedian(std::vector<double> values);

}  // namespace parallax
