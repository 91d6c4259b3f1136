// The multi-scale drift model: features, fitting in both modes, and the causal protocol's
// guarantee that nothing after t reaches a prediction for t.
#include "gyrodrift/drift/drift_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <set>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/drift/features.h"

namespace gyrodrift::drift {
namespace {

// A small thermal log: temperature ramps, a drift that follows a lagged temperature and its rate,
// white noise on top.
struct Log {
  Eigen::VectorXd rate, temperature, drift;
};

Log MakeLog(Eigen::Index n, std::uint64_t seed) {
  Log log{Eigen::VectorXd(n), Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Rng rng(seed, 0);
  double lagged = 20.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / n;
    log.temperature[t] = 20.0 + 15.0 * std::sin(2 * std::numbers::pi * 1.5 * x);
    const double previous = lagged;
    lagged += (log.temperature[t] - lagged) / 120.0;
    log.drift[t] = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous);
    log.rate[t] = log.drift[t] + 0.02 * rng.Normal();
  }
  return log;
}

TEST(ThermalFeatures, FirstOrderLagsAndTheirRates) {
  FeatureOptions o;
  o.thermal_set = ThermalSet::kLagBank;
  o.time_constants_s = {10.0};
  Eigen::VectorXd step = Eigen::VectorXd::Constant(200, 5.0);
  step.tail(100).setConstant(15.0);
  const Eigen::MatrixXd f = ThermalFeatures(step, o);
  ASSERT_EQ(f.cols(), 3);
  EXPECT_EQ(f(99, 1), 5.0);  // steady state: the lag equals the input, the rate is zero
  EXPECT_EQ(f(99, 2), 0.0);
  // Exact first-order step response: after k samples the lag has covered 1 - exp(-k dt / tau).
  EXPECT_NEAR(f(109, 1), 15.0 - 10.0 * std::exp(-10.0 / 10.0), 1e-12);
  EXPECT_NEAR(f(109, 2), (15.0 - f(109, 1)) / 10.0, 1e-15);
  // Causal: changing the future leaves every earlier row unchanged.
  Eigen::VectorXd changed = step;
  changed.tail(50).setConstant(-3.0);
  const Eigen::MatrixXd g = ThermalFeatures(changed, o);
  EXPECT_EQ(f.topRows(150), g.topRows(150));
}

TEST(ThermalFeatures, LadderRungsAddUpToTheTemperatureAndClassicIsTemperatureAndRate) {
  const Log log = MakeLog(2000, 11);
  FeatureOptions o;  // kAuto counts as the ladder here
  const Eigen::MatrixXd ladder = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(ladder.cols(), 7);
  EXPECT_EQ(o.NumThermalFeatures(), 7);
  // Rungs plus the slowest lag telescope back to T (to rounding).
  EXPECT_LE((ladder.leftCols(6).rowwise().sum() - log.temperature).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(ladder(100, 6), std::pow(log.temperature[100] - 20.0, 2), 1e-12);
  o.thermal_set = ThermalSet::kLagBank;
  const Eigen::MatrixXd bank = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(bank.cols(), 11);
  EXPECT_NEAR((ladder.col(0) - (log.temperature - bank.col(1))).cwiseAbs().maxCoeff(), 0.0, 1e-12);
  o.thermal_set = ThermalSet::kClassic;
  const Eigen::MatrixXd classic = ThermalFeatures(log.temperature, o);
  ASSERT_EQ(classic.cols(), 2);
  EXPECT_EQ(classic.col(0), log.temperature);
  EXPECT_EQ(classic.col(1), bank.col(2));  // (T - T_60) / 60, K/s
  // The drift model resolves auto: classic for poly, ladder for the rest.
  DriftOptions d;
  d.method = Method::kPoly;
  EXPECT_EQ(EffectiveFeatures(d).thermal_set, ThermalSet::kClassic);
  d.method = Method::kMsElm;
  EXPECT_EQ(EffectiveFeatures(d).thermal_set, ThermalSet::kLadder);
  EXPECT_EQ(ThermalSetFromString("lag-bank"), ThermalSet::kLagBank);
  EXPECT_THROW(ThermalSetFromString("cubic"), UsageError);
  o.time_constants_s.clear();
  EXPECT_THROW(o.Validate(), UsageError);  // classic needs a smoothing time constant
}

TEST(ThermalFeatures, RejectsBadInput) {
  FeatureOptions o;
  Eigen::VectorXd t = Eigen::VectorXd::Constant(10, 1.0);
  t[3] = std::nan("");
  EXPECT_THROW(ThermalFeatures(t, o), DataError);
  o.time_constants_s = {0.0};
  EXPECT_THROW(ThermalFeatures(Eigen::VectorXd::Ones(10), o), UsageError);
  o = FeatureOptions{};
  o.rate_hz = 0.0;
  EXPECT_THROW(o.Validate(), UsageError);
}

DriftOptions Fast(Mode mode, Method method) {
  DriftOptions o;
  o.mode = mode;
  o.method = method;
  o.decomposition.ensemble_size = 10;
  o.selection.monte_carlo.realisations = 20;
  o.threads = 2;
  return o;
}

TEST(ThermalFeatures, TimeConstantsLongerThanAQuarterOfTheTrainingRecordAreDropped) {
  FeatureOptions o;  // 60, 300, 900, 1800, 3600 s at 1 Hz
  EXPECT_EQ(ForTrainingRecord(o, 28800).time_constants_s, o.time_constants_s);  // 8 h: all
  EXPECT_EQ(ForTrainingRecord(o, 7200).time_constants_s, (std::vector<double>{60, 300, 900, 1800}));
  EXPECT_EQ(ForTrainingRecord(o, 3000).time_constants_s, (std::vector<double>{60, 300}));
  EXPECT_EQ(ForTrainingRecord(o, 100).time_constants_s, (std::vector<double>{60}));  // shortest
  EXPECT_FALSE(ForTrainingRecord(o, 100).limit_time_constants);
  o.rate_hz = 0.1;  // 3000 samples are 30000 s
  EXPECT_EQ(ForTrainingRecord(o, 3000).time_constants_s, o.time_constants_s);
  o.rate_hz = 1.0;
  o.limit_time_constants = false;
  EXPECT_EQ(ForTrainingRecord(o, 100).time_constants_s, o.time_constants_s);
  // A fitted model keeps what it used, with the limit off, so a saved model estimates the same.
  const Log log = MakeLog(3000, 12);
  const DriftModel model =
      FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kPoly));
  EXPECT_EQ(model.options.features.time_constants_s, (std::vector<double>{60, 300}));
  EXPECT_FALSE(model.options.features.limit_time_constants);
}

