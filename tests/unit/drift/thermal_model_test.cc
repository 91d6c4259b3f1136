// The identification of a thermal drift model (thermal_model.h): it finds the state a synthetic
// drift was built from, among the grid's candidates, by cross-validation, and a hysteresis term
// where the drift has one; regimes are told
// apart; beyond the calibration's range the powers continue along their tangent; bad options and
// runs too short to cross-validate are refused; a run without cooling or dwells is flagged.
#include "gyrodrift/drift/thermal_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/features.h"

namespace gyrodrift::drift {
namespace {

// A chamber programme: dwells and ramps between -20 and 60 degC, 1 Hz, `hours` long.
Eigen::VectorXd Programme(double hours) {
  const Eigen::Index n = static_cast<Eigen::Index>(hours * 3600);
  Eigen::VectorXd t(n);
  const double levels[] = {20, 60, -20, 40, 0, 50, -10, 30};
  double now = 20.0;
  Eigen::Index i = 0;
  for (int k = 0; i < n; ++k) {
    const double target = levels[k % 8];
    for (; i < n && std::abs(now - target) > 1e-9; ++i) {  // 1 K/min ramp
      now += std::copysign(std::min(1.0 / 60.0, std::abs(target - now)), target - now);
      t[i] = now;
    }
    for (Eigen::Index d = 0; i < n && d < 2400; ++d, ++i) t[i] = now;  // 40-min dwell
  }
  return t;
}

Eigen::VectorXd State(const Eigen::VectorXd& t, double tau) {
  Eigen::VectorXd a(t.size()), b(t.size());
  FirstOrderLag(t, tau, 1.0, a);
  FirstOrderLag(a, tau, 1.0, b);
  return b;
}

TEST(ThermalModel, FindsTheStateADriftWasBuiltFrom) {
  const Eigen::VectorXd t = Programme(16.0);
  const Eigen::VectorXd s = State(t, 480.0);
  Eigen::VectorXd a(t.size());
  FirstOrderLag(t, 480.0, 1.0, a);
  const Eigen::VectorXd rate = (a - s) / 480.0;  // K/s
  Rng rng(3, 0);
  Eigen::VectorXd drift(t.size()), y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double d = s[i] - 20.0;
    drift[i] = 0.1 + 2e-3 * d + 4e-5 * d * d + 30.0 * rate[i];
    y[i] = drift[i] + 0.2 * rng.Normal();
  }
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  ASSERT_FALSE(m.states.empty()) << m.Summary();
  bool found = false;
  for (const ThermalState& st : m.states) found = found || std::abs(st.tau_s - 480.0) < 1e-9;
  EXPECT_TRUE(found) << m.Summary();
  EXPECT_TRUE(m.report.warnings.empty()) << m.report.Summary();
  EXPECT_EQ(m.report.folds, 8);
  EXPECT_GT(m.report.skill, 0.9);
  const Eigen::MatrixXd e = m.EstimateWithSd(t);
  const double rms = std::sqrt((e.col(0) - drift).squaredNorm() / static_cast<double>(t.size()));
  EXPECT_LT(rms, 0.01) << m.Summary();
  EXPECT_GT(e.col(1).minCoeff(), 0.0);
  EXPECT_EQ(m.RegressorNames().size(), static_cast<size_t>(m.coefficients.size()));
  // The same data, the same model (no randomness without the nonlinear option).
  EXPECT_EQ(IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}).coefficients, m.coefficients);
}

