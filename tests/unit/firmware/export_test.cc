// Firmware export: the coefficients JSON, evaluated with the equation docs/firmware.md documents,
// reproduces drift::EstimateDrift (one and two channels, ms-elm, a reference temperature, a
// hysteresis term, several axes); rendering is deterministic; the C header has the documented shape; models that cannot
// run in firmware and bad options are refused with one line naming the reason. The C header's
// arithmetic is checked by compiling it: tests/cli/export_test.cc.
#include "gyrodrift/firmware/export.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <cmath>
#include <filesystem>
#include <functional>
#include <numeric>
#include <memory>
#include <numbers>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/features.h"
#include "gyrodrift/io/files.h"
#include "support/firmware_driver.h"
#include "support/test_support.h"

namespace gyrodrift::firmware {
namespace {

using drift::Method;
using io::LoadedModel;
using io::ParseModelFile;
using io::WriteFileAtomically;
using drift::Mode;
using nlohmann::json;

struct Log {
  Eigen::VectorXd rate;
  Eigen::MatrixXd temperature;  // case, board (a lag of the case, warmer)
};

// Temperature swings, a drift following a lagged case temperature, its rate and the board, and
// with hysteresis_dph a bias that differs between heating and cooling (a backlash of 1 K on the
// lagged temperature).
Log MakeLog(Eigen::Index n, std::uint64_t seed, double offset_c = 0.0,
            double hysteresis_dph = 0.0) {
  Log log{Eigen::VectorXd(n), Eigen::MatrixXd(n, 2)};
  Rng rng(seed, 0);
  double lagged = 20.0 + offset_c, play = lagged;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / static_cast<double>(n);
    log.temperature(t, 0) = offset_c + 20.0 + 15.0 * std::sin(2 * std::numbers::pi * 1.5 * x);
    const double previous = lagged;
    lagged += (log.temperature(t, 0) - lagged) / 40.0;
    play = std::clamp(play, lagged - 1.0, lagged + 1.0);
    log.rate[t] = 0.01 * (lagged - 20.0) + 0.0004 * (lagged - 20.0) * (lagged - 20.0) +
                  4.0 * (lagged - previous) + hysteresis_dph * (lagged - play) +
                  0.02 * rng.Normal();
  }
  Eigen::VectorXd board(n);
  drift::FirstOrderLag(log.temperature.col(0), 200.0, 1.0, board);
  log.temperature.col(1) = board.array() + 5.0;
  log.rate += 0.003 * (log.temperature.col(1).array() - 25.0).matrix();
  return log;
}

// A heat-up of the same gyro: a cold soak, one ramp up, a hold (a run that never cools, so its
// model's cooling rates have a finite edge); with `cool` the mirror, a cool-down from 40 degC (its
// heating rates have one).
Log MakeOneWay(Eigen::Index n, std::uint64_t seed, bool cool) {
  Log log{Eigen::VectorXd(n), Eigen::MatrixXd(n, 2)};
  Rng rng(seed, 0);
  double lagged = cool ? 40.0 : 0.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / static_cast<double>(n);
    const double ramp = 40.0 * std::clamp((x - 0.1) / 0.6, 0.0, 1.0);
    log.temperature(t, 0) = cool ? 40.0 - ramp : ramp;
    const double previous = lagged;
    lagged += (log.temperature(t, 0) - lagged) / 40.0;
    log.rate[t] = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous) + 0.02 * rng.Normal();
  }
  log.temperature.col(1) = log.temperature.col(0).array() + 5.0;
  return log;
}

drift::DriftOptions Compensate(Method method) {
  drift::DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = method;
  o.decomposition.ensemble_size = 10;
  o.selection.monte_carlo.realisations = 20;
  o.features.time_constants_s = {30.0, 120.0};
  o.thermal.shortest_tau_s = 10.0;
  o.seed = 5;
  return o;
}