TEST(DriftModel, MsElmPredictModeBuildsGroupsThatSumToTheSignal) {
  const Log log = MakeLog(1500, 1);
  const DriftModel model =
      FitDriftModel(log.rate, Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  ASSERT_GE(model.sub_models.size(), 2u) << model.Summary();
  EXPECT_EQ(model.lags, 4);
  EXPECT_GT(model.training_imfs, 3);
  decomposition::DecompositionOptions d = model.options.decomposition;
  d.seed = model.options.seed;
  const Eigen::MatrixXd series = GroupSeries(model, decomposition::Decompose(log.rate, d));
  EXPECT_LE((series.rowwise().sum() - log.rate).cwiseAbs().maxCoeff(), 1e-12);
}

// The white-noise level comes from the decomposition's own noise EMDs: the fit runs no
// Monte-Carlo and equals, bit for bit, a fit given the Monte-Carlo level of the same seed.
TEST(DriftModel, MsElmReusesTheDecompositionsNoiseForTheWhiteNoiseLevel) {
  const Log log = MakeLog(1500, 3);
  DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  o.decomposition.ensemble_size = 20;
  // ICEEMDAN decomposes the noise to full depth; BEEMDAN's bound may stop before the noise run
  // does, and then SelectModes completes the level by the Monte-Carlo (selection_test).
  o.decomposition.method = decomposition::Method::kIceemdan;
  o.seed = 4;
  // No level of its own: the process-wide cache (other tests in this process may have filled it)
  // does not grow.
  const size_t cached_levels = selection::NoiseLevelCache::Global().Size();
  const DriftModel reused = FitDriftModel(log.rate, Eigen::VectorXd(), o);
  EXPECT_EQ(selection::NoiseLevelCache::Global().Size(), cached_levels) << reused.selection_summary;
  DriftOptions given = o;
  selection::MonteCarloOptions mc = o.selection.monte_carlo;
  mc.seed = o.seed;
  given.selection.noise_level = std::make_shared<const selection::NoiseLevel>(
      selection::ComputeNoiseLevel(1500, mc, o.selection.kde, o.selection.distance));
  const DriftModel reference = FitDriftModel(log.rate, Eigen::VectorXd(), given);
  EXPECT_EQ(reused.selection_summary, reference.selection_summary);
  ASSERT_EQ(reused.sub_models.size(), reference.sub_models.size());
  for (size_t g = 0; g < reused.sub_models.size(); ++g) {
    EXPECT_EQ(reused.sub_models[g].imfs, reference.sub_models[g].imfs) << g;
  }
  EXPECT_EQ(PredictOneStep(reused, log.rate, Eigen::VectorXd(), 4, Protocol::kPaper),
            PredictOneStep(reference, log.rate, Eigen::VectorXd(), 4, Protocol::kPaper));
}

// The seed rule (common/random.h): each random stream of a fit has its own seed. Sub-model g's
// learner draws from SeedFor(seed, "sub-model", g), never from the seed itself, whose streams
// (seed, i) are the decomposition's white noise; over an evaluation's repeats no two (repeat,
// sub-model) pairs share a seed, as seed + r + g made repeat r + 1's sub-model g - 1 repeat r's
// sub-model g. The white-noise level, computed apart here (ensemble 10 < 20 realisations), draws
// the user's seed, not the Monte-Carlo's default 1.
TEST(DriftModel, NoTwoRandomStreamsOfAFitCoincide) {
  const Log log = MakeLog(1500, 1);
  DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  o.seed = 7;
  const DriftModel model = FitDriftModel(log.rate, Eigen::VectorXd(), o);
  ASSERT_GE(model.sub_models.size(), 2u) << model.Summary();
  std::set<std::string> seeds{std::to_string(o.seed)};
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    ASSERT_TRUE(model.sub_models[g].learner) << g;
    const std::string used = model.sub_models[g].learner->Save().texts.at("seed");
    EXPECT_EQ(used, std::to_string(SeedFor(o.seed, "sub-model", g)));
    EXPECT_TRUE(seeds.insert(used).second) << "sub-model " << g << " reuses seed " << used;
  }
  EXPECT_NE(model.selection_summary.find("seed=7)"), std::string::npos) << model.selection_summary;

  std::set<std::uint64_t> all;
  for (int r = 0; r < 100; ++r) {
    const std::uint64_t repeat = RepeatSeed(o.seed, r);
    EXPECT_TRUE(all.insert(repeat).second) << "repeat " << r;
    for (std::uint64_t g = 0; g < 8; ++g) {
      EXPECT_TRUE(all.insert(SeedFor(repeat, "sub-model", g)).second) << r << ", " << g;
    }
  }
  EXPECT_EQ(RepeatSeed(o.seed, 0), o.seed);  // one repeat scores the model fit writes
}

