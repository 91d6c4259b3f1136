#include "thermal_columns.h"

#include <algorithm>
#include <cmath>

#include "gyrodrift/drift/features.h"

namespace gyrodrift::drift::internal {
namespace {

// The state of `order` cascaded lags of t (and the lag before the last, for its rate), every
// lag restarting at each record's first sample.
void StateOf(const Eigen::Ref<const Eigen::VectorXd>& t, double tau_s, int order, double dt_s,
             const std::vector<Eigen::Index>& record_starts, Eigen::VectorXd& previous,
             Eigen::VectorXd& state) {
  state = t;
  for (int o = 0; o < order; ++o) {
    previous = state;
    ForEachRecord(t.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      FirstOrderLag(previous.segment(begin, length), tau_s, dt_s, state.segment(begin, length));
    });
  }
}

}  // namespace

double TangentPower(double z, int p, double lo, double hi) {
  if (p == 1) return z;
  const double edge = std::clamp(z, lo, hi);
  return std::pow(edge, p) + p * std::pow(edge, p - 1) * (z - edge);
}

// H_w of a state's level (degC) for each half-width w (K): (s - P_w[s]) / w, the play operator
// P_w starting at the level of each record's first sample.
void HysteresisColumns(const Eigen::Ref<const Eigen::VectorXd>& level,
                       const std::vector<double>& widths_k,
                       const std::vector<Eigen::Index>& record_starts,
                       Eigen::Ref<Eigen::MatrixXd> out) {
  for (size_t w = 0; w < widths_k.size(); ++w) {
    const double width = widths_k[w];
    auto col = out.col(static_cast<Eigen::Index>(w));
    ForEachRecord(level.size(), record_starts, [&](Eigen::Index begin, Eigen::Index length) {
      double play = level[begin];
      for (Eigen::Index i = begin; i < begin + length; ++i) {
        play = std::clamp(play, level[i] - width, level[i] + width);
        col[i] = (level[i] - play) / width;
      }
    });
  }
}

// Columns of one state: its standardised level to the powers 1..max_power (the powers >= 2
// continued along their tangent beyond [s.level_min, s.level_max]), its rate (K/s; with
// `within_support`, beyond [s.rate_min, s.rate_max] at s.rate_beyond times its slope), then H_w
// of its level for each of widths_k. With `learn_range` the ranges are first set to the state's
// own (the calibration run). `level` receives the state's level (degC).
void StateColumns(const Eigen::Ref<const Eigen::VectorXd>& t, ThermalState& s, int order,
                  int max_power, double dt_s, double centre, double scale, bool learn_range,
                  bool within_support, const std::vector<Eigen::Index>& record_starts,
                  const std::vector<double>& widths_k, Eigen::Ref<Eigen::MatrixXd> out,
                  Eigen::VectorXd& state) {
  Eigen::VectorXd previous;
  StateOf(t, s.tau_s, order, dt_s, record_starts, previous, state);
  const Eigen::ArrayXd z = (state.array() - centre) / scale;
  auto rate = out.col(max_power);
  rate = (previous - state) / s.tau_s;
  if (learn_range) {
    s.level_min = z.minCoeff();
    s.level_max = z.maxCoeff();
    s.rate_min = rate.minCoeff();
    s.rate_max = rate.maxCoeff();
  }
  if (within_support) {
    for (Eigen::Index i = 0; i < rate.size(); ++i) {
      const double edge = std::clamp(rate[i], s.rate_min, s.rate_max);
      rate[i] = edge + s.rate_beyond * (rate[i] - edge);
    }
  }
  out.col(0) = z.matrix();
  for (int p = 2; p <= max_power; ++p) {
    auto col = out.col(p - 1);
    for (Eigen::Index i = 0; i < z.size(); ++i) {
      col[i] = TangentPower(z[i], p, s.level_min, s.level_max);
    }
  }
  HysteresisColumns(state, widths_k, record_starts,
                    out.middleCols(max_power + 1, static_cast<Eigen::Index>(widths_k.size())));
}

// The static powers 1..powers of a channel's standardised level z (tangent beyond [lo, hi]).
void StaticColumns(const Eigen::Ref<const Eigen::VectorXd>& z, int powers, double lo, double hi,
                   Eigen::Ref<Eigen::MatrixXd> out) {
  for (int p = 1; p <= powers; ++p) {
    auto col = out.col(p - 1);
    for (Eigen::Index i = 0; i < z.size(); ++i) col[i] = TangentPower(z[i], p, lo, hi);
  }
}

}  // namespace gyrodrift::drift::internal