LoadedModel Fit(const Log& log, drift::DriftOptions o, int channels = 1,
                const std::string& target = "rate_dph") {
  LoadedModel m;
  m.model = drift::FitDriftModel(log.rate, log.temperature.leftCols(channels), o);
  m.info = {target, channels == 1 ? "case_c" : "case_c,board_c", "train.csv", ""};
  return m;
}

// `m` as the axis `target` (the export refuses two axes of one name).
LoadedModel Renamed(LoadedModel m, const std::string& target) {
  m.info.target_column = target;
  return m;
}

// The estimate of every axis from the coefficients JSON, with the equation of docs/firmware.md:
// per sub-model b0 + sum_c sum_p a_cp P_p(z_c) + sum_j [sum_p g_jp P_p(zs_j) + r_j R(ds_j/dt)]
// + h H_w(s_k) - reference_estimate, P_p the power continued along its tangent beyond the range and
// R the rate within [rate_min, rate_max] (null: unbounded), beyond at rate_beyond times its slope.
Eigen::MatrixXd EvaluateCoefficients(const json& j, const Eigen::MatrixXd& temperature_c) {
  const Eigen::Index n = temperature_c.rows();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(n, static_cast<Eigen::Index>(j["axes"].size()));
  for (size_t a = 0; a < j["axes"].size(); ++a) {
    const json& axis = j["axes"][a];
    for (const json& sub : axis["sub_models"]) {
      if (sub["zero"].get<bool>()) continue;
      Eigen::VectorXd e = Eigen::VectorXd::Constant(n, sub["intercept"].get<double>());
      auto tangent_powers = [](const std::vector<double>& powers, double z, double lo, double hi) {
        const double edge = std::clamp(z, lo, hi);
        double sum = 0.0;
        for (size_t p = 1; p <= powers.size(); ++p) {
          const double pp = static_cast<double>(p);
          sum += powers[p - 1] * (p == 1 ? z : std::pow(edge, pp) + pp * std::pow(edge, pp - 1) * (z - edge));
        }
        return sum;
      };
      auto bound = [](const json& v, double otherwise) {
        return v.is_null() ? otherwise : v.get<double>();
      };
      constexpr double kInf = std::numeric_limits<double>::infinity();
      for (const json& l : sub["static"]) {
        const auto c = l["channel"].get<Eigen::Index>();
        const std::vector<double> powers = l["powers"].get<std::vector<double>>();
        const double lo = bound(l["level_min"], -kInf), hi = bound(l["level_max"], kInf);
        for (Eigen::Index t = 0; t < n; ++t) {
          const double z = (temperature_c(t, c) - l["centre_c"].get<double>()) / l["scale_k"].get<double>();
          e[t] += tangent_powers(powers, z, lo, hi);
        }
      }
      std::vector<Eigen::VectorXd> levels;  // of each state, degC
      for (const json& s : sub["states"]) {
        const auto c = s["channel"].get<Eigen::Index>();
        Eigen::VectorXd& level = levels.emplace_back(n);
        const double gain = s["gain"].get<double>(), tau = s["tau_s"].get<double>();
        const double lo = s["level_min"].get<double>(), hi = s["level_max"].get<double>();
        const std::vector<double> powers = s["powers"].get<std::vector<double>>();
        std::vector<double> stage(static_cast<size_t>(s["order"].get<int>()), temperature_c(0, c));
        for (Eigen::Index t = 0; t < n; ++t) {
          double input = temperature_c(t, c), before_last = input;
          for (double& x : stage) {
            before_last = input;
            x += gain * (input - x);
            input = x;
          }
          level[t] = input;
          const double z = (input - s["centre_c"].get<double>()) / s["scale_k"].get<double>();
          const double free = (before_last - input) / tau;
          const double edge =
              std::clamp(free, bound(s["rate_min"], -kInf), bound(s["rate_max"], kInf));
          const double rate = edge + s["rate_beyond"].get<double>() * (free - edge);
          e[t] += tangent_powers(powers, z, lo, hi) + s["rate"].get<double>() * rate;
        }
      }
      if (!sub["hysteresis"].is_null()) {
        const json& h = sub["hysteresis"];
        const Eigen::VectorXd& level = levels[h["state"].get<size_t>()];
        const double w = h["width_k"].get<double>();
        double play = level[0];
        for (Eigen::Index t = 0; t < n; ++t) {
          play = std::clamp(play, level[t] - w, level[t] + w);
          e[t] += h["coefficient"].get<double>() * (level[t] - play) / w;
        }
      }
      out.col(static_cast<Eigen::Index>(a)) += e;
      out.col(static_cast<Eigen::Index>(a)).array() -= sub["reference_estimate"].get<double>();
    }
  }
  return out;
}