// An MS-ELM predict model fitted on the first 500 samples of a 700-sample log, and causal options
// with 64-sample windows on 2 threads.
struct CausalCase {
  Log log;
  DriftModel model;
  CausalOptions causal;
};

CausalCase MakeCausalCase(std::uint64_t seed) {
  CausalCase c{MakeLog(700, seed), {}, {}};
  c.model =
      FitDriftModel(c.log.rate.head(500), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  c.causal.window = 64;
  c.causal.threads = 2;
  return c;
}

TEST(DriftModel, CausalWindowProgressIsMonotoneAndDoesNotChangeTheResult) {
  auto [log, model, causal] = MakeCausalCase(5);
  const Eigen::VectorXd quiet =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal);
  std::vector<double> seen;
  causal.progress = [&seen](double f) { seen.push_back(f); };
  const Eigen::VectorXd reported =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal);
  EXPECT_EQ(quiet, reported);
  ASSERT_GE(seen.size(), 10u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GT(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
}

// Full windows share one set of white-noise EMDs (computed once, not per window): each
// prediction is still the one a lone decomposition of its window gives, to the bit.
TEST(DriftModel, CausalWindowsSharingTheNoiseEmdsPredictAsAloneWindows) {
  const auto [log, model, causal] = MakeCausalCase(6);
  const Eigen::VectorXd all =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal);
  for (Eigen::Index t : {500, 563, 699}) {
    // A record ending at t has a single full window: nothing to share.
    const Eigen::VectorXd alone = PredictOneStep(model, log.rate.head(t + 1), Eigen::VectorXd(), t,
                                                 Protocol::kCausal, causal);
    ASSERT_EQ(alone.size(), 1);
    EXPECT_EQ(alone[0], all[t - 500]) << t;
  }
}

