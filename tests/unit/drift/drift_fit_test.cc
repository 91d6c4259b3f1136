// FitDriftModel (drift_fit.cc): the white-noise level taken from the decomposition, the seed
// rule of its random streams, its progress, automatic lags, records, what a model keeps, and the
// input it refuses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "drift/fit_steps.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

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
    if (model.sub_models[g].mean) continue;  // a white group predicted by its mean draws nothing
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

// Progress runs from the decomposition (0) through the grouping to the sub-model fits (1), in
// order, naming the two steps; it changes nothing in the model.
TEST(DriftModel, FitReportsItsProgressInOrderAndUnchanged) {
  const Log log = MakeLog(1500, 2);
  DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  const DriftModel quiet = FitDriftModel(log.rate, Eigen::VectorXd(), o);
  std::mutex mutex;
  std::vector<std::pair<double, std::string>> seen;
  const Execution execution{.progress = [&](double fraction, std::string_view step) {
    std::lock_guard<std::mutex> lock(mutex);
    seen.emplace_back(fraction, step);
  }};
  const DriftModel reported = FitDriftModel(log.rate, Eigen::VectorXd(), o, {}, execution);
  EXPECT_EQ(reported.Summary(), quiet.Summary());
  EXPECT_EQ(PredictOneStep(reported, log.rate, Eigen::VectorXd(), 4, Protocol::kPaper),
            PredictOneStep(quiet, log.rate, Eigen::VectorXd(), 4, Protocol::kPaper));
  EXPECT_EQ(reported.options, quiet.options);
  ASSERT_GE(seen.size(), 3u);
  EXPECT_EQ(seen.front(), std::make_pair(0.0, std::string("decompose")));
  EXPECT_EQ(seen.back(), std::make_pair(1.0, std::string("fit sub-models")));
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_GE(seen[i].first, seen[i - 1].first) << i;
    // Never back from fitting to decomposing.
    EXPECT_FALSE(seen[i - 1].second == "fit sub-models" && seen[i].second == "decompose") << i;
  }
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

// MS-ELM's noise group: white, it is predicted by its training mean unless its learner beats the
// mean on the held-out last validation_fraction of the block (learner fitted on the rest). A
// white series gets the mean; an autocorrelated one, which its lags predict, keeps its learner;
// only the group named noise is judged.
TEST(DriftModel, WhiteNoiseGroupIsPredictedByItsMeanUnlessItsLearnerBeatsIt) {
  const Eigen::Index n = 1500;
  Eigen::VectorXd white(n), ar(n), slow(n);
  Rng rng(9, 0);
  rng.FillNormal(white);
  white.array() += 0.3;
  double state = 0.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    state = 0.95 * state + rng.Normal();
    ar[t] = state;
    slow[t] = std::sin(static_cast<double>(t) / 200.0);
  }
  auto fit = [&](const Eigen::VectorXd& noise_series, const std::string& first_name) {
    DriftModel model;
    model.options = Fast(Mode::kPredict, Method::kMsElm);
    model.sub_models.push_back({first_name, {1}, false, nullptr});
    model.sub_models.push_back({"drift", {}, true, nullptr});
    Eigen::MatrixXd series(n, 2);
    series << noise_series, slow;
    internal::FitLearners(model, series, series.rowwise().sum(), Eigen::MatrixXd(n, 0), n,
                          Eigen::MatrixXd(), {}, 1);
    return std::make_pair(model, series);
  };
  const auto [white_model, white_series] = fit(white, "noise");
  ASSERT_TRUE(white_model.sub_models[0].mean.has_value());
  EXPECT_EQ(white_model.sub_models[0].learner, nullptr);
  EXPECT_EQ(*white_model.sub_models[0].mean, white.mean());
  EXPECT_NE(white_model.sub_models[1].learner, nullptr);  // the drift group is not judged
  EXPECT_FALSE(white_model.sub_models[1].mean.has_value());
  // The prediction is the drift learner's plus the constant, at every horizon.
  DriftModel drift_only = white_model;
  drift_only.sub_models.erase(drift_only.sub_models.begin());
  for (int horizon : {1, 5}) {
    const Eigen::VectorXd with_mean =
        PredictFromSeries(white_model, white_series, Eigen::MatrixXd(n, 0), 100, 50, horizon);
    const Eigen::VectorXd alone = PredictFromSeries(drift_only, white_series.rightCols(1),
                                                    Eigen::MatrixXd(n, 0), 100, 50, horizon);
    EXPECT_LE(((with_mean - alone).array() - white.mean()).abs().maxCoeff(), 1e-12) << horizon;
  }
  const auto [ar_model, ar_series] = fit(ar, "noise");
  EXPECT_NE(ar_model.sub_models[0].learner, nullptr);
  EXPECT_FALSE(ar_model.sub_models[0].mean.has_value());
  const auto [mixed_model, mixed_series] = fit(white, "mixed");
  EXPECT_NE(mixed_model.sub_models[0].learner, nullptr);
}