// Two calibration runs (the second starting hot, away from where the first ended), fitted as two
// records: each state restarts with its run, as the gyro's did, so the model is the one a single
// long run gives; run across the break, the lags would carry a step that no gyro saw.
TEST(ThermalModel, SeveralRecordsRestartTheirStates) {
  const Eigen::VectorXd a = Programme(8.0);
  const Eigen::VectorXd b = 40.0 - 0.5 * (Programme(8.0).array() - 20.0);
  auto drift_of = [](const Eigen::VectorXd& t) {
    const Eigen::VectorXd s = State(t, 480.0);
    Eigen::VectorXd lag(t.size());
    FirstOrderLag(t, 480.0, 1.0, lag);
    const Eigen::VectorXd rate = (lag - s) / 480.0;
    return Eigen::VectorXd(0.1 + 2e-3 * (s.array() - 20.0) + 4e-5 * (s.array() - 20.0).square() +
                           30.0 * rate.array());
  };
  const Eigen::Index n = a.size();
  Eigen::VectorXd t(2 * n), drift(2 * n), y(2 * n);
  t << a, b;
  drift << drift_of(a), drift_of(b);
  Rng rng(5, 0);
  for (Eigen::Index i = 0; i < y.size(); ++i) y[i] = drift[i] + 0.2 * rng.Normal();
  const std::vector<Eigen::Index> starts{n};

  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.record_starts = starts});
  EXPECT_EQ(m.report.records, 2);
  EXPECT_NE(m.report.Summary().find("in 2 records"), std::string::npos) << m.report.Summary();
  auto rms = [&](const Eigen::VectorXd& e) {
    return std::sqrt((e - drift).squaredNorm() / static_cast<double>(drift.size()));
  };
  const double with_records = rms(m.Estimate(t, starts));
  EXPECT_LT(with_records, 0.01) << m.Summary();
  // Each record estimated on its own is the records' estimate, to the bit.
  const Eigen::VectorXd whole = m.Estimate(t, starts);
  EXPECT_EQ(m.Estimate(b), whole.tail(n));
  EXPECT_EQ(m.Estimate(a), whole.head(n));
  // Fitted as one run, the states carry the 20-K step across the break: a worse model.
  const ThermalRegression joined = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  EXPECT_EQ(joined.report.records, 1);
  EXPECT_GT(rms(joined.Estimate(t)), 2.0 * with_records) << joined.Summary();
  // Record starts out of order or out of range are refused.
  EXPECT_THROW(IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.record_starts = {n, n}}),
               DataError);
  EXPECT_THROW(m.Estimate(t, {0}), DataError);
  EXPECT_THROW(m.Estimate(t, {2 * n}), DataError);
}

// The play operator of half-width w (K) of x, (x - play) / w, started at x[0].
Eigen::VectorXd Play(const Eigen::VectorXd& x, double w) {
  Eigen::VectorXd h(x.size());
  double play = x[0];
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    play = std::clamp(play, x[i] - w, x[i] + w);
    h[i] = (x[i] - play) / w;
  }
  return h;
}

// A gyro whose bias on cooling sits 0.16 deg/h below its bias on heating through the same
// temperature (a backlash of 1 K on the state's level): the identification finds the term, its
// state and width, and without it the estimate is several times worse.
TEST(ThermalModel, FindsAHysteresisTheDriftHas) {
  const Eigen::VectorXd t = Programme(16.0);
  const Eigen::VectorXd s = State(t, 480.0);
  Eigen::VectorXd a(t.size());
  FirstOrderLag(t, 480.0, 1.0, a);
  const Eigen::VectorXd hysteresis = Play(s, 1.0);
  Rng rng(4, 0);
  Eigen::VectorXd drift(t.size()), y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double d = s[i] - 20.0;
    drift[i] = 0.1 + 2e-3 * d + 4e-5 * d * d + 30.0 * (a[i] - s[i]) / 480.0 + 0.08 * hysteresis[i];
    y[i] = drift[i] + 0.2 * rng.Normal();
  }
  auto rms = [&](const Eigen::VectorXd& e) {
    return std::sqrt((e - drift).squaredNorm() / static_cast<double>(drift.size()));
  };
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  EXPECT_TRUE(m.report.hysteresis_tried);
  ASSERT_TRUE(m.has_hysteresis()) << m.Summary();
  EXPECT_EQ(m.hysteresis_width_k, 1.0);
  EXPECT_EQ(m.states[static_cast<size_t>(m.hysteresis_state)].tau_s, 480.0) << m.Summary();
  EXPECT_NEAR(m.coefficients[m.coefficients.size() - 1], 0.08, 0.01);
  EXPECT_EQ(m.RegressorNames().back(), "H(L2(T1; 480 s); 1 K)");
  EXPECT_NE(m.Summary().find("hysteresis of the 480-s state (play 1 K)"), std::string::npos)
      << m.Summary();
  const double with_term = rms(m.Estimate(t));
  EXPECT_LT(with_term, 0.01) << m.Summary();

  ThermalModelOptions off;
  off.hysteresis = HysteresisTerm::kOff;
  const ThermalRegression without = IdentifyThermalModel(t, y, 1.0, off);
  EXPECT_FALSE(without.report.hysteresis_tried);
  EXPECT_FALSE(without.has_hysteresis());
  EXPECT_GT(rms(without.Estimate(t)), 3.0 * with_term) << without.Summary();

  // The play starts afresh with every record, as the lags do.
  const Eigen::Index half = t.size() / 2;
  EXPECT_EQ(m.Estimate(t, {half}).tail(t.size() - half), m.Estimate(t.tail(t.size() - half)));
}