// Recursive multi-step prediction: a linear autoregression on 4 lags represents a sampled sine
// exactly, so fed its own predictions it still continues the sine 12 steps ahead; a mistake in
// the recursion (a lag in the wrong place, the wrong thermal row) would not.
TEST(DriftModel, PredictAheadContinuesASineFromItsOwnPredictions) {
  const Eigen::Index n = 600;
  Eigen::VectorXd y(n);
  for (Eigen::Index t = 0; t < n; ++t) y[t] = std::sin(2 * std::numbers::pi * t / 37.0);
  DriftOptions o = Fast(Mode::kPredict, Method::kPoly);
  o.learner.poly_degree = 1;
  const DriftModel model = FitDriftModel(y.head(400), Eigen::VectorXd(), o);
  for (int horizon : {1, 2, 12}) {
    const Eigen::VectorXd ahead =
        PredictAhead(model, y, Eigen::VectorXd(), 420, horizon, Protocol::kPaper);
    ASSERT_EQ(ahead.size(), n - 420);
    EXPECT_LT((ahead - y.tail(n - 420)).cwiseAbs().maxCoeff(), 1e-6) << horizon;
  }
  // Horizon 1 is the classic one-step prediction: the learner on the lag rows, nothing more.
  EXPECT_EQ(PredictAhead(model, y, Eigen::VectorXd(), 420, 1, Protocol::kCausal),
            model.sub_models.front().learner->Predict(LagRows(y, model.lags, 420, n - 420)));
  // The 12-step prediction of y[t] starts at t - 11: it needs lags + 11 samples before t.
  EXPECT_NO_THROW(PredictAhead(model, y, Eigen::VectorXd(), 15, 12, Protocol::kPaper));
  EXPECT_THROW(PredictAhead(model, y, Eigen::VectorXd(), 14, 12, Protocol::kPaper), DataError);
  EXPECT_THROW(PredictAhead(model, y, Eigen::VectorXd(), 420, 0, Protocol::kPaper), UsageError);
}

// With a temperature, every step of the recursion reads the thermal inputs of its own time: an
// output that is a linear function of the temperature one sample earlier is predicted exactly
// 6 steps ahead (the inputs of the origin would miss it by the temperature's change).
TEST(DriftModel, PredictAheadReadsEachStepsThermalInputs) {
  const Eigen::Index n = 800;
  Eigen::VectorXd temperature(n), y(n);
  for (Eigen::Index t = 0; t < n; ++t) {
    temperature[t] = 20.0 + 10.0 * std::sin(2 * std::numbers::pi * t / 300.0) + 0.02 * t;
  }
  y[0] = 0.0;
  for (Eigen::Index t = 1; t < n; ++t) y[t] = 0.3 * (temperature[t - 1] - 20.0);
  DriftOptions o = Fast(Mode::kPredict, Method::kPoly);
  o.learner.poly_degree = 1;
  o.features.use_temperature = true;
  const DriftModel model = FitDriftModel(y.head(500), temperature.head(500), o);
  ASSERT_TRUE(model.uses_temperature());
  const Eigen::VectorXd ahead = PredictAhead(model, y, temperature, 520, 6, Protocol::kPaper);
  EXPECT_LT((ahead - y.tail(n - 520)).cwiseAbs().maxCoeff(), 1e-6);
}

