// A thermal model's coefficients in physical units (thermal_coefficients.h): rebuilt from them
// and the states' levels, rates and hysteresis, the estimate is the model's own (on a fitted model
// and around any reference inside the calibration range); in equilibrium at the reference, the
// estimate is the bias; beyond a state's range the expansion follows the tangent; a static
// drift's slope comes out in its own units.
#include "gyrodrift/drift/thermal_coefficients.h"

#include <gtest/gtest.h>

#include <cmath>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/features.h"

namespace gyrodrift::drift {
namespace {

// Ramps of 1 K/min between dwells of 40 min, 1 Hz, `hours` long.
Eigen::VectorXd Programme(double hours) {
  const Eigen::Index n = static_cast<Eigen::Index>(hours * 3600);
  Eigen::VectorXd t(n);
  const double levels[] = {20, 60, -20, 40, 0, 50};
  double now = 20.0;
  Eigen::Index i = 0;
  for (int k = 0; i < n; ++k) {
    const double target = levels[k % 6];
    for (; i < n && std::abs(now - target) > 1e-9; ++i) {
      now += std::copysign(std::min(1.0 / 60.0, std::abs(target - now)), target - now);
      t[i] = now;
    }
    for (Eigen::Index d = 0; i < n && d < 2400; ++d, ++i) t[i] = now;
  }
  return t;
}

// The estimate rebuilt from the physical coefficients: the bias, then every term times
// (level - reference)^k, the rate in K/min or H, read from the model's regressors.
Eigen::VectorXd Rebuild(const ThermalRegression& m, const ThermalCoefficients& c,
                        const Eigen::MatrixXd& temperature) {
  const Eigen::MatrixXd x = m.Regressors(temperature);
  Eigen::VectorXd out = Eigen::VectorXd::Constant(x.rows(), c.terms[0].value);
  Eigen::Index col = 1;
  for (int ch = 0; ch < m.channels(); ++ch) {
    const Eigen::ArrayXd u =
        temperature.col(ch).array() - c.reference_c[static_cast<size_t>(ch)];
    for (int k = 1; k <= m.static_power[static_cast<size_t>(ch)]; ++k) {
      out += (c.terms[static_cast<size_t>(col)].value * u.pow(k)).matrix();
      ++col;
    }
  }
  for (const ThermalState& s : m.states) {
    const auto ch = static_cast<size_t>(s.channel);
    // The first power's column is the standardised level itself.
    const Eigen::ArrayXd u =
        m.centre_c[ch] + m.scale_k[ch] * x.col(col).array() - c.reference_c[ch];
    for (int k = 1; k <= m.max_power; ++k) {
      out += (c.terms[static_cast<size_t>(col + k - 1)].value * u.pow(k)).matrix();
    }
    col += m.max_power;
    out += c.terms[static_cast<size_t>(col)].value * 60.0 * x.col(col);  // K/s -> K/min
    ++col;
  }
  if (m.has_hysteresis()) out += c.terms[static_cast<size_t>(col)].value * x.col(col);
  return out;
}

TEST(ThermalCoefficients, RebuildTheEstimateOfAFittedModel) {
  const Eigen::VectorXd t = Programme(8.0);
  Eigen::VectorXd a(t.size()), s(t.size());
  FirstOrderLag(t, 480.0, 1.0, a);
  FirstOrderLag(a, 480.0, 1.0, s);
  Rng rng(5, 0);
  Eigen::VectorXd y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double d = s[i] - 20.0;
    y[i] = 3.0 + 0.05 * d + 4e-4 * d * d - 2e-6 * d * d * d + 30.0 * (a[i] - s[i]) / 480.0 +
           0.05 * rng.Normal();
  }
  ThermalModelOptions o;
  o.hysteresis = HysteresisTerm::kOn;  // a hysteresis column too, whatever the search keeps
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, o);
  ASSERT_FALSE(m.states.empty()) << m.Summary();
  const Eigen::VectorXd estimate = m.Estimate(t);
  const double tolerance = 1e-9 * estimate.cwiseAbs().maxCoeff();
  // Around the calibration's mean (the default), and around references inside the range.
  for (const std::optional<double> reference : {std::optional<double>{}, std::optional<double>{0.0},
                                                 std::optional<double>{45.0}}) {
    const ThermalCoefficients c = PhysicalCoefficients(m, reference);
    ASSERT_EQ(c.terms.size(), static_cast<size_t>(m.coefficients.size()));
    EXPECT_EQ(c.reference_c[0], reference.value_or(m.centre_c[0]));
    EXPECT_LT((Rebuild(m, c, t) - estimate).cwiseAbs().maxCoeff(), tolerance)
        << m.Summary() << " reference " << c.reference_c[0];
    // The bias at the reference is the estimate of a record that sits there.
    EXPECT_NEAR(c.terms[0].value, m.Estimate(Eigen::VectorXd::Constant(5, c.reference_c[0]))[4],
                tolerance);
    EXPECT_EQ(c.terms[0].term, "bias");
  }
  // The units follow the terms: a state's powers per K^k, its rate per K/min.
  const ThermalCoefficients c = PhysicalCoefficients(m, 20.0, {"temp"});
  const size_t first = 1 + static_cast<size_t>(m.static_power[0]);
  EXPECT_EQ(c.terms[first].unit, "/K");
  EXPECT_EQ(c.terms[first].state, 0);
  EXPECT_EQ(c.terms[first + static_cast<size_t>(m.max_power)].unit, "/(K/min)");
  EXPECT_NE(c.terms[1].term.find("temp"), std::string::npos);
  ASSERT_EQ(c.state_range_c.size(), m.states.size());
  EXPECT_GT(c.state_range_c[0].second - c.state_range_c[0].first, 60.0);
  EXPECT_THROW(PhysicalCoefficients(m, std::nan("")), OptionError);
}