double MaxRelativeError(const Eigen::VectorXd& got, const Eigen::VectorXd& want) {
  return (got - want).cwiseAbs().maxCoeff() / std::sqrt(want.squaredNorm() / want.size());
}

template <class E>
void ExpectThrows(const std::function<void()>& f, const std::string& message) {
  try {
    f();
    ADD_FAILURE() << "accepted; expected: " << message;
  } catch (const E& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(message), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

class FirmwareExport : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Log log = MakeLog(3000, 3);
    thermal_ = new LoadedModel(Fit(log, Compensate(Method::kThermal)));
    two_ = new LoadedModel(Fit(log, Compensate(Method::kThermal), 2));
    ms_ = new LoadedModel(Fit(log, Compensate(Method::kMsElm)));
    drift::DriftOptions ref = Compensate(Method::kThermal);
    ref.reference_c = 25.0;
    referenced_ = new LoadedModel(Fit(log, ref));
    drift::DriftOptions hyst = Compensate(Method::kThermal);
    hyst.thermal.hysteresis = drift::HysteresisTerm::kOn;
    hyst.thermal.max_states = 1;  // no pair of nearly collinear states, whose float rounding
                                  // the other models already exercise
    hysteresis_ = new LoadedModel(Fit(MakeLog(3000, 3, 0.0, 0.3), hyst));
    heat_up_ = new LoadedModel(Fit(MakeOneWay(3000, 3, false), Compensate(Method::kThermal)));
    cool_down_ = new LoadedModel(Fit(MakeOneWay(3000, 3, true), Compensate(Method::kThermal)));
  }
  static void TearDownTestSuite() {
    for (LoadedModel* m : {thermal_, two_, ms_, referenced_, hysteresis_, heat_up_, cool_down_}) {
      delete m;
    }
  }
  static LoadedModel* thermal_;
  static LoadedModel* two_;
  static LoadedModel* ms_;
  static LoadedModel* referenced_;
  static LoadedModel* hysteresis_;  // with a hysteresis term
  static LoadedModel* heat_up_;     // a state whose cooling rates have a finite edge
  static LoadedModel* cool_down_;   // one whose heating rates have
};
LoadedModel* FirmwareExport::thermal_ = nullptr;
LoadedModel* FirmwareExport::two_ = nullptr;
LoadedModel* FirmwareExport::ms_ = nullptr;
LoadedModel* FirmwareExport::referenced_ = nullptr;
LoadedModel* FirmwareExport::hysteresis_ = nullptr;
LoadedModel* FirmwareExport::heat_up_ = nullptr;
LoadedModel* FirmwareExport::cool_down_ = nullptr;

// Whether a model has a state whose rate has a finite edge (its calibration never showed a
// direction) and a nonzero coefficient, so that exporting it exercises the rate beyond that edge
// (the test log swings at up to 4 K/min both ways, the one-way runs ramp at 0.8 K/min).
bool HasBoundedRate(const LoadedModel& m) {
  for (const auto& sub : m.model.sub_models) {
    const drift::ThermalRegression& t = *sub.thermal;
    Eigen::Index rate = std::accumulate(t.static_power.begin(), t.static_power.end(), 0) +
                        t.max_power + 1;  // the first state's rate column
    for (const auto& s : t.states) {
      if ((std::isfinite(s.rate_min) || std::isfinite(s.rate_max)) && t.coefficients[rate] != 0.0) {
        return true;
      }
      rate += t.max_power + 1;
    }
  }
  return false;
}