TEST(ThermalModel, HysteresisIsTriedOnLongRunsOrWhenAsked) {
  ThermalModelOptions o;
  EXPECT_EQ(o.hysteresis, HysteresisTerm::kAuto);
  EXPECT_FALSE(o.TriesHysteresis(kHysteresisAutoMinDurationS - 1.0));
  EXPECT_TRUE(o.TriesHysteresis(kHysteresisAutoMinDurationS));
  o.hysteresis = HysteresisTerm::kOn;
  EXPECT_TRUE(o.TriesHysteresis(3600.0));
  o.hysteresis = HysteresisTerm::kOff;
  EXPECT_FALSE(o.TriesHysteresis(1e6));
  o.hysteresis = HysteresisTerm::kAuto;
  o.hysteresis_widths_k.clear();
  EXPECT_FALSE(o.TriesHysteresis(1e6));  // nothing to try
  EXPECT_NO_THROW(o.Validate());
  o.hysteresis = HysteresisTerm::kOn;
  EXPECT_THROW(o.Validate(), OptionError);  // on, with no width
  o.hysteresis_widths_k = {1.0, 0.0};
  EXPECT_THROW(o.Validate(), OptionError);
  o.hysteresis_widths_k.assign(9, 1.0);
  EXPECT_THROW(o.Validate(), OptionError);
  EXPECT_EQ(HysteresisTermFromString("on"), HysteresisTerm::kOn);
  EXPECT_EQ(ToString(HysteresisTerm::kAuto), "auto");
  EXPECT_THROW(HysteresisTermFromString("sometimes"), OptionError);
  // An 8-h run does not try it by default; the report says so.
  const Eigen::VectorXd t = Programme(8.0);
  const Eigen::VectorXd y = 0.01 * (State(t, 240.0).array() - 20.0);
  EXPECT_FALSE(IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}).report.hysteresis_tried);
}

TEST(ThermalModel, SegmentsTellRampsFromDwells) {
  Eigen::VectorXd t(7200);
  for (Eigen::Index i = 0; i < 7200; ++i) {
    t[i] = i < 2400 ? 20.0 : i < 4800 ? 20.0 + (i - 2400) / 60.0 : 60.0;  // dwell, ramp, dwell
  }
  const std::vector<ThermalSegment> s = Segments(t, 1.0, 0.1);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_FALSE(s[0].ramp);
  EXPECT_TRUE(s[1].ramp);
  EXPECT_FALSE(s[2].ramp);
  EXPECT_EQ(s.front().begin, 0);
  EXPECT_EQ(s.back().end, 7200);
  EXPECT_NEAR(static_cast<double>(s[1].begin), 2400.0, 30.0);
}