// Several records are for the thermal method in compensate mode (its lag states restart at each);
// every other method needs one uniform record.
TEST(DriftModel, SeveralRecordsAreFittedByTheThermalMethodOnly) {
  const Log log = MakeLog(3000, 9);
  const std::vector<Eigen::Index> starts{1500};
  const DriftModel thermal =
      FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kThermal), starts);
  ASSERT_TRUE(thermal.identified());
  EXPECT_EQ(thermal.sub_models.front().thermal->report.records, 2);
  EXPECT_THROW(
      FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kPoly), starts),
      UsageError);
  EXPECT_THROW(
      FitDriftModel(log.rate, Eigen::VectorXd(), Fast(Mode::kPredict, Method::kElm), starts),
      UsageError);
}

// A log whose gaps were filled (io::GapPolicy::kCarry): the thermal features run over every row,
// the fit uses the logged rows only, whatever the made-up rows hold.
TEST(DriftModel, AMaskOfLoggedRowsKeepsTheFitToThem) {
  const Log log = MakeLog(3000, 11);
  std::vector<bool> logged(3000, false);
  for (size_t i = 0; i < logged.size(); i += 100) {
    for (size_t k = 0; k < 10; ++k) logged[i + k] = true;  // 10 of every 100 rows
  }
  const DriftOptions o = Fast(Mode::kCompensate, Method::kPoly);
  Eigen::VectorXd spoiled = log.rate;
  for (Eigen::Index i = 0; i < spoiled.size(); ++i) {
    if (!logged[static_cast<size_t>(i)]) spoiled[i] = std::nan("");
  }
  const DriftModel masked = FitDriftModel(spoiled, log.temperature, o, {}, {}, logged);
  // The same learner fitted by hand on the logged rows of the full-record features.
  const DriftModel full = FitDriftModel(log.rate, log.temperature, o);
  const FeatureOptions features = EffectiveFeatures(full.options);
  const Eigen::MatrixXd x = ThermalFeatures(log.temperature, features);
  const DriftModel refit = [&] {
    DriftModel m = full;
    m.sub_models.front().learner =
        FitLearner(LoggedRows(x, logged), LoggedRows(log.rate, logged), [&] {
          LearnerOptions l = full.options.learner;
          l.kind = LearnerKind::kPoly;
          l.seed = SeedFor(full.options.seed, "sub-model", 0);
          return l;
        }());
    return m;
  }();
  EXPECT_EQ(EstimateDrift(masked, log.temperature), EstimateDrift(refit, log.temperature));
  EXPECT_NE(EstimateDrift(masked, log.temperature), EstimateDrift(full, log.temperature));
  // A decomposition (or a prediction from the output's past) would read the made-up rows.
  EXPECT_THROW(FitDriftModel(log.rate, log.temperature, Fast(Mode::kCompensate, Method::kMsElm),
                             {}, {}, logged),
               UsageError);
  EXPECT_THROW(FitDriftModel(log.rate, Eigen::VectorXd(), Fast(Mode::kPredict, Method::kPoly), {},
                             {}, logged),
               UsageError);
  EXPECT_THROW(FitDriftModel(log.rate, log.temperature, o, {}, {}, std::vector<bool>(10, true)),
               DataError);
  // The model says how many samples it was fitted on: the logged ones.
  EXPECT_EQ(masked.training_samples, 300);
  // The constant too is the logged rows' (it was the grid's until 2026-11-27).
  const DriftModel constant = FitDriftModel(
      spoiled, log.temperature, Fast(Mode::kCompensate, Method::kConstant), {}, {}, logged);
  EXPECT_EQ(constant.training_samples, 300);
  EXPECT_DOUBLE_EQ(EstimateDrift(constant, log.temperature)[0],
                   LoggedRows(log.rate, logged).mean());
}

// Options are plain values: a model holds the options it was fitted with (the thermal time
// constants limited to the record, as FitDriftModel does), whatever execution ran the fit, and
// the same options compare equal (reference_c unset included).
TEST(DriftModel, AModelHoldsTheOptionsItWasFittedWith) {
  const Log log = MakeLog(600, 4);
  const DriftOptions o = Fast(Mode::kPredict, Method::kMsElm);
  EXPECT_EQ(DriftOptions(), DriftOptions());
  EXPECT_EQ(o, Fast(Mode::kPredict, Method::kMsElm));
  EXPECT_NE(o, Fast(Mode::kPredict, Method::kElm));
  int calls = 0;
  const DriftModel one =
      FitDriftModel(log.rate.head(500), Eigen::VectorXd(), o, {},
                    {.threads = 1, .progress = [&calls](double, std::string_view) { ++calls; }});
  const DriftModel two =
      FitDriftModel(log.rate.head(500), Eigen::VectorXd(), o, {}, {.threads = 2});
  EXPECT_GT(calls, 0);
  DriftOptions expected = o;
  expected.features = ForTrainingRecord(o.features, 500);
  EXPECT_EQ(one.options, expected);
  EXPECT_EQ(two.options, expected);
  EXPECT_EQ(PredictOneStep(one, log.rate, Eigen::VectorXd(), 500, Protocol::kPaper),
            PredictOneStep(two, log.rate, Eigen::VectorXd(), 500, Protocol::kPaper));
  EXPECT_THROW(FitDriftModel(log.rate, Eigen::VectorXd(), o, {}, {.threads = -1}), UsageError);
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

}  // namespace
}  // namespace gyrodrift::drift