const ExportOptions kJson{.format = ExportFormat::kCoefficientsJson};

TEST_F(FirmwareExport, CoefficientsReproduceTheLibrarysEstimate) {
  // The test run 8 K warmer than the calibration: the powers continue along their tangents.
  const Log test = MakeLog(2000, 4, 8.0);
  ASSERT_TRUE(hysteresis_->model.sub_models[0].thermal->has_hysteresis())
      << hysteresis_->model.Summary();
  ASSERT_TRUE(HasBoundedRate(*heat_up_)) << heat_up_->model.Summary();
  ASSERT_TRUE(HasBoundedRate(*cool_down_)) << cool_down_->model.Summary();
  for (const LoadedModel* m :
       {thermal_, two_, ms_, referenced_, hysteresis_, heat_up_, cool_down_}) {
    const json j = json::parse(RenderCoefficientsJson({*m}, kJson));
    EXPECT_EQ(j["format"], "gyrodrift-coefficients");
    EXPECT_EQ(j["format_version"], 4);
    EXPECT_EQ(j["rate_hz"], 1.0);
    const int channels = m->model.temperature_channels();
    const Eigen::MatrixXd t = test.temperature.leftCols(channels);
    const Eigen::VectorXd want = drift::EstimateDrift(m->model, t);
    EXPECT_LT(MaxRelativeError(EvaluateCoefficients(j, t).col(0), want), 1e-12)
        << m->model.Summary();
  }
  // The test reaches beyond a state's calibrated range (else the tangent is not exercised).
  bool beyond = false;
  for (const auto& sub : thermal_->model.sub_models) {
    for (const auto& s : sub.thermal->states) {
      const double z_max = (test.temperature.col(s.channel).maxCoeff() -
                            sub.thermal->centre_c[static_cast<size_t>(s.channel)]) /
                           sub.thermal->scale_k[static_cast<size_t>(s.channel)];
      beyond = beyond || z_max > s.level_max + 0.1;
    }
  }
  EXPECT_TRUE(beyond);
  // The two-channel model uses the board channel, so the channel mapping is exercised.
  const auto& t2 = *two_->model.sub_models[0].thermal;
  EXPECT_TRUE(t2.static_power[1] > 0 || std::any_of(t2.states.begin(), t2.states.end(),
                                          [](const auto& s) { return s.channel == 1; }))
      << t2.Summary();
  // The reference: the estimate is zero for a record in equilibrium at it.
  const json j = json::parse(RenderCoefficientsJson({*referenced_}, kJson));
  EXPECT_EQ(j["axes"][0]["reference_c"], 25.0);
  EXPECT_NEAR(EvaluateCoefficients(j, Eigen::MatrixXd::Constant(50, 1, 25.0)).cwiseAbs().maxCoeff(),
              0.0, 1e-12);
}