// The H-step prediction of y[t] uses samples before t - H + 1 only (causal protocol, with the
// decomposition of trailing windows and the recursion): changing samples from c on leaves every
// prediction up to y[c + H - 1] unchanged to the bit.
TEST(DriftModel, PredictAheadIgnoresSamplesAfterItsOrigin) {
  const Log log = MakeLog(900, 7);
  const DriftModel model =
      FitDriftModel(log.rate.head(600), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  CausalOptions causal;
  causal.window = 128;
  const int horizon = 5;
  const Eigen::VectorXd base =
      PredictAhead(model, log.rate, Eigen::VectorXd(), 600, horizon, Protocol::kCausal, causal);
  Eigen::VectorXd changed = log.rate;
  changed.tail(150).array() += 5.0;  // samples 750.. change
  const Eigen::VectorXd after =
      PredictAhead(model, changed, Eigen::VectorXd(), 600, horizon, Protocol::kCausal, causal);
  // y[t] for t <= 754 starts at t - 4 <= 750, from samples up to 749.
  EXPECT_EQ(base.head(155), after.head(155));
  EXPECT_NE(base.segment(155, 5), after.segment(155, 5));
  const Eigen::VectorXd one =
      PredictAhead(model, log.rate, Eigen::VectorXd(), 600, 1, Protocol::kCausal, causal);
  EXPECT_NE(base, one);
}

// The causal windows cannot resolve slow IMFs: a note names a sub-model that sums them (not the
// noise group, whose energy is in its first IMFs, nor the residue's), and the window that would.
TEST(DriftModel, CausalWindowNoteNamesSubModelsTheWindowsCannotFeed) {
  DriftModel model;
  model.options.method = Method::kMsElm;
  model.sub_models = {{"noise", {1, 2, 3}, false, nullptr},
                      {"mixed", {4, 5, 6, 7, 8, 9, 10, 11, 12}, false, nullptr},
                      {"drift", {13}, true, nullptr}};
  const std::string note = CausalWindowNote(model, 512);
  EXPECT_NE(note.find("resolves about 8 IMFs; sub-model 'mixed' (IMFs 4-12) holds slower ones"),
            std::string::npos)
      << note;
  EXPECT_NE(note.find("a window of 8192 samples would resolve them"), std::string::npos) << note;
  EXPECT_EQ(CausalWindowNote(model, 8192), "");
  model.sub_models = {{"noise", {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13}, false, nullptr},
                      {"drift", {}, true, nullptr}};
  EXPECT_EQ(CausalWindowNote(model, 512), "");  // the default grouping on a 1 Hz FOG log
  model.options.method = Method::kElm;
  model.sub_models = {{"signal", {}, true, nullptr}};
  EXPECT_EQ(CausalWindowNote(model, 16), "");
}

TEST(DriftModel, CausalPredictionsIgnoreTheFuture) {
  const Log log = MakeLog(900, 2);
  for (Method method : {Method::kMsElm, Method::kEmdElm, Method::kElm}) {
    const DriftModel model =
        FitDriftModel(log.rate.head(600), Eigen::VectorXd(), Fast(Mode::kPredict, method));
    CausalOptions causal;
    causal.window = 128;
    const Eigen::VectorXd base =
        PredictOneStep(model, log.rate, Eigen::VectorXd(), 600, Protocol::kCausal, causal);
    Eigen::VectorXd changed = log.rate;
    changed.tail(150).array() += 5.0;  // samples 750.. change
    const Eigen::VectorXd after =
        PredictOneStep(model, changed, Eigen::VectorXd(), 600, Protocol::kCausal, causal);
    // Predictions for t <= 750 use samples up to 749 only: unchanged to the bit.
    EXPECT_EQ(base.head(151), after.head(151)) << ToString(method);
    EXPECT_NE(base.tail(10), after.tail(10)) << ToString(method);
    if (UsesDecomposition(method)) {
      // The paper protocol decomposes the whole record: the same change leaks into earlier
      // predictions, which is exactly the leakage the causal protocol removes.
      const Eigen::VectorXd paper =
          PredictOneStep(model, log.rate, Eigen::VectorXd(), 600, Protocol::kPaper);
      const Eigen::VectorXd paper_changed =
          PredictOneStep(model, changed, Eigen::VectorXd(), 600, Protocol::kPaper);
      EXPECT_NE(paper.head(150), paper_changed.head(150)) << ToString(method);
    }
  }
}

TEST(DriftModel, CompensateModeNeedsOnlyTemperatureAtRunTime) {
  const Log train = MakeLog(3000, 3);
  for (Method method : {Method::kMsElm, Method::kElm, Method::kPoly}) {
    const DriftModel model =
        FitDriftModel(train.rate, train.temperature, Fast(Mode::kCompensate, method));
    const Log test = MakeLog(3000, 4);  // same programme, new noise
    const Eigen::VectorXd estimate = EstimateDrift(model, test.temperature);
    const double rms_drift = std::sqrt(test.drift.squaredNorm() / 3000);
    const double rms_error = std::sqrt((estimate - test.drift).squaredNorm() / 3000);
    EXPECT_LT(rms_error, 0.3 * rms_drift) << ToString(method) << ": " << model.Summary();
  }
}

TEST(DriftModel, CompensateModeIdentifiesEveryGroupReferencesOnRequestAndIsThreadCountFree) {
  const Log train = MakeLog(3000, 8);
  DriftOptions o = Fast(Mode::kCompensate, Method::kMsElm);
  const DriftModel model = FitDriftModel(train.rate, train.temperature, o);
  ASSERT_GE(model.sub_models.size(), 2u) << model.Summary();
  EXPECT_TRUE(model.identified());
  for (const SubModel& sub : model.sub_models) {
    ASSERT_TRUE(sub.thermal) << sub.name << ": every group has its own identified thermal model";
    EXPECT_FALSE(sub.learner) << sub.name;
  }
  // The fitted intercept is kept by default: the estimate in equilibrium is the unit's bias.
  EXPECT_TRUE(std::isnan(o.reference_c));
  const Eigen::VectorXd estimate = EstimateDrift(model, train.temperature);
  // Referenced: a record in equilibrium at 20 degC has no thermal drift, and referencing only
  // shifts the estimate by a constant.
  o.reference_c = 20.0;
  const DriftModel referenced = FitDriftModel(train.rate, train.temperature, o);
  const Eigen::VectorXd at_reference =
      EstimateDrift(referenced, Eigen::VectorXd::Constant(500, 20.0));
  EXPECT_LE(at_reference.cwiseAbs().maxCoeff(), 1e-12);
  const Eigen::VectorXd shifted = EstimateDrift(referenced, train.temperature);
  EXPECT_LE(((shifted - estimate).array() - (shifted - estimate).mean()).abs().maxCoeff(), 1e-10);
  // One thread or two: the same bits.
  o.reference_c = std::nan("");
  o.threads = 1;
  EXPECT_EQ(EstimateDrift(FitDriftModel(train.rate, train.temperature, o), train.temperature),
            estimate);
  // The nonlinear option: each group is still identified, and the blocked cross-validation
  // decides whether it keeps a correction (one only where it lowered the error).
  o.linear_compensation = false;
  const DriftModel nonlinear = FitDriftModel(train.rate, train.temperature, o);
  ASSERT_TRUE(nonlinear.identified());
  for (const SubModel& sub : nonlinear.sub_models) {
    const CalibrationReport& r = sub.thermal->report;
    // (tried wherever there is a regressor beside the intercept)
    EXPECT_EQ(std::isnan(r.cv_rmse_nonlinear), sub.thermal->coefficients.size() == 1) << sub.name;
    EXPECT_EQ(sub.thermal->correction != nullptr, r.nonlinear_units > 0) << sub.name;
    if (sub.thermal->correction) EXPECT_LT(r.cv_rmse_nonlinear, r.cv_rmse) << sub.name;
  }
  o.reference_c = 300.0;
  EXPECT_THROW(o.Validate(), UsageError);
}

TEST(DriftModel, ThermalMethodIsCompensateOnlyAndTakesSeveralChannels) {
  const Log train = MakeLog(3000, 8);
  DriftOptions o = Fast(Mode::kPredict, Method::kThermal);
  EXPECT_THROW(o.Validate(), UsageError);
  o.mode = Mode::kCompensate;
  Eigen::MatrixXd two(train.temperature.size(), 2);
  two.col(0) = train.temperature;
  Eigen::VectorXd lagged(train.temperature.size());
  FirstOrderLag(train.temperature, 400.0, 1.0, lagged);
  two.col(1) = lagged;
  const DriftModel model = FitDriftModel(train.rate, two, o);
  EXPECT_EQ(model.temperature_channels(), 2);
  EXPECT_EQ(EstimateDrift(model, two).size(), two.rows());
  EXPECT_THROW(EstimateDrift(model, train.temperature), DataError);
  // Feature-based methods take one channel and say so.
  o.method = Method::kPoly;
  EXPECT_THROW(FitDriftModel(train.rate, two, o), UsageError);
}

TEST(DriftModel, AutoLagsPickACandidateOnTheValidationBlock) {
  const Log log = MakeLog(1200, 5);
  DriftOptions o = Fast(Mode::kPredict, Method::kElm);
  o.auto_lags = true;
  o.lag_candidates = {1, 3, 6};
  const DriftModel model = FitDriftModel(log.rate, Eigen::VectorXd(), o);
  ASSERT_EQ(model.lag_validation_rmse.size(), 3u);
  const auto best =
      std::min_element(model.lag_validation_rmse.begin(), model.lag_validation_rmse.end());
  EXPECT_EQ(model.lags,
            o.lag_candidates[static_cast<size_t>(best - model.lag_validation_rmse.begin())]);
}

TEST(DriftModel, BadInputIsRejected) {
  const Log log = MakeLog(500, 6);
  EXPECT_THROW(FitDriftModel(log.rate, Eigen::VectorXd(), Fast(Mode::kCompensate, Method::kElm)),
               DataError);
  EXPECT_THROW(
      FitDriftModel(log.rate.head(10), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kElm)),
      DataError);
  DriftOptions bad = Fast(Mode::kPredict, Method::kElm);
  bad.features.lags = 0;
  EXPECT_THROW(FitDriftModel(log.rate, Eigen::VectorXd(), bad), UsageError);
  EXPECT_THROW(MethodFromString("lstm"), UsageError);
  EXPECT_THROW(ModeFromString("guess"), UsageError);
}