TEST(ThermalModel, PowersContinueAlongTheirTangentBeyondTheCalibrationRange) {
  const Eigen::VectorXd t = Programme(8.0);
  Rng rng(4, 0);
  Eigen::VectorXd y(t.size());
  const Eigen::VectorXd s = State(t, 240.0);
  for (Eigen::Index i = 0; i < t.size(); ++i) y[i] = 1e-4 * std::pow(s[i] - 20.0, 2) + 0.05 * rng.Normal();
  ThermalModelOptions o;
  o.max_states = 1;
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, o);
  ASSERT_EQ(m.states.size(), 1u) << m.Summary();
  const ThermalState& st = m.states[0];
  // A record in equilibrium far above the range: the state's standardised level is z; its
  // square column is the tangent at the range's top, not z^2.
  const double hot = 150.0;
  const Eigen::MatrixXd x = m.Regressors(Eigen::VectorXd::Constant(10, hot));
  const double z = (hot - m.centre_c[0]) / m.scale_k[0];
  ASSERT_GT(z, st.level_max);
  const Eigen::Index first = 1 + m.static_power[0];
  EXPECT_NEAR(x(9, first), z, 1e-12);
  EXPECT_NEAR(x(9, first + 1), st.level_max * st.level_max + 2 * st.level_max * (z - st.level_max),
              1e-9);
  // Inside the range the columns are the plain powers.
  const double mid = 0.5 * (st.level_min + st.level_max);
  const Eigen::MatrixXd inside =
      m.Regressors(Eigen::VectorXd::Constant(10, m.centre_c[0] + mid * m.scale_k[0]));
  EXPECT_NEAR(inside(9, first + 1), mid * mid, 1e-9);
}

TEST(ThermalModel, ARunWithoutCoolingOrDwellsIsFlaggedAndBadInputRefused) {
  Eigen::VectorXd t(3600), y(3600);
  Rng rng(5, 0);
  for (Eigen::Index i = 0; i < 3600; ++i) {
    t[i] = 20.0 + i / 360.0;  // one slow ramp, 10 K
    y[i] = 0.01 * t[i] + 0.1 * rng.Normal();
  }
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  const std::string all = [&] {
    std::string s;
    for (const std::string& w : m.report.warnings) s += w + "\n";
    return s;
  }();
  EXPECT_NE(all.find("spans only"), std::string::npos) << all;
  EXPECT_NE(all.find("no cooling ramp"), std::string::npos) << all;
  EXPECT_NE(all.find("no dwell"), std::string::npos) << all;
  // The length the advice asks for is one whose grid holds a long enough state: the grid goes in
  // steps of sqrt(2) from 30 s, and 960 s (lag 1920 s) is the first above 900 s, at 1/16 of 4.27 h.
  std::string advice;
  for (const std::string& a : m.report.advice) advice += a + "\n";
  EXPECT_NE(advice.find("short run: 1 h lets states lag by 339 s at most; 4.27 h reaches 1920 s"),
            std::string::npos)
      << advice;
  const ThermalModelOptions o;
  const std::vector<double> grid = o.Grid(4.27 * 3600.0);
  EXPECT_DOUBLE_EQ(grid.back(), 960.0);

  ThermalModelOptions bad;
  bad.max_states = 5;
  EXPECT_THROW(IdentifyThermalModel(t, y, 1.0, bad), OptionError);
  bad = {};
  bad.longest_tau_s = 10.0;  // below the shortest
  EXPECT_THROW(bad.Validate(), OptionError);
  EXPECT_THROW(IdentifyThermalModel(t.head(20), y.head(20), 1.0, ThermalModelOptions{}),
               DataError);
  EXPECT_THROW(IdentifyThermalModel(Eigen::VectorXd::Constant(3600, 20.0), y, 1.0,
                                    ThermalModelOptions{}),
               DataError);
  Eigen::VectorXd with_nan = y;
  with_nan[100] = std::nan("");
  EXPECT_THROW(IdentifyThermalModel(t, with_nan, 1.0, ThermalModelOptions{}), DataError);
}