TEST_F(FirmwareExport, AxesShareTheChannelsAndLagsTheyHaveInCommon) {
  const LoadedModel second = Fit(MakeLog(3000, 9), Compensate(Method::kThermal), 2, "rate_y_dph");
  const std::vector<LoadedModel> axes{*thermal_, second, Renamed(*thermal_, "rate_z_dph")};
  const json j = json::parse(RenderCoefficientsJson(axes, kJson));
  EXPECT_EQ(j["channels"], (std::vector<std::string>{"case_c", "board_c"}));
  ASSERT_EQ(j["axes"].size(), 3u);
  EXPECT_EQ(j["axes"][1]["name"], "rate_y_dph");
  const Log test = MakeLog(1500, 10);
  const Eigen::MatrixXd got = EvaluateCoefficients(j, test.temperature);
  EXPECT_LT(MaxRelativeError(got.col(0),
                             drift::EstimateDrift(thermal_->model, test.temperature.leftCols(1))),
            1e-12);
  EXPECT_LT(MaxRelativeError(got.col(1), drift::EstimateDrift(second.model, test.temperature)),
            1e-12);
  EXPECT_EQ(got.col(0), got.col(2));

  const ExportSummary one = SummariseExport({*thermal_});
  const ExportSummary three = SummariseExport(axes);
  EXPECT_EQ(three.axes, 3);
  EXPECT_EQ(three.channels, 2);
  EXPECT_EQ(three.states, 2 * one.states + SummariseExport({second}).states);
  // The third axis repeats the first: its states run on the first one's lags.
  const ExportSummary two = SummariseExport({*thermal_, second});
  EXPECT_EQ(three.lag_stages, two.lag_stages);
  EXPECT_LE(two.lag_stages, one.lag_stages + SummariseExport({second}).lag_stages);
  EXPECT_GT(one.lag_stages, 0);
  EXPECT_EQ(three.rate_hz, 1.0);
  EXPECT_NE(three.Line().find("3 axes, 2 temperature channels"), std::string::npos) << three.Line();
}

// One logger's rate read from two logs' time stamps differs in its last digits: export takes both,
// and each axis's lags run at its own model's gain (sharing the first one's was 1e-6 off).
TEST_F(FirmwareExport, AxesAtRatesThatDifferInTheLastDigitsKeepTheirOwnGains) {
  drift::DriftOptions o = Compensate(Method::kThermal);
  o.features.rate_hz = 1.0 + 9e-7;
  const LoadedModel faster = Fit(MakeLog(3000, 3), o, 1, "rate_y_dph");
  const auto& states = faster.model.sub_models.front().thermal->states;
  const auto& first = thermal_->model.sub_models.front().thermal->states;
  ASSERT_FALSE(states.empty());
  ASSERT_EQ(states.size(), first.size());
  for (size_t i = 0; i < states.size(); ++i) ASSERT_EQ(states[i].tau_s, first[i].tau_s);
  const json j = json::parse(RenderCoefficientsJson({*thermal_, faster}, kJson));
  const Log test = MakeLog(1500, 10);
  const Eigen::MatrixXd got = EvaluateCoefficients(j, test.temperature.leftCols(1));
  EXPECT_LT(MaxRelativeError(got.col(0),
                             drift::EstimateDrift(thermal_->model, test.temperature.leftCols(1))),
            1e-12);
  EXPECT_LT(MaxRelativeError(got.col(1),
                             drift::EstimateDrift(faster.model, test.temperature.leftCols(1))),
            1e-12);
  EXPECT_EQ(SummariseExport({*thermal_, faster}).lag_stages,
            2 * SummariseExport({*thermal_}).lag_stages);
}