TEST(Evaluation, ReportsBothProtocolsAndScoresAgainstTruth) {
  const Log log = MakeLog(1000, 7);
  EvaluationOptions eo;
  eo.methods = {Method::kMsElm, Method::kPoly};
  eo.causal.window = 128;
  const EvaluationResult r =
      Evaluate(log.rate, Eigen::VectorXd(), log.drift, Fast(Mode::kPredict, Method::kMsElm), eo);
  ASSERT_EQ(r.rows.size(), 4u);
  EXPECT_EQ(r.split_index, 700);
  EXPECT_TRUE(r.against_truth);
  for (const auto& row : r.rows) {
    EXPECT_EQ(row.estimate.size(), 300);
    EXPECT_GT(row.rmse, 0.0);
    EXPECT_GE(row.max_abs, row.rmse);
  }
  // Single models do not decompose: both protocols are the same computation.
  EXPECT_EQ(r.rows[2].rmse, r.rows[3].rmse);
  EXPECT_NE(r.Table().find("ms-elm"), std::string::npos);
  EXPECT_TRUE(std::isnan(r.training_temperature_min_c));  // no temperature given
  EXPECT_EQ(r.test_outside_training_temperature_share, 0.0);
}

// With a horizon, both protocols score PredictAhead's predictions: the causal row is the model
// fitted on the training block predicting 6 steps ahead, the paper row the same recursion from
// the whole record's sub-series; compensate mode has no horizon.
TEST(Evaluation, ScoresPredictionsAheadWithAHorizon) {
  const Log log = MakeLog(1000, 8);
  EvaluationOptions eo;
  eo.methods = {Method::kMsElm, Method::kElm};
  eo.causal.window = 128;
  eo.horizon = 6;
  const DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  const EvaluationResult r = Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo);
  ASSERT_EQ(r.rows.size(), 4u);
  DriftOptions elm = o;
  elm.method = Method::kElm;
  const DriftModel single = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), elm);
  EXPECT_EQ(r.rows[2].estimate,
            PredictAhead(single, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal));
  const DriftModel ms = FitDriftModel(log.rate.head(700), Eigen::VectorXd(), o);
  EXPECT_EQ(r.rows[1].estimate,
            PredictAhead(ms, log.rate, Eigen::VectorXd(), 700, 6, Protocol::kCausal, eo.causal));
  eo.horizon = 1;
  const EvaluationResult one = Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo);
  EXPECT_NE(one.rows[0].estimate, r.rows[0].estimate);  // paper protocol: 1 against 6 steps
  eo.horizon = 2;
  EXPECT_THROW(
      Evaluate(log.rate, log.temperature, log.drift, Fast(Mode::kCompensate, Method::kPoly), eo),
      UsageError);
  eo.horizon = 0;
  EXPECT_THROW(eo.Validate(), UsageError);
  // A horizon reaching back past the training block's history is refused before any fit.
  eo.horizon = 690;
  EXPECT_THROW(Evaluate(log.rate, Eigen::VectorXd(), log.drift, o, eo), OptionError);
  // The causal options are checked as PredictAhead checks them.
  eo.horizon = 1;
  eo.causal.ensemble_size = -1;
  EXPECT_THROW(eo.Validate(), OptionError);
}