// A heat-up calibration (cold soak, one ramp up at 0.6 K/min, a hold) of a gyro whose drift
// follows a lagged level, a gradient (sensor less coil: a lag difference, whose sign follows the
// direction of the change) and a Shupe rate term.
struct HeatUp {
  Eigen::VectorXd t, drift;
};
HeatUp HeatUpRun(const Eigen::VectorXd& t) {
  const Eigen::VectorXd coil = State(t, 600.0);
  Eigen::VectorXd a(t.size());
  FirstOrderLag(t, 600.0, 1.0, a);
  HeatUp h{t, Eigen::VectorXd(t.size())};
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double d = coil[i] - 20.0;
    h.drift[i] = 0.1 + 3e-3 * d + 5e-5 * d * d + 0.01 * (t[i] - coil[i]) +
                 60.0 * (a[i] - coil[i]) / 600.0;
  }
  return h;
}

// What a one-way calibration cannot identify stays out: no lag difference (two states, or a state
// beside the static term), and a rate of the sign it never saw (cooling) moves beyond the edge of
// the rates it did see at half its slope, with the standard deviation widened by what that left
// out. The run gets its advice. On a mission that cools, the estimate is no worse than doing
// nothing.
TEST(ThermalModel, AOneWayHeatUpTakesNoLagDifferenceAndHalvesCoolingRates) {
  const Eigen::Index n = 8 * 3600;
  Eigen::VectorXd cal(n);
  for (Eigen::Index i = 0; i < n; ++i) cal[i] = std::min(60.0, -20.0 + 0.01 * std::max<Eigen::Index>(0, i - 2700));
  const HeatUp h = HeatUpRun(cal);
  Rng rng(8, 0);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) y[i] = h.drift[i] + 0.2 * rng.Normal();
  const ThermalRegression m = IdentifyThermalModel(cal, y, 1.0, ThermalModelOptions{});
  EXPECT_LE(m.states.size(), 1u) << m.Summary();
  EXPECT_FALSE(!m.states.empty() && m.static_power[0] > 0) << m.Summary();
  std::string advice;
  for (const std::string& a : m.report.advice) advice += a + "\n";
  EXPECT_NE(advice.find("no cooling: add a ramp down"), std::string::npos) << advice;
  for (const ThermalState& s : m.states) {
    EXPECT_TRUE(std::isfinite(s.rate_min)) << "cooling was never seen";
    EXPECT_TRUE(std::isinf(s.rate_max)) << "heating was";
  }
  // A mission between the calibration's ends that heats and cools at 1 K/min.
  const Eigen::VectorXd mission = Programme(8.0).array() * 0.5 + 10.0;
  const Eigen::VectorXd truth = HeatUpRun(mission).drift;
  const Eigen::MatrixXd e = m.EstimateWithSd(mission);
  const double none = std::sqrt(truth.squaredNorm() / static_cast<double>(truth.size()));
  const double after = std::sqrt((e.col(0) - truth).squaredNorm() / static_cast<double>(truth.size()));
  EXPECT_LT(after, none) << m.Summary();
  // Where the mission cools beyond the calibration's edge, the state's rate column moves at half
  // the free rate's slope; within the rates the run showed, it is the free rate.
  ASSERT_EQ(m.states.size(), 1u) << m.Summary();
  const ThermalState& s = m.states[0];
  EXPECT_EQ(s.rate_beyond, 0.5);
  const Eigen::Index rate = 1 + m.static_power[0] + m.max_power;
  const Eigen::VectorXd kept = m.Regressors(mission).col(rate);
  const Eigen::VectorXd free = m.Regressors(mission, {}, /*within_support=*/false).col(rate);
  EXPECT_LT(free.minCoeff(), s.rate_min);
  for (Eigen::Index i = 0; i < free.size(); ++i) {
    const double want = free[i] < s.rate_min ? s.rate_min + 0.5 * (free[i] - s.rate_min) : free[i];
    ASSERT_NEAR(kept[i], want, 1e-15) << "sample " << i;
  }
  // The standard deviation holds what the half left out, either way.
  const Eigen::VectorXd unheld =
      m.Regressors(mission, {}, false) * m.coefficients - m.Regressors(mission) * m.coefficients;
  EXPECT_TRUE((e.col(1).array() >= unheld.array().abs() - 1e-12).all());
}