// The header is C: the only test of its text is a compiler (the system's, as a user's would be).
// Several axes with two channels, ms-elm, a reference, a hysteresis term, a heat-up's model (a
// cooling rate beyond its edge) and a model without states (no lag stage) in one header, and that
// last model alone (a state struct without lags), double and float.
TEST_F(FirmwareExport, HeadersOfEveryShapeCompileAndMatchTheLibrary) {
  ASSERT_TRUE(std::filesystem::exists(test::kCCompiler)) << "no C compiler was found";
  drift::DriftOptions flat = Compensate(Method::kThermal);
  flat.thermal.max_states = 0;
  const LoadedModel stateless = Fit(MakeLog(3000, 3), flat, 2, "rate_z_dph");
  ASSERT_TRUE(stateless.model.sub_models[0].thermal->states.empty());
  ASSERT_TRUE(HasBoundedRate(*heat_up_)) << heat_up_->model.Summary();
  ASSERT_TRUE(HasBoundedRate(*cool_down_)) << cool_down_->model.Summary();
  std::vector<LoadedModel> axes{*thermal_,    *two_,     *ms_,        *referenced_,
                                *hysteresis_, *heat_up_, *cool_down_, stateless};
  for (size_t a = 0; a < axes.size(); ++a) axes[a] = Renamed(axes[a], "axis" + std::to_string(a));
  const Log test = MakeLog(2000, 4, 8.0);
  const std::string dir = test::TempDir("firmware_header");
  for (const bool single : {false, true}) {
    const ExportOptions options{.single_precision = single, .prefix = single ? "imu_f" : "imu"};
    for (const bool alone : {false, true}) {
      const std::vector<LoadedModel> exported = alone ? std::vector<LoadedModel>{stateless} : axes;
      const std::string header = dir + "/" + options.prefix + (alone ? "_alone" : "") + ".h";
      WriteFileAtomically(header, RenderFirmwareC(exported, options));
      const Eigen::MatrixXd got =
          test::RunFirmwareHeader(header, options.prefix, test.temperature, dir);
      ASSERT_EQ(got.cols(), static_cast<Eigen::Index>(exported.size()));
      for (size_t a = 0; a < exported.size(); ++a) {
        const Eigen::MatrixXd t =
            test.temperature.leftCols(exported[a].model.temperature_channels());
        EXPECT_LT(MaxRelativeError(got.col(static_cast<Eigen::Index>(a)),
                                   drift::EstimateDrift(exported[a].model, t)),
                  single ? 1e-5 : 1e-9)
            << "axis " << a << (single ? ", float" : ", double");
      }
    }
  }
}

// A temperature that is not finite (a sensor's NaN) is held at the channel's last one: the
// estimates are the library's on the series with that sample repeated, not NaN ever after.
TEST_F(FirmwareExport, HeaderHoldsATemperatureThatIsNotFinite) {
  ASSERT_TRUE(std::filesystem::exists(test::kCCompiler)) << "no C compiler was found";
  const std::vector<LoadedModel> axes{*two_, Renamed(*hysteresis_, "rate_y_dph")};
  const Log test = MakeLog(1200, 6, 8.0);
  Eigen::MatrixXd glitched = test.temperature, held = test.temperature;
  glitched(400, 0) = std::numeric_limits<double>::quiet_NaN();
  glitched(401, 0) = std::numeric_limits<double>::quiet_NaN();
  glitched(900, 1) = std::numeric_limits<double>::infinity();
  held(400, 0) = held(401, 0) = held(399, 0);
  held(900, 1) = held(899, 1);
  const std::string dir = test::TempDir("firmware_nan");
  WriteFileAtomically(dir + "/held.h", RenderFirmwareC(axes, {.prefix = "held"}));
  const Eigen::MatrixXd got = test::RunFirmwareHeader(dir + "/held.h", "held", glitched, dir);
  ASSERT_EQ(got.cols(), 2);
  for (Eigen::Index a = 0; a < 2; ++a) {
    const LoadedModel& axis = axes[static_cast<size_t>(a)];
    EXPECT_TRUE(got.col(a).allFinite()) << "axis " << a;
    EXPECT_LT(MaxRelativeError(got.col(a),
                               drift::EstimateDrift(
                                   axis.model, held.leftCols(axis.model.temperature_channels()))),
              1e-9)
        << "axis " << a;
  }
}