// A model made by hand: one second-order state of 100 s, standardised around 25 degC by 10 K,
// seen between 5 and 45 degC, y = 2 + 3 z + 0.5 z^2 - 0.1 z^3 + 120 dz/dt, no linear term.
ThermalRegression HandMade() {
  ThermalRegression m;
  m.rate_hz = 1.0;
  m.order = 2;
  m.max_power = 3;
  m.centre_c = {25.0};
  m.scale_k = {10.0};
  m.static_power = {0};
  m.static_min = {0.0};
  m.static_max = {0.0};
  m.states = {{0, 100.0, -2.0, 2.0}};
  m.coefficients = Eigen::Vector<double, 5>(2.0, 3.0, 0.5, -0.1, 120.0);
  m.covariance = Eigen::VectorXd::Constant(5, 0.04).asDiagonal();
  return m;
}

TEST(ThermalCoefficients, AHandMadeModelInPhysicalUnits) {
  const ThermalRegression m = HandMade();
  // Around the centre: per K^k is the coefficient over 10^k; the rate's per K/min is 120 / 60.
  const ThermalCoefficients c = PhysicalCoefficients(m);
  EXPECT_DOUBLE_EQ(c.terms[0].value, 2.0);
  EXPECT_DOUBLE_EQ(c.terms[1].value, 0.3);
  EXPECT_DOUBLE_EQ(c.terms[2].value, 0.005);
  EXPECT_DOUBLE_EQ(c.terms[3].value, -1e-4);
  EXPECT_DOUBLE_EQ(c.terms[4].value, 2.0);
  EXPECT_DOUBLE_EQ(c.terms[1].sd, 0.2 / 10.0);
  EXPECT_DOUBLE_EQ(c.terms[4].sd, 0.2 / 60.0);
  EXPECT_EQ(c.terms[3].unit, "/K^3");
  EXPECT_EQ(c.state_range_c[0], std::make_pair(5.0, 45.0));
  // Around 35 degC (z0 = 1): the slope of 3 z + 0.5 z^2 - 0.1 z^3 there is 3 + 1 - 0.3 per
  // standard deviation, the curvature 0.5 - 0.3, the bias the polynomial's value.
  const ThermalCoefficients d = PhysicalCoefficients(m, 35.0);
  EXPECT_DOUBLE_EQ(d.terms[0].value, 2.0 + 3.0 + 0.5 - 0.1);
  EXPECT_NEAR(d.terms[1].value, 3.7 / 10.0, 1e-15);
  EXPECT_NEAR(d.terms[2].value, 0.2 / 100.0, 1e-15);
  EXPECT_NEAR(d.terms[3].value, -0.1 / 1000.0, 1e-15);
  // The standard deviations go through the same map: the bias's is the norm of its row times 0.2.
  EXPECT_NEAR(d.terms[0].sd, 0.2 * std::sqrt(1.0 + 1.0 + 1.0 + 1.0), 1e-15);
}

TEST(ThermalCoefficients, BeyondTheRangeTheExpansionFollowsTheTangent) {
  const ThermalRegression m = HandMade();
  // 65 degC is z0 = 4, beyond the range's edge at 2: the powers continue linearly from 2.
  const ThermalCoefficients c = PhysicalCoefficients(m, 65.0);
  EXPECT_DOUBLE_EQ(c.terms[2].value, 0.0);
  EXPECT_DOUBLE_EQ(c.terms[3].value, 0.0);
  EXPECT_NEAR(c.terms[1].value, (3.0 + 0.5 * 2 * 2 - 0.1 * 3 * 4) / 10.0, 1e-15);
  // The bias is the estimate of a record in equilibrium there, and the linear expansion holds on
  // that side of the edge (a record resting beyond it).
  for (const double temperature : {65.0, 50.0, 80.0}) {
    const double estimate = m.Estimate(Eigen::VectorXd::Constant(3, temperature))[2];
    EXPECT_NEAR(c.terms[0].value + c.terms[1].value * (temperature - 65.0), estimate, 1e-12)
        << temperature;
  }
  // Inside the range, around 5 degC (the edge itself), the polynomial reaches the other edge.
  const ThermalCoefficients e = PhysicalCoefficients(m, 5.0);
  const double at_45 = e.terms[0].value + e.terms[1].value * 40.0 + e.terms[2].value * 1600.0 +
                       e.terms[3].value * 64000.0;
  EXPECT_NEAR(at_45, m.Estimate(Eigen::VectorXd::Constant(2, 45.0))[1], 1e-12);
}

TEST(ThermalCoefficients, AStaticSlopeInItsOwnUnits) {
  // y = 4 + 0.7 (T - 20) exactly, fitted by the identification (whatever terms it picks, the
  // static slope around the reference is the sum of the per-K terms, 0.7 units per K).
  const Eigen::VectorXd t = Programme(4.0);
  const Eigen::VectorXd y = (4.0 + 0.7 * (t.array() - 20.0)).matrix();
  ThermalModelOptions o;
  o.hysteresis = HysteresisTerm::kOff;
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, o);
  const ThermalCoefficients c = PhysicalCoefficients(m, 20.0);
  double slope = 0.0;
  for (const PhysicalCoefficient& term : c.terms) {
    if (term.unit == "/K") slope += term.value;
  }
  EXPECT_NEAR(slope, 0.7, 1e-4) << m.Summary();
  EXPECT_NEAR(c.terms[0].value, 4.0, 1e-4) << m.Summary();
}

}  // namespace
}  // namespace gyrodrift::drift
