// The columns of the thermal model's design (thermal_model.h): a channel's static powers, a lag
// state's level powers, its rate and hysteresis terms. Shared by the identification's candidate
// design and a fitted model's Regressors. Private to src/drift.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "gyrodrift/drift/thermal_model.h"

namespace gyrodrift::drift::internal {

// z to the power p, continued along its tangent beyond [lo, hi] for p >= 2.
double TangentPower(double z, int p, double lo, double hi);

// H_w of a state's level (degC) for each half-width w (K): (s - P_w[s]) / w, the play operator
// P_w starting at the level of each record's first sample.
void HysteresisColumns(const Eigen::Ref<const Eigen::VectorXd>& level,
                       const std::vector<double>& widths_k,
                       const std::vector<Eigen::Index>& record_starts,
                       Eigen::Ref<Eigen::MatrixXd> out);

// Columns of one state: its standardised level to the powers 1..max_power (the powers >= 2
// continued along their tangent beyond [s.level_min, s.level_max]), its rate (K/s; with
// `within_support`, beyond [s.rate_min, s.rate_max] at s.rate_beyond times its slope), then H_w
// of its level for each of widths_k. With `learn_range` the ranges are first set to the state's
// own (the calibration run). `level` receives the state's level (degC).
void StateColumns(const Eigen::Ref<const Eigen::VectorXd>& t, ThermalState& s, int order,
                  int max_power, double dt_s, double centre, double scale, bool learn_range,
                  bool within_support, const std::vector<Eigen::Index>& record_starts,
                  const std::vector<double>& widths_k, Eigen::Ref<Eigen::MatrixXd> out,
                  Eigen::VectorXd& state);

// The static powers 1..powers of a channel's standardised level z (tangent beyond [lo, hi]).
void StaticColumns(const Eigen::Ref<const Eigen::VectorXd>& z, int powers, double lo, double hi,
                   Eigen::Ref<Eigen::MatrixXd> out);

}  // namespace gyrodrift::drift::internal