// init and step say how many temperatures they could not take.
TEST_F(FirmwareExport, InitAndStepCountTheTemperaturesTheyCouldNotTake) {
  ASSERT_TRUE(std::filesystem::exists(test::kCCompiler)) << "no C compiler was found";
  const std::string dir = test::TempDir("firmware_counts");
  WriteFileAtomically(dir + "/two.h", RenderFirmwareC({*two_}, {.prefix = "two"}));
  WriteFileAtomically(dir + "/counts.c", R"(#include <math.h>
#include <stdio.h>
#include "two.h"
int main(void) {
  two_state s;
  two_real t[TWO_N_CHANNELS] = {(two_real)NAN, 21.0};
  two_real drift[TWO_N_AXES];
  int at_nan, at_good, held, none;
  at_nan = two_init(&s, t);
  t[0] = 20.0;
  at_good = two_init(&s, t);
  t[1] = (two_real)INFINITY;
  held = two_step(&s, t, drift);
  t[1] = 21.5;
  none = two_step(&s, t, drift);
  printf("%d %d %d %d %d\n", at_nan, at_good, held, none, drift[0] == drift[0]);
  return 0;
}
)");
  const test::CommandResult compiled =
      test::RunShell(std::string("'") + test::kCCompiler + "' " + test::kCFlags + " '" + dir +
                     "/counts.c' -o '" + dir + "/counts'");
  ASSERT_EQ(compiled.exit_code, 0) << compiled.err;
  const test::CommandResult run = test::RunShell("'" + dir + "/counts'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out, "1 0 1 0 1\n");
}

TEST_F(FirmwareExport, RenderingIsDeterministicAndHasTheDocumentedShape) {
  const ExportOptions c{.prefix = "imu_x"};
  const std::string text = RenderFirmwareC({*ms_}, c);
  // Same bytes again, and from the model read back from its file.
  EXPECT_EQ(RenderFirmwareC({*ms_}, c), text);
  const LoadedModel reread = ParseModelFile(RenderModelFile(ms_->model, ms_->info), "m.json");
  EXPECT_EQ(RenderFirmwareC({reread}, c), text);
  EXPECT_EQ(RenderCoefficientsJson({reread}, kJson), RenderCoefficientsJson({*ms_}, kJson));
  for (const char* needle :
       {"#ifndef IMU_X_H", "#define IMU_X_N_AXES 1", "#define IMU_X_N_CHANNELS 1",
        "#define IMU_X_AXIS_0_NAME \"rate_dph\"", "#define IMU_X_CHANNEL_0_NAME \"case_c\"",
        "typedef double imu_x_real;", "} imu_x_state;", "static inline int imu_x_init(",
        "static inline int imu_x_step(", "no libm", "Sample rate: 1 Hz"}) {
    EXPECT_NE(text.find(needle), std::string::npos) << needle;
  }
  // Nothing to link and no other header: the gains are literals. (Comments mention exp.)
  std::string code;
  for (size_t at = 0; at < text.size();) {
    const size_t open = text.find("/*", at);
    code += text.substr(at, open - at);
    at = open == std::string::npos ? open : text.find("*/", open) + 2;
  }
  EXPECT_EQ(code.find("#include"), std::string::npos);
  EXPECT_EQ(code.find("exp"), std::string::npos);
  EXPECT_EQ(code.find("pow("), std::string::npos);
  // The axis comment names its sub-models.
  std::string names;
  for (const auto& sub : ms_->model.sub_models) names += (names.empty() ? "" : ", ") + sub.name;
  ASSERT_GE(ms_->model.sub_models.size(), 2u);
  EXPECT_NE(text.find("/* axis 0: rate_dph, the sum of sub-models " + names + " */"),
            std::string::npos)
      << names;
  const std::string single = RenderFirmwareC({*ms_}, {.single_precision = true, .prefix = "imu_x"});
  EXPECT_NE(single.find("typedef float imu_x_real;"), std::string::npos);
  EXPECT_NE(single.find("f * (s->lag["), std::string::npos);  // float literals
  EXPECT_EQ(single.find("double"), std::string::npos);
}

TEST_F(FirmwareExport, NamesAreQuotedSafely) {
  LoadedModel odd = *thermal_;
  odd.info.target_column = "rate \"x\"?\?/ */ /* \xc2\xb0";
  odd.info.temperature_column = "T*/\\";
  const std::string text = RenderFirmwareC({odd}, {});
  EXPECT_NE(text.find("#define GYRO_COMP_AXIS_0_NAME \"rate \\\"x\\\"\\?\\?/ */ /* \\302\\260\""),
            std::string::npos)
      << text.substr(0, 2000);
  EXPECT_NE(text.find("#define GYRO_COMP_CHANNEL_0_NAME \"T*/\\\\\""), std::string::npos);
  // Comments hold no "*/" but their own ends, and no trigraph.
  size_t comment_ends = 0, opens = 0;
  for (size_t at = 0; (at = text.find("*/", at)) != std::string::npos; ++at) ++comment_ends;
  for (size_t at = 0; (at = text.find("/*", at)) != std::string::npos; ++at) ++opens;
  // (the names' "*/" inside the string literals of the two #defines count once each, the
  // target's "/*" once)
  EXPECT_EQ(comment_ends, opens - 1 + 2);
}

TEST_F(FirmwareExport, RefusesWhatCannotRunInFirmware) {
  const Log log = MakeLog(600, 5);
  drift::DriftOptions predict = Compensate(Method::kElm);
  predict.mode = Mode::kPredict;
  ExpectThrows<UsageError>([&] { RenderFirmwareC({Fit(log, predict)}, {}); },
                           "axis 0 (rate_dph) is a predict-mode model");
  for (Method learner : {Method::kPoly, Method::kElm}) {
    ExpectThrows<UsageError>(
        [&] { RenderFirmwareC({Fit(log, Compensate(learner))}, {}); },
        "learner on thermal features, not an identified thermal model: export takes method "
        "thermal, ms-elm or emd-elm");
  }
  // A nonlinear correction (whichever network: the refusal looks at its presence only).
  LoadedModel corrected = *thermal_;
  auto thermal = std::make_shared<drift::ThermalRegression>(*thermal_->model.sub_models[0].thermal);
  thermal->correction = Fit(log, Compensate(Method::kElm)).model.sub_models[0].learner;
  corrected.model.sub_models[0].thermal = thermal;
  ExpectThrows<UsageError>(
      [&] {
        RenderFirmwareC({*thermal_, corrected}, {});
      },
      "axis 1 (rate_dph): sub-model 'signal' has a nonlinear correction");
  ExpectThrows<UsageError>([&] { RequireExportable({}); }, "at least one model");
  // One step function serves every axis: one sample rate.
  drift::DriftOptions fast = Compensate(Method::kThermal);
  fast.features.rate_hz = 10.0;
  ExpectThrows<UsageError>(
      [&] {
        RenderCoefficientsJson({*thermal_, Fit(log, fast)}, kJson);
      },
      "one sample rate");
  // A file whose column list does not fit its models.
  LoadedModel short_list = *two_;
  short_list.info.temperature_column = "case_c";
  ExpectThrows<DataError>([&] { RenderFirmwareC({short_list}, {}); },
                          "takes 2 temperature channel(s), its file names 1");
}

TEST(ExportOptions, ValidatesThePrefixAndTheFormat) {
  for (const char* good : {"gyro_comp", "x", "Imu2_z", "a23456789012345678901234567890bc"}) {
    EXPECT_NO_THROW((ExportOptions{.prefix = good}.Validate())) << good;
  }
  for (const char* bad : {"", "2x", "_x", "a-b", "a b", "gyro.comp",
                          "a234567890123456789012345678901bc", "t\xc3\xa9"}) {
    ExpectThrows<OptionError>([&] { ExportOptions{.prefix = bad}.Validate(); },
                              "prefix = '" + std::string(bad) + "': must be a C identifier");
  }
  ExpectThrows<OptionError>(
      [] {
        ExportOptions{.format = ExportFormat::kCoefficientsJson, .single_precision = true}
            .Validate();
      },
      "single_precision = true: must be false with format json-coefficients");
  EXPECT_EQ(ExportFormatFromString("c"), ExportFormat::kC);
  EXPECT_EQ(ExportFormatFromString(ToString(ExportFormat::kCoefficientsJson)),
            ExportFormat::kCoefficientsJson);
  ExpectThrows<OptionError>([] { ExportFormatFromString("h"); },
                            "format = 'h': must be one of c, json-coefficients");
}

}  // namespace
}  // namespace gyrodrift::firmware