// A step between two holds shows the drift at two temperatures and the few minutes between: the
// levels enter linearly (a curve there would rest on the step's settling alone), the run is told
// so with its advice, and a mission between the holds is compensated better than not at all. A
// heat-up whose ramp crosses the middle half of its range in 30 min or more keeps its powers.
TEST(ThermalModel, AStepBetweenTwoHoldsGetsALine) {
  const Eigen::Index n = 8 * 3600;
  Eigen::VectorXd step(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    step[i] =
        std::min(40.0, 2.0 / 60.0 * static_cast<double>(std::max<Eigen::Index>(0, i - 14400)));
  }
  auto drift = [](const Eigen::VectorXd& t) {
    const Eigen::VectorXd coil = State(t, 600.0);
    return Eigen::VectorXd(0.1 + 4e-3 * (coil.array() - 20.0) +
                           5e-5 * (coil.array() - 20.0).square() + 0.02 * (t - coil).array());
  };
  Rng rng(12, 0);
  Eigen::VectorXd y = drift(step);
  for (Eigen::Index i = 0; i < n; ++i) y[i] += 0.1 * rng.Normal();
  const ThermalRegression m = IdentifyThermalModel(step, y, 1.0, ThermalModelOptions{});
  EXPECT_EQ(m.max_power, 1) << m.Summary();
  std::string warnings, advice;
  for (const std::string& w : m.report.warnings) warnings += w + "\n";
  for (const std::string& a : m.report.advice) advice += a + "\n";
  EXPECT_NE(warnings.find("min in the middle half of its temperature range (30 min show a curve)"),
            std::string::npos)
      << warnings;
  EXPECT_NE(advice.find("mid-range: dwell 30 min or more"), std::string::npos) << advice;
  const Eigen::VectorXd mission = Programme(8.0).array() * 0.25 + 15.0;  // 10..30 degC
  const Eigen::VectorXd truth = drift(mission);
  const Eigen::VectorXd e = m.Estimate(mission);
  const double none = std::sqrt(truth.squaredNorm() / static_cast<double>(n));
  EXPECT_LT(std::sqrt((e - truth).squaredNorm() / static_cast<double>(n)), 0.5 * none)
      << m.Summary();

  Eigen::VectorXd ramp(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    ramp[i] = std::min(40.0, 0.6 / 60.0 * static_cast<double>(std::max<Eigen::Index>(0, i - 3600)));
  }
  EXPECT_EQ(IdentifyThermalModel(ramp, drift(ramp), 1.0, ThermalModelOptions{}).max_power, 3);
}

