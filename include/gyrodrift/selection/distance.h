// Distances between two probability densities sampled on the same uniform grid.
//
// p and q are densities (not probabilities) at grid points with spacing `step`; integrals are
// Riemann sums over the grid, sum_j (.) * step. With BC = sum sqrt(p q) step (the Bhattacharyya
// coefficient) and m = (p + q) / 2:
//   L2             sqrt(sum (p - q)^2 step)              [0, inf)  Komaty et al., IEEE TIM 2014
//   L1             sum |p - q| step                      [0, 2]
//   Hellinger      sqrt(sum (sqrt p - sqrt q)^2 step / 2) [0, 1]
//   Jensen-Shannon (KL(p||m) + KL(q||m)) / 2, natural log [0, ln 2]  Lin, IEEE TIT 37(1) 1991
//   Bhattacharyya  -ln max(BC, 1e-300)                   [0, 690.8] Bhattacharyya 1943
// All are symmetric in p and q and zero for identical densities. Cost O(grid).
// Units: L2 has the units of sqrt(density), i.e. 1/sqrt(unit of the data); the others are
// dimensionless.
#pragma once

#include <Eigen/Core>
#include <string_view>

namespace gyrodrift::selection {

enum class PdfDistance { kL2, kL1, kHellinger, kJensenShannon, kBhattacharyya };
std::string_view ToString(PdfDistance distance);
// "l2", "l1", "hellinger", "jensen-shannon", "bhattacharyya"; throws UsageError.
PdfDistance PdfDistanceFromString(std::string_view name);

// Distance between densities p and q (same length, same grid, step > 0). Negative values are
// treated as 0.
double Distance(PdfDistance distance, const Eigen::Ref<const Eigen::VectorXd>& p,
                const Eigen::Ref<const Eigen::VectorXd>& q, double step);

}  // namespace gyrodrift::selection
