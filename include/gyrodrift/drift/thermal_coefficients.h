// A fitted thermal model's coefficients in physical units (thermal_model.h stores them on the
// standardised levels z = (T - centre_c) / scale_k, so that a coefficient of 1116 meant 1116
// target units per standard deviation of the calibration's temperature, 16.2 K there).
//
// Around reference temperatures T0 (one per channel; by default the calibration's means), with
// u = T - T0 of a channel's temperature or a state's level (K), the model reads
//   drift = bias(T0) + sum_c sum_{k=1..Q} a_ck u_c^k + sum_j [ sum_{k=1..P} c_jk u_j^k
//           + r_j ds_j/dt ] [ + h H ]
// where bias(T0) is the estimate with every state in equilibrium at T0 (no rate, no hysteresis),
// a_ck and c_jk the k-th Taylor coefficients of a channel's static powers and of a state's powers
// at T0 (target units per K^k),
// r_j in target units per K/min and h in target units (H in [-1, 1]). The expansion is exact
// while each level stays on one side of the edges of its calibration range (inside it:
// the polynomial; beyond an edge the powers >= 2 continue along their tangent, so about a T0
// beyond an edge the terms of order >= 2 are zero and the expansion holds on that side).
// A nonlinear correction (ThermalRegression::correction) is not part of the coefficients.
// Standard deviations follow from the coefficient covariance through the same linear map.
// Cost O(M^2) for M coefficients.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "gyrodrift/drift/thermal_model.h"

namespace gyrodrift::drift {

// One coefficient in physical units.
struct PhysicalCoefficient {
  std::string term;  // RegressorNames' name ("1" is the bias at the reference)
  int power = 0;     // of u in the term: 0 bias or hysteresis, 1..3 levels, 1 for rates
  int state = -1;    // index in model.states of its state (levels, rate, hysteresis), else -1
  // The unit after the target's: "" (target units), "/K", "/K^2", "/K^3", "/(K/min)".
  std::string unit;
  double value = 0.0;
  double sd = 0.0;  // from the coefficient covariance
};

struct ThermalCoefficients {
  std::vector<double> reference_c;          // T0 per channel, degC
  std::vector<PhysicalCoefficient> terms;   // in the order of RegressorNames
  // Per state: its level's calibration range, degC (where the expansion is a polynomial).
  std::vector<std::pair<double, double>> state_range_c;
  // physical values = transform * model.coefficients (M x M).
  Eigen::MatrixXd transform;
};

// The coefficients of a valid model around `reference_c` (one value for every channel, degC,
// finite) or, unset, each channel's calibration mean (centre_c). `channel_names` as
// RegressorNames. Throws OptionError for a non-finite reference.
ThermalCoefficients PhysicalCoefficients(const ThermalRegression& model,
                                         std::optional<double> reference_c = std::nullopt,
                                         const std::vector<std::string>& channel_names = {});

}  // namespace gyrodrift::drift
