// Small order statistics shared across modules.
#pragma once

#include <vector>

namespace gyrodrift {

// Median of the values (the mean of the two middle ones for an even count); NaN when empty.
// Takes a copy to reorder. Cost O(n).
double Median(std::vector<double> values);

}  // namespace gyrodrift
