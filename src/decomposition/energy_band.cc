#include "gyrodrift/decomposition/energy_band.h"

#include <cassert>
#include <cmath>
#include <vector>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/statistics.h"

namespace gyrodrift::decomposition {

void ValidateBandConfidence(double confidence, const char* field) {
  if (confidence != 0.95 && confidence != 0.99) {
    ThrowOption(field, FormatValue(confidence),
                "0.95 or 0.99 (the bands fitted by Flandrin et al. 2004)");
  }
}

double RobustLog2NoiseEnergy(const Eigen::Ref<const Eigen::VectorXd>& mode1) {
  std::vector<double> magnitude(static_cast<size_t>(mode1.size()));
  for (Eigen::Index t = 0; t < mode1.size(); ++t) {
    magnitude[static_cast<size_t>(t)] = std::abs(mode1[t]);
  }
  const double median = Median(std::move(magnitude));
  return std::log2(static_cast<double>(mode1.size())) + 2.0 * std::log2(median / 0.6745);
}

double EnergyBand::Log2Upper(int k) const {
  assert(k >= 1 && (confidence == 0.95 || confidence == 0.99));
  const bool high = confidence == 0.99;
  const double a = high ? 0.46 : 0.474;
  const double b = high ? -1.919 : -2.449;
  return log2_e1 - std::log2(0.719) - k * std::log2(2.01) + std::exp2(a * k + b);
}

}  // namespace gyrodrift::decomposition