// Two plateaus logged apart show no response to change: no lag state, a line between them. A
// run that heats and cools slower than the ramp threshold shows no direction: no lag difference
// (two states, or a state beside T) and no hysteresis term, as in a one-way run.
TEST(ThermalModel, HoldsTakeNoStateAndARunWithoutRampsNoLagDifference) {
  const Eigen::Index n = 4 * 3600;
  Eigen::VectorXd t(2 * n), y(2 * n);
  Rng rng(13, 0);
  for (Eigen::Index i = 0; i < 2 * n; ++i) {
    t[i] = (i < n ? 0.0 : 40.0) + 0.05 * rng.Normal();
    y[i] = 0.1 + 4e-3 * (t[i] - 20.0) + 0.1 * rng.Normal();
  }
  const ThermalRegression holds =
      IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.record_starts = {n}});
  EXPECT_TRUE(holds.states.empty()) << holds.Summary();
  EXPECT_EQ(holds.max_power, 1) << holds.Summary();

  Eigen::VectorXd slow(4 * n);  // 0 -> 40 degC at 0.1 K/min, 1 h at 40, back down, hold at 0
  for (Eigen::Index i = 0; i < slow.size(); ++i) {
    const double sec = static_cast<double>(i);
    slow[i] =
        sec < 27600.0 ? std::min(40.0, sec / 600.0) : std::max(0.0, 40.0 - (sec - 27600.0) / 600.0);
  }
  const Eigen::VectorXd coil = State(slow, 900.0);
  Eigen::VectorXd ys(slow.size());
  for (Eigen::Index i = 0; i < slow.size(); ++i) {
    ys[i] = 0.1 + 3e-3 * (coil[i] - 20.0) + 0.02 * (slow[i] - coil[i]) + 0.1 * rng.Normal();
  }
  const ThermalRegression m = IdentifyThermalModel(slow, ys, 1.0, ThermalModelOptions{});
  EXPECT_LT(m.report.max_heating_k_per_min, 0.2) << m.report.Summary();
  EXPECT_LE(m.states.size(), 1u) << m.Summary();
  EXPECT_FALSE(!m.states.empty() && m.static_power[0] > 0) << m.Summary();
  EXPECT_FALSE(m.has_hysteresis()) << m.Summary();
}

// The guarantee: a gyro without temperature dependence gets the constant, whatever the
// temperature did; the report says so.
TEST(ThermalModel, NoTemperatureDependenceGivesTheConstant) {
  const Eigen::VectorXd t = Programme(8.0);
  Rng rng(9, 0);
  Eigen::VectorXd y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) y[i] = 0.3 + 0.2 * rng.Normal();
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  EXPECT_EQ(m.report.level, CalibrationReport::kConstant) << m.report.Summary();
  EXPECT_TRUE(m.states.empty());
  EXPECT_EQ(m.static_power[0], 0);
  ASSERT_EQ(m.coefficients.size(), 1);
  EXPECT_NEAR(m.coefficients[0], 0.3, 0.01);
  EXPECT_NE(m.report.Summary().find("structure: the constant"), std::string::npos)
      << m.report.Summary();
}

// A gyro with a plain static cubic gets static powers of T, not lag states.
TEST(ThermalModel, AStaticDriftGetsStaticPowers) {
  const Eigen::VectorXd t = Programme(8.0);
  Rng rng(10, 0);
  Eigen::VectorXd y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    const double d = t[i] - 20.0;
    y[i] = 0.1 + 4e-3 * d + 1e-4 * d * d + 0.05 * rng.Normal();
  }
  const ThermalRegression m = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  EXPECT_EQ(m.report.level, CalibrationReport::kStatic) << m.report.Summary();
  EXPECT_GE(m.static_power[0], 2);
  EXPECT_EQ(m.RegressorNames()[2], "T1^2");
}