// Shared white-noise EMDs serve one record length: a model fitted with a set in its options does
// not keep it, and predicts on records of any length.
TEST(DriftModel, AModelKeepsNoSharedNoiseEmds) {
  const Log log = MakeLog(600, 4);
  DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  decomposition::DecompositionOptions d = o.decomposition;
  d.seed = o.seed;
  o.decomposition.noise_emds = std::make_shared<const decomposition::NoiseEmds>(500, d);
  const DriftModel model = FitDriftModel(log.rate.head(500), Eigen::VectorXd(), o);
  EXPECT_EQ(model.options.decomposition.noise_emds, nullptr);
  o.decomposition.noise_emds = nullptr;
  const DriftModel plain = FitDriftModel(log.rate.head(500), Eigen::VectorXd(), o);
  EXPECT_EQ(PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kPaper),
            PredictOneStep(plain, log.rate, Eigen::VectorXd(), 500, Protocol::kPaper));
}

TEST(Evaluation, SaysWhereTheTestTemperatureLeavesTheTrainingRange) {
  Log log = MakeLog(1000, 9);
  // A slow warming on top of the cycle: the last 300 samples reach above anything before them.
  for (Eigen::Index t = 0; t < 1000; ++t) log.temperature[t] += 0.02 * static_cast<double>(t);
  EvaluationOptions eo;
  eo.methods = {Method::kPoly};
  const EvaluationResult r =
      Evaluate(log.rate, log.temperature, log.drift, Fast(Mode::kCompensate, Method::kPoly), eo);
  EXPECT_EQ(r.training_temperature_max_c, log.temperature.head(700).maxCoeff());
  const double expected =
      static_cast<double>(
          (log.temperature.tail(300).array() > r.training_temperature_max_c).count()) /
      300.0;
  EXPECT_GT(expected, 0.2);
  EXPECT_EQ(r.test_outside_training_temperature_share, expected);
  EXPECT_EQ(ShareOutsideRange(log.temperature, std::nan(""), std::nan("")), 0.0);
}

}  // namespace
}  // namespace gyrodrift::drift