// A duty-cycled log: 5 s of every 300 s logged, the rest made up across the gaps. Samples not
// logged never reach the fit (garbage there changes nothing), and the model is the continuous
// log's to within its noise.
TEST(ThermalModel, SamplesNotLoggedAreNotFitted) {
  const Eigen::VectorXd t = Programme(8.0);
  const Eigen::VectorXd s = State(t, 480.0);
  Rng rng(11, 0);
  Eigen::VectorXd drift(t.size()), y(t.size());
  std::vector<bool> logged(static_cast<size_t>(t.size()));
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    drift[i] = 0.1 + 3e-3 * (s[i] - 20.0);
    y[i] = drift[i] + 0.02 * rng.Normal();
    logged[static_cast<size_t>(i)] = i % 300 < 5;
  }
  const ThermalRegression m =
      IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.logged = logged});
  Eigen::VectorXd garbage = y;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    if (!logged[static_cast<size_t>(i)]) garbage[i] = 1e3;
  }
  const ThermalRegression g =
      IdentifyThermalModel(t, garbage, 1.0, ThermalModelOptions{}, {.logged = logged});
  EXPECT_EQ(g.coefficients, m.coefficients);
  // Not read at all: NaN there gives the same model; NaN at a logged sample is refused, by name.
  Eigen::VectorXd holes = y;
  for (Eigen::Index i = 0; i < t.size(); ++i) {
    if (!logged[static_cast<size_t>(i)]) holes[i] = std::numeric_limits<double>::quiet_NaN();
  }
  EXPECT_EQ(
      IdentifyThermalModel(t, holes, 1.0, ThermalModelOptions{}, {.logged = logged}).coefficients,
      m.coefficients);
  holes[300] = std::numeric_limits<double>::quiet_NaN();  // row 301, the 6th logged
  try {
    IdentifyThermalModel(t, holes, 1.0, ThermalModelOptions{}, {.logged = logged});
    ADD_FAILURE() << "a NaN at a logged sample was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("target sample 301 (logged) is nan"), std::string::npos)
        << e.what();
  }
  const double rms =
      std::sqrt((m.Estimate(t) - drift).squaredNorm() / static_cast<double>(t.size()));
  EXPECT_LT(rms, 0.02) << m.Summary();
  EXPECT_THROW(IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.logged = logged, .nonlinear = true}),
               UsageError);
  EXPECT_THROW(IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{}, {.logged = {true}}),
               DataError);
}

// A log of which fewer than half the rows were logged (duty-cycled) gets the ridge worth 16 logged
// samples and, its logged samples short of 12 h, no hysteresis term; a continuous 16-h log gets
// neither ridge nor the rule (docs/drift.md 4.8).
TEST(ThermalModel, AMostlyUnloggedRunIsShrunkAndTriesNoHysteresis) {
  const Eigen::VectorXd t = Programme(16.0);
  const Eigen::VectorXd s = State(t, 480.0);
  Rng rng(12, 0);
  Eigen::VectorXd y(t.size());
  for (Eigen::Index i = 0; i < t.size(); ++i)
    y[i] = 0.1 + 3e-3 * (s[i] - 20.0) + 0.02 * rng.Normal();
  auto logged_where = [&](auto keep) {
    std::vector<bool> logged(static_cast<size_t>(t.size()));
    for (Eigen::Index i = 0; i < t.size(); ++i) logged[static_cast<size_t>(i)] = keep(i);
    return logged;
  };
  const ThermalRegression bursts =
      IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{},
                           {.logged = logged_where([](Eigen::Index i) { return i % 300 < 5; })});
  EXPECT_EQ(bursts.report.prior_samples, 16.0);
  EXPECT_FALSE(bursts.report.hysteresis_tried);
  EXPECT_NE(bursts.report.Summary().find("ridge worth 16 logged samples"), std::string::npos);
  const ThermalRegression most =
      IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{},
                           {.logged = logged_where([](Eigen::Index i) { return i % 10 < 6; })});
  EXPECT_EQ(most.report.prior_samples, 0.0);
  EXPECT_EQ(most.report.Summary().find("ridge"), std::string::npos);
  const ThermalRegression all = IdentifyThermalModel(t, y, 1.0, ThermalModelOptions{});
  EXPECT_EQ(all.report.prior_samples, 0.0);
  EXPECT_TRUE(all.report.hysteresis_tried);
}

TEST(ThermalModel, GridFollowsTheRunLength) {
  const ThermalModelOptions o;
  const std::vector<double> grid16 = o.Grid(16 * 3600.0);
  EXPECT_DOUBLE_EQ(grid16.front(), 30.0);
  EXPECT_LE(grid16.back(), 3600.0);  // 1/16 of the run
  EXPECT_GT(grid16.back() * std::sqrt(2.0), 3600.0);
  EXPECT_LT(o.Grid(3600.0).size(), grid16.size());
}

}  // namespace
}  // namespace gyrodrift::drift
