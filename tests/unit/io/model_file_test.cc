// Model files: every method in both modes survives a save/load round trip with predictions equal
// to the bit; options and awkward doubles come back exactly; damaged, foreign, incomplete or
// mis-shaped files are refused with a message naming the problem.
#include "gyrodrift/io/model_file.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::io {
namespace {

using drift::Method;
using drift::Mode;
using nlohmann::json;

struct Log {
  Eigen::VectorXd rate, temperature;
};

// Temperature swings, a drift following a lagged temperature and its rate, white noise.
Log MakeLog(Eigen::Index n, std::uint64_t seed) {
  Log log{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Rng rng(seed, 0);
  double lagged = 20.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / static_cast<double>(n);
    log.temperature[t] = 20.0 + 15.0 * std::sin(2 * std::numbers::pi * 1.5 * x);
    const double previous = lagged;
    lagged += (log.temperature[t] - lagged) / 40.0;
    log.rate[t] = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous) + 0.02 * rng.Normal();
  }
  return log;
}

drift::DriftOptions Small(Mode mode, Method method) {
  drift::DriftOptions o;
  o.mode = mode;
  o.method = method;
  o.decomposition.ensemble_size = 10;
  o.selection.monte_carlo.realisations = 20;
  o.features.time_constants_s = {30.0, 120.0};
  o.learner.bp_epochs = 50;
  o.seed = 5;
  return o;
}

ModelFileInfo Info() { return {"rate_dph", "temperature_c", "train.csv", ""}; }

// Recomputes the checksum after a deliberate edit, so the test reaches the field checks.
std::string Reseal(json j) {
  j.erase("checksum");
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx",
                static_cast<unsigned long long>(
                    Fnv1a64(j.dump(-1, ' ', false, json::error_handler_t::replace))));
  j["checksum"] = std::string("fnv1a64:") + hex;
  return j.dump(1);
}

void ExpectRefused(const std::string& text, const std::string& message) {
  try {
    ParseModelFile(text, "m.json");
    ADD_FAILURE() << "accepted; expected: " << message;
  } catch (const DataError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(message), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    EXPECT_EQ(what.rfind("m.json: ", 0), 0u) << what;
  }
}

class EveryMethod : public ::testing::TestWithParam<std::tuple<Mode, Method>> {};

TEST_P(EveryMethod, RoundTripGivesIdenticalPredictions) {
  const auto [mode, method] = GetParam();
  const Log log = MakeLog(260, 11);
  drift::DriftOptions o = Small(mode, method);
  // Predict mode with the thermal history too, so every input path is exercised.
  if (mode == Mode::kPredict && method == Method::kElm) o.features.use_temperature = true;
  const drift::DriftModel model = drift::FitDriftModel(log.rate, log.temperature, o);
  const std::string text = RenderModelFile(model, Info());
  const LoadedModel loaded = ParseModelFile(text, "m.json");

  EXPECT_EQ(loaded.info.target_column, "rate_dph");
  EXPECT_EQ(loaded.info.temperature_column, "temperature_c");
  EXPECT_EQ(loaded.info.source, "train.csv");
  EXPECT_FALSE(loaded.info.tool_version.empty());
  EXPECT_EQ(loaded.model.options, model.options);
  ASSERT_EQ(loaded.model.sub_models.size(), model.sub_models.size());
  for (size_t g = 0; g < model.sub_models.size(); ++g) {
    EXPECT_EQ(loaded.model.sub_models[g].name, model.sub_models[g].name);
    EXPECT_EQ(loaded.model.sub_models[g].imfs, model.sub_models[g].imfs);
    EXPECT_EQ(loaded.model.sub_models[g].has_residue, model.sub_models[g].has_residue);
    EXPECT_EQ(loaded.model.sub_models[g].learner == nullptr,
              model.sub_models[g].learner == nullptr);
  }
  EXPECT_EQ(loaded.model.lags, model.lags);
  EXPECT_EQ(loaded.model.training_imfs, model.training_imfs);
  EXPECT_EQ(loaded.model.training_samples, model.training_samples);
  EXPECT_EQ(loaded.model.Summary(), model.Summary());
  // Everything that was written comes back: the loaded model renders to the same bytes.
  EXPECT_EQ(RenderModelFile(loaded.model, loaded.info), text);

  const Log test = MakeLog(200, 12);
  if (mode == Mode::kCompensate) {
    const Eigen::VectorXd a = drift::EstimateDrift(model, test.temperature);
    const Eigen::VectorXd b = drift::EstimateDrift(loaded.model, test.temperature);
    EXPECT_TRUE(a.allFinite());
    EXPECT_EQ(a, b);  // bit for bit
  } else {
    const Eigen::VectorXd t = model.uses_temperature() ? test.temperature : Eigen::VectorXd();
    const Eigen::VectorXd a =
        drift::PredictOneStep(model, test.rate, t, 20, drift::Protocol::kPaper);
    const Eigen::VectorXd b =
        drift::PredictOneStep(loaded.model, test.rate, t, 20, drift::Protocol::kPaper);
    EXPECT_TRUE(a.allFinite());
    EXPECT_EQ(a, b);
    drift::CausalOptions causal;
    causal.window = 64;
    const Eigen::VectorXd c =
        drift::PredictOneStep(model, test.rate, t, 190, drift::Protocol::kCausal, causal);
    const Eigen::VectorXd d =
        drift::PredictOneStep(loaded.model, test.rate, t, 190, drift::Protocol::kCausal, causal);
    EXPECT_EQ(c, d);
  }
}

INSTANTIATE_TEST_SUITE_P(ModelFile, EveryMethod,
                         ::testing::Combine(::testing::Values(Mode::kPredict, Mode::kCompensate),
                                            ::testing::Values(Method::kMsElm, Method::kElm,
                                                              Method::kEmdElm, Method::kPoly,
                                                              Method::kSvr, Method::kBp)),
                         // (kThermal is compensate-only: the test above)
                         [](const auto& info) {
                           std::string name =
                               std::string(drift::ToString(std::get<0>(info.param))) + "_" +
                               std::string(drift::ToString(std::get<1>(info.param)));
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });

// The baselines (drift/baseline.h): their one sub-model holds a "baseline", no learner.
INSTANTIATE_TEST_SUITE_P(
    ModelFileBaselines, EveryMethod,
    ::testing::Values(std::tuple{Mode::kPredict, Method::kNone},
                      std::tuple{Mode::kPredict, Method::kConstant},
                      std::tuple{Mode::kPredict, Method::kPersistence},
                      std::tuple{Mode::kPredict, Method::kTrailingMean},
                      std::tuple{Mode::kPredict, Method::kExpSmoothing},
                      std::tuple{Mode::kPredict, Method::kKalmanLevel},
                      std::tuple{Mode::kPredict, Method::kKalmanTrend},
                      std::tuple{Mode::kCompensate, Method::kNone},
                      std::tuple{Mode::kCompensate, Method::kConstant}),
    [](const auto& info) {
      std::string name = std::string(drift::ToString(std::get<0>(info.param))) + "_" +
                         std::string(drift::ToString(std::get<1>(info.param)));
      for (char& c : name) {
        if (c == '-') c = '_';
      }
      return name;
    });

// A baseline's parameters are checked on reading; a learner's model cannot claim one.
TEST(ModelFile, ABaselineOutOfRangeOrMisplacedIsRefused) {
  const Log log = MakeLog(260, 13);
  const drift::DriftModel model = drift::FitDriftModel(
      log.rate, Eigen::VectorXd(), Small(Mode::kPredict, Method::kExpSmoothing));
  json j = json::parse(RenderModelFile(model, Info()));
  j["model"]["sub_models"][0]["baseline"]["alpha"] = 2.0;
  ExpectRefused(Reseal(j), "baseline alpha = 2: must be in (0, 1]");
  j["model"]["sub_models"][0].erase("baseline");
  ExpectRefused(Reseal(j), "has no \"baseline\"");
  const drift::DriftModel poly =
      drift::FitDriftModel(log.rate, Eigen::VectorXd(), Small(Mode::kPredict, Method::kPoly));
  j = json::parse(RenderModelFile(poly, Info()));
  j["model"]["sub_models"][0]["baseline"] = j["model"]["sub_models"][0]["learner"];
  ExpectRefused(Reseal(j), "only a baseline method's model has");
}

TEST(ModelFile, IdentifiedModelsOfTwoChannelsWithACorrectionComeBackExactly) {
  const Log log = MakeLog(4000, 13);
  Eigen::MatrixXd two(log.temperature.size(), 2);
  two.col(0) = log.temperature;
  Eigen::VectorXd board(log.temperature.size());
  drift::FirstOrderLag(log.temperature, 200.0, 1.0, board);
  two.col(1) = board.array() + 5.0;
  for (Method method : {Method::kThermal, Method::kMsElm}) {
    drift::DriftOptions o = Small(Mode::kCompensate, method);
    o.linear_compensation = false;  // try the nonlinear correction
    o.thermal.max_states = 1;
    const drift::DriftModel model = drift::FitDriftModel(log.rate, two, o);
    ASSERT_TRUE(model.identified());
    // (a group the cross-validation fits by its mean alone has no regressor to correct)
    EXPECT_TRUE(std::any_of(model.sub_models.begin(), model.sub_models.end(), [](const auto& sub) {
      return !std::isnan(sub.thermal->report.cv_rmse_nonlinear);
    })) << model.Summary();
    ModelFileInfo info = Info();
    info.temperature_column = "case_c,board_c";
    const std::string text = RenderModelFile(model, info);
    const LoadedModel loaded = ParseModelFile(text, "m.json");
    EXPECT_EQ(loaded.info.temperature_column, "case_c,board_c");
    EXPECT_EQ(loaded.model.temperature_channels(), 2);
    EXPECT_EQ(RenderModelFile(loaded.model, loaded.info), text);
    const Eigen::MatrixXd test = two.topRows(900);
    EXPECT_EQ(drift::EstimateDriftWithSd(model, test), drift::EstimateDriftWithSd(loaded.model, test))
        << ToString(method);
  }
  // A stored regressor list that does not match the states is refused by name.
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, Small(Mode::kCompensate, Method::kThermal));
  json j = json::parse(RenderModelFile(model, Info()));
  j["model"]["sub_models"][0]["thermal"]["regressors"][0] = "2";
  try {
    ParseModelFile(Reseal(j), "m.json");
    ADD_FAILURE() << "accepted a regressor list that does not match the states";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("regressors"), std::string::npos) << e.what();
  }
}

TEST(ModelFile, AHysteresisTermComesBackExactlyAndOlderFilesReadWithout) {
  // A bias that differs between heating and cooling: a backlash of 1 K on the temperature.
  Log log = MakeLog(4000, 17);
  double play = log.temperature[0];
  for (Eigen::Index t = 0; t < log.rate.size(); ++t) {
    play = std::clamp(play, log.temperature[t] - 1.0, log.temperature[t] + 1.0);
    log.rate[t] += 0.3 * (log.temperature[t] - play);
  }
  drift::DriftOptions o = Small(Mode::kCompensate, Method::kThermal);
  o.thermal.hysteresis = drift::HysteresisTerm::kOn;
  const drift::DriftModel model = drift::FitDriftModel(log.rate, log.temperature, o);
  ASSERT_TRUE(model.sub_models[0].thermal->has_hysteresis()) << model.Summary();
  const std::string text = RenderModelFile(model, Info());
  const LoadedModel loaded = ParseModelFile(text, "m.json");
  EXPECT_EQ(RenderModelFile(loaded.model, loaded.info), text);
  EXPECT_EQ(loaded.model.options.thermal, o.thermal);
  EXPECT_EQ(drift::EstimateDriftWithSd(model, log.temperature),
            drift::EstimateDriftWithSd(loaded.model, log.temperature));
  // A term naming a state the model does not have is refused.
  json j = json::parse(text);
  j["model"]["sub_models"][0]["thermal"]["hysteresis"]["state"] = 7;
  ExpectRefused(Reseal(j), "hysteresis");
  // Files before version 5 were identified without the term: their options say so.
  j = json::parse(RenderModelFile(
      drift::FitDriftModel(log.rate, log.temperature, Small(Mode::kCompensate, Method::kThermal)),
      Info()));
  j["format_version"] = 4;
  j["options"]["thermal"].erase("hysteresis");
  j["options"]["thermal"].erase("hysteresis_widths_k");
  j["model"]["sub_models"][0]["thermal"].erase("hysteresis");
  j["model"]["sub_models"][0]["thermal"]["report"].erase("hysteresis_tried");
  j["model"]["sub_models"][0]["thermal"]["report"].erase("prior_samples");
  const LoadedModel old = ParseModelFile(Reseal(j), "v4.json");
  EXPECT_EQ(old.model.options.thermal.hysteresis, drift::HysteresisTerm::kOff);
  EXPECT_FALSE(old.model.sub_models[0].thermal->has_hysteresis());
  EXPECT_EQ(old.model.sub_models[0].thermal->report.prior_samples, 0.0);  // no ridge before it
  // The sparse-log ridge's strength comes back as written.
  j["model"]["sub_models"][0]["thermal"]["report"]["prior_samples"] = 16.0;
  EXPECT_EQ(ParseModelFile(Reseal(j), "v4.json").model.sub_models[0].thermal->report.prior_samples,
            16.0);
}

// A heat-up's model continues its cooling rates beyond the run's at a share of their slope
// (rate_beyond, version 9); it comes back exactly, a file before version 9 holds them at the
// edge, and a share outside [0, 1] is refused.
TEST(ModelFile, TheShareOfAnUnshownRateComesBackAndOlderFilesHoldTheRate) {
  const Eigen::Index n = 4000;
  Log heat{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Rng rng(21, 0);
  double lagged = 0.0;
  for (Eigen::Index t = 0; t < n; ++t) {
    heat.temperature[t] = 40.0 * std::clamp((static_cast<double>(t) / n - 0.1) / 0.6, 0.0, 1.0);
    const double previous = lagged;
    lagged += (heat.temperature[t] - lagged) / 40.0;
    heat.rate[t] = 0.01 * (lagged - 20.0) + 4.0 * (lagged - previous) + 0.02 * rng.Normal();
  }
  const drift::DriftModel model =
      drift::FitDriftModel(heat.rate, heat.temperature, Small(Mode::kCompensate, Method::kThermal));
  const auto& states = model.sub_models[0].thermal->states;
  ASSERT_FALSE(states.empty()) << model.Summary();
  ASSERT_TRUE(std::isfinite(states[0].rate_min)) << model.Summary();
  EXPECT_EQ(states[0].rate_beyond, 0.5);
  const std::string text = RenderModelFile(model, Info());
  const LoadedModel loaded = ParseModelFile(text, "m.json");
  EXPECT_EQ(RenderModelFile(loaded.model, loaded.info), text);
  const Eigen::VectorXd cooling = MakeLog(2000, 22).temperature;  // cools at up to 1.4 K/min
  EXPECT_EQ(drift::EstimateDrift(model, cooling), drift::EstimateDrift(loaded.model, cooling));
  json j = json::parse(text);
  j["format_version"] = 8;
  j["model"]["sub_models"][0]["thermal"]["states"][0].erase("rate_beyond");
  const LoadedModel old = ParseModelFile(Reseal(j), "v8.json");
  EXPECT_EQ(old.model.sub_models[0].thermal->states[0].rate_beyond, 0.0);
  drift::DriftModel held = model;
  auto thermal = std::make_shared<drift::ThermalRegression>(*model.sub_models[0].thermal);
  thermal->states[0].rate_beyond = 0.0;
  held.sub_models[0].thermal = thermal;
  EXPECT_EQ(drift::EstimateDrift(old.model, cooling), drift::EstimateDrift(held, cooling));
  EXPECT_NE(drift::EstimateDrift(old.model, cooling), drift::EstimateDrift(model, cooling));
  j = json::parse(text);
  j["model"]["sub_models"][0]["thermal"]["states"][0]["rate_beyond"] = 2.0;
  ExpectRefused(Reseal(j), "rate_beyond is outside [0, 1]");
}

TEST(ModelFile, EveryOptionAndAwkwardDoublesComeBackExactly) {
  drift::DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kEmdElm;
  o.decomposition.method = decomposition::Method::kIceemdan;
  o.decomposition.sifting.stop_rule = decomposition::StopRule::kSNumber;
  o.decomposition.sifting.rilling_threshold1 = 0.1 + 0.2;  // 0.30000000000000004
  o.decomposition.sifting.rilling_threshold2 = 0.7;
  o.decomposition.sifting.s_number = 6;
  o.decomposition.sifting.max_sifts = 77;
  o.decomposition.max_imfs = 9;
  o.decomposition.ensemble_size = 33;
  o.decomposition.noise_strength = 1.0 / 3.0;
  o.decomposition.seed = std::numeric_limits<std::uint64_t>::max();
  o.decomposition.noise_scaling = decomposition::NoiseScaling::kConstantSnr;
  o.decomposition.beemdan_bound = decomposition::BeemdanBound::kFixedStages;
  o.decomposition.band_confidence = 0.95;
  o.decomposition.noise_stages = 2;
  o.selection.criterion = selection::Criterion::kKomaty;
  o.selection.distance = selection::PdfDistance::kHellinger;
  o.selection.kde.grid_points = 1000;
  o.selection.kde.bandwidth_scale = std::nextafter(1.0, 2.0);
  o.selection.kde.method = selection::KdeMethod::kDirect;
  o.selection.center_signal = false;
  o.selection.monte_carlo.realisations = 21;
  o.selection.monte_carlo.seed = 1ULL << 63;
  o.selection.monte_carlo.sifting.stop_rule = decomposition::StopRule::kFixed;
  o.features.lags = 7;
  o.features.time_constants_s = {std::nextafter(60.0, 0.0), 1e6, 1.0};
  o.features.rate_hz = 1.0 / 7.0;
  o.features.thermal_set = drift::ThermalSet::kLagBank;
  o.learner.elm.hidden_units = 12;
  o.learner.elm.activation = elm::Activation::kTanh;
  o.learner.elm.solver = elm::Solver::kQr;
  o.learner.elm.selection = elm::Selection::kFixed;
  o.learner.elm.ridge_c = std::numeric_limits<double>::infinity();  // no ridge: QR
  o.learner.elm.hidden_unit_candidates = {3, 12};
  o.learner.elm.ridge_c_candidates = {4.9406564584124654e-300, 1e10};
  o.learner.elm.standardize_targets = false;
  o.learner.poly_degree = 3;
  o.learner.svr_gamma = 0.125;
  o.learner.bp_hidden = {4, 3};
  o.auto_lags = true;
  o.lag_candidates = {2, 3};
  o.validation_fraction = 0.25;
  o.linear_compensation = false;
  o.reference_c.reset();  // keep the fitted intercept
  o.thermal.shortest_tau_s = 17.0;
  o.thermal.taus_per_octave = 3;
  o.thermal.longest_tau_share = 0.1 + 0.2;
  o.thermal.max_states = 3;
  o.thermal.folds_at_regimes = true;
  o.thermal.hysteresis = drift::HysteresisTerm::kOn;
  o.thermal.hysteresis_widths_k = {0.1 + 0.2, 3.0};
  o.seed = 123456789012345ULL;
  const json j = DriftOptionsToJson(o);
  const json reparsed = json::parse(j.dump());
  const drift::DriftOptions r = DriftOptionsFromJson(reparsed, "x");
  EXPECT_EQ(DriftOptionsToJson(r), j);
  EXPECT_EQ(r, o);                     // every field, as values
  EXPECT_EQ(j["reference_c"], "nan");  // unset, as older files wrote it
  drift::DriftOptions referenced = o;
  referenced.reference_c = 25.5;
  EXPECT_EQ(DriftOptionsFromJson(json::parse(DriftOptionsToJson(referenced).dump()), "x"),
            referenced);
  EXPECT_EQ(r.decomposition.sifting.rilling_threshold1, 0.1 + 0.2);
  EXPECT_EQ(r.decomposition.noise_strength, 1.0 / 3.0);
  EXPECT_EQ(r.decomposition.seed, std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(r.selection.kde.bandwidth_scale, std::nextafter(1.0, 2.0));
  EXPECT_EQ(r.selection.monte_carlo.seed, 1ULL << 63);
  EXPECT_EQ(r.features.time_constants_s, o.features.time_constants_s);
  EXPECT_EQ(r.features.rate_hz, 1.0 / 7.0);
  EXPECT_EQ(r.features.thermal_set, drift::ThermalSet::kLagBank);
  // A file written before the feature set was stored means "auto".
  json old_file = reparsed;
  old_file["features"].erase("thermal_set");
  EXPECT_EQ(DriftOptionsFromJson(old_file, "x").features.thermal_set, drift::ThermalSet::kAuto);
  EXPECT_TRUE(std::isinf(r.learner.elm.ridge_c));
  EXPECT_EQ(r.learner.elm.ridge_c_candidates, o.learner.elm.ridge_c_candidates);
  EXPECT_EQ(r.learner.bp_hidden, o.learner.bp_hidden);
  EXPECT_EQ(r.learner.elm.activation, elm::Activation::kTanh);
  EXPECT_EQ(r.selection.distance, selection::PdfDistance::kHellinger);
  EXPECT_EQ(r.lag_candidates, o.lag_candidates);
  EXPECT_EQ(r.seed, o.seed);
  EXPECT_FALSE(r.linear_compensation);
  EXPECT_FALSE(r.reference_c);
  EXPECT_EQ(r.thermal, o.thermal);
  EXPECT_EQ(j["learner"]["elm"]["ridge_c"], "inf");
}

TEST(ModelFile, RandomDoublesSurviveTheJsonText) {
  Rng rng(3, 0);
  for (int i = 0; i < 20000; ++i) {
    double v;
    const std::uint64_t bits = rng.NextU64();
    std::memcpy(&v, &bits, sizeof(v));
    if (!std::isfinite(v)) continue;
    const json j = json::parse(json(v).dump());
    ASSERT_EQ(j.get<double>(), v) << json(v).dump();
  }
}

TEST(ModelFile, Fnv1a64KnownVectors) {
  EXPECT_EQ(Fnv1a64(""), 0xcbf29ce484222325ULL);
  EXPECT_EQ(Fnv1a64("a"), 0xaf63dc4c8601ec8cULL);
  EXPECT_EQ(Fnv1a64("foobar"), 0x85944171f73967e8ULL);
}

class Refusal : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const Log log = MakeLog(200, 21);
    const drift::DriftModel model =
        drift::FitDriftModel(log.rate, Eigen::VectorXd(), Small(Mode::kPredict, Method::kElm));
    text_ = new std::string(RenderModelFile(model, {"rate_dph", "", "in.csv", ""}));
  }
  static void TearDownTestSuite() { delete text_; }
  static json Json() { return json::parse(*text_); }
  static std::string* text_;
};
std::string* Refusal::text_ = nullptr;

TEST_F(Refusal, ValidFileLoads) { EXPECT_NO_THROW(ParseModelFile(*text_, "m.json")); }

TEST_F(Refusal, DamagedNumberFailsTheChecksum) {
  std::string damaged = *text_;
  const size_t p = damaged.find("\"output_weights\"");
  ASSERT_NE(p, std::string::npos);
  const size_t digit = damaged.find_first_of("123456789", damaged.find("\"data\"", p));
  damaged[digit] = damaged[digit] == '9' ? '8' : static_cast<char>(damaged[digit] + 1);
  ExpectRefused(damaged, "checksum mismatch");
}

TEST_F(Refusal, NumbersBeyondDoubleAreADataError) {
  // Found by tests/fuzz/fuzz_model_file: the JSON parser's out_of_range escaped as an internal
  // error.
  ExpectRefused("{\"format\": \"gyrodrift-model\", \"x\": -3.7e5958811599461}",
                "number overflow");
}

TEST_F(Refusal, TruncatedFileIsNotJson) {
  ExpectRefused(text_->substr(0, text_->size() / 2), "not valid JSON");
}

TEST_F(Refusal, OtherFormatsAndVersions) {
  ExpectRefused("{\"tool\": \"gyrodrift\"}", "not a gyrodrift model file");
  ExpectRefused("[1, 2]", "not a gyrodrift model file");
  json j = Json();
  j["format"] = "gyrodrift-imfs";
  ExpectRefused(Reseal(j), "not a gyrodrift model file");
  j = Json();
  const int next = kModelFormatVersion + 1;
  j["format_version"] = next;
  ExpectRefused(Reseal(j), "format_version " + std::to_string(next) +
                               " is not supported (this gyrodrift reads versions 1 to " +
                               std::to_string(kModelFormatVersion) + ")");
  j["format_version"] = 0;
  ExpectRefused(Reseal(j), "format_version 0 is not supported");
  // A version-1 file (before the feature set, the limit flag and the range were stored) loads,
  // with what those files meant: the "auto" set, every stored constant, no range.
  j = Json();
  j["format_version"] = 1;
  j["options"]["features"].erase("thermal_set");
  j["options"]["features"].erase("limit_time_constants");
  j["model"].erase("temperature_range_c");
  const LoadedModel old = ParseModelFile(Reseal(j), "v1.json");
  EXPECT_EQ(old.model.options.features.thermal_set, drift::ThermalSet::kAuto);
  EXPECT_FALSE(old.model.options.features.limit_time_constants);
  EXPECT_TRUE(std::isnan(old.model.temperature_min_c));
  // The rate unit is recorded from format 4 on: older files read as "not recorded", a bad one is
  // named.
  EXPECT_EQ(ParseModelFile(*text_, "m.json").info.rate_unit, "dph");
  j = Json();
  j["format_version"] = 3;
  j["training"].erase("rate_unit");
  EXPECT_EQ(ParseModelFile(Reseal(j), "v3.json").info.rate_unit, "");
  j = Json();
  j["training"]["rate_unit"] = "mph";
  ExpectRefused(Reseal(j), "field 'training.rate_unit' = 'mph': must be dph, dps or rads");
  // A range must be ordered and finite.
  j = Json();
  j["model"]["temperature_range_c"] = json::array({30.0, 20.0});
  ExpectRefused(Reseal(j), "temperature_range_c");
}

TEST_F(Refusal, MissingFieldsAreNamed) {
  json j = Json();
  j.erase("checksum");
  ExpectRefused(j.dump(), "field 'checksum' is missing");
  j = Json();
  j["options"].erase("seed");
  ExpectRefused(Reseal(j), "field 'options.seed' is missing");
  j = Json();
  j["options"]["decomposition"]["sifting"].erase("s_number");
  ExpectRefused(Reseal(j), "field 'options.decomposition.sifting.s_number' is missing");
  j = Json();
  j["model"]["sub_models"][0]["learner"]["arrays"].erase("output_weights");
  ExpectRefused(Reseal(j), "output_weights");
}

// Reading ignores what it does not look for, so a field it does not know would be dropped
// without a word: a misspelt option (its default then used instead) or another tool's field.
TEST_F(Refusal, UnknownFieldsAreNamed) {
  json j = Json();
  j["options"]["seeds"] = 7;
  ExpectRefused(Reseal(j), "field 'options.seeds' is not part of a gyrodrift model file");
  j = Json();
  j["model"]["sub_models"][0]["learner"]["arrays"]["bias"] = j["model"]["sub_models"][0]
                                                                ["learner"]["arrays"]["biases"];
  ExpectRefused(Reseal(j), "field 'model.sub_models[0].learner.arrays.bias' is not part");
  j = Json();
  j["comment"] = "fitted on the March chamber run";
  ExpectRefused(Reseal(j), "field 'comment' is not part");
}

TEST_F(Refusal, WrongTypesShapesAndValuesAreNamed) {
  json j = Json();
  j["options"]["seed"] = -3;
  ExpectRefused(Reseal(j), "field 'options.seed' must be an unsigned integer");
  j = Json();
  j["options"]["method"] = "wavelet";
  ExpectRefused(Reseal(j), "field 'options.method' = 'wavelet' is not understood");
  j = Json();
  j["options"]["features"]["rate_hz"] = -1.0;
  ExpectRefused(Reseal(j), "holds an invalid option: features.rate_hz");
  j = Json();
  auto& array = j["model"]["sub_models"][0]["learner"]["arrays"]["output_weights"];
  array["rows"] = array["rows"].get<int>() + 1;
  ExpectRefused(Reseal(j), "values for a");
  j = Json();
  j["model"]["sub_models"][0]["learner"]["arrays"]["biases"]["data"][0] = "many";
  ExpectRefused(Reseal(j),
                "field 'model.sub_models[0].learner.arrays.biases.data[0]' must be a number");
  j = Json();
  j["model"]["sub_models"][0]["learner"] = nullptr;
  ExpectRefused(Reseal(j), "a predict-mode sub-model needs a learner");
  j = Json();
  j["model"]["lags"] = 6;  // the learner was trained on 4 lags
  ExpectRefused(Reseal(j), "takes 4 inputs, the model's options give 6");
  j = Json();
  j["model"]["sub_models"] = json::array();
  ExpectRefused(Reseal(j), "at least one sub-model");
}

// Several gyro axes in one file (issue 13): every axis comes back exactly, in order; a one-axis
// reader refuses the file by naming its axes; the axes' own shape is checked.
TEST(ModelFile, SeveralAxesComeBackExactlyAndInOrder) {
  const Log log = MakeLog(300, 9);
  const drift::DriftModel a =
      drift::FitDriftModel(log.rate, log.temperature, Small(Mode::kCompensate, Method::kThermal));
  const drift::DriftModel b = drift::FitDriftModel(
      (-2.0 * log.rate).eval(), log.temperature, Small(Mode::kCompensate, Method::kPoly));
  const std::vector<LoadedModel> axes = {
      {a, {"gyro_x", "temperature_c", "imu.csv", ""}},
      {b, {"gyro_y", "temperature_c", "imu.csv", ""}}};
  const std::string text = RenderModelFile(axes);
  const std::vector<LoadedModel> loaded = ParseModelFileAxes(text, "m.json");
  ASSERT_EQ(loaded.size(), 2u);
  EXPECT_EQ(loaded[1].info.target_column, "gyro_y");
  EXPECT_EQ(drift::EstimateDrift(loaded[0].model, log.temperature),
            drift::EstimateDrift(a, log.temperature));
  EXPECT_EQ(drift::EstimateDrift(loaded[1].model, log.temperature),
            drift::EstimateDrift(b, log.temperature));
  EXPECT_EQ(RenderModelFile(loaded), text);
  // A one-axis file keeps its layout and is read by both readers.
  EXPECT_EQ(ParseModelFileAxes(RenderModelFile({axes[0]}), "m.json").size(), 1u);
  try {
    ParseModelFile(text, "m.json");
    ADD_FAILURE() << "a two-axis file read as one axis";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("2 axes (gyro_x, gyro_y)"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(RenderModelFile(std::vector<LoadedModel>{}), UsageError);
  EXPECT_THROW(RenderModelFile({axes[0], axes[0]}), UsageError);  // two axes of one target

  auto refused = [](const json& j, const std::string& message) {
    try {
      ParseModelFileAxes(Reseal(j), "m.json");
      ADD_FAILURE() << "accepted; expected: " << message;
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  json j = json::parse(text);
  j["axes"][1]["training"]["target_column"] = "gyro_x";
  refused(j, "field 'axes[1].training.target_column' = 'gyro_x' is the target of an earlier axis");
  j = json::parse(text);
  j["axes"].erase(1);
  refused(j, "field 'axes' holds 1 axes");
  j = json::parse(text);
  j["axes"][0]["options"].erase("seed");
  refused(j, "field 'axes[0].options.seed' is missing");
  j = json::parse(text);
  j["axes"][1]["note"] = 1;
  refused(j, "field 'axes[1].note' is not part");
  j = json::parse(text);
  j["training"] = j["axes"][0]["training"];
  refused(j, "field 'training' is not part");
}

TEST(ModelFile, RefusesToStoreWhatItCannotRebuild) {
  const Log log = MakeLog(200, 41);
  drift::DriftModel model =
      drift::FitDriftModel(log.rate, Eigen::VectorXd(), Small(Mode::kPredict, Method::kPoly));
  model.sub_models[0].learner = nullptr;  // predict mode cannot run a zero sub-model
  EXPECT_THROW(RenderModelFile(model, Info()), UsageError);
}

// A sub-model predicted by its training mean (version 7) comes back as one, with predictions
// equal to the bit; a mean beside a learner, or a non-finite one, is refused; a version-6 file
// (no "mean") reads as before.
TEST(ModelFile, ASubModelPredictedByItsMeanComesBackExactly) {
  const Log log = MakeLog(400, 42);
  drift::DriftModel model =
      drift::FitDriftModel(log.rate, Eigen::VectorXd(), Small(Mode::kPredict, Method::kMsElm));
  ASSERT_GE(model.sub_models.size(), 2u);
  model.sub_models[0].learner = nullptr;
  model.sub_models[0].mean = 0.1 + 1.0 / 3.0;
  const std::string text = RenderModelFile(model, Info());
  const LoadedModel loaded = ParseModelFile(text, "m.json");
  ASSERT_TRUE(loaded.model.sub_models[0].mean.has_value());
  EXPECT_EQ(*loaded.model.sub_models[0].mean, *model.sub_models[0].mean);
  EXPECT_EQ(loaded.model.sub_models[0].learner, nullptr);
  EXPECT_FALSE(loaded.model.sub_models[1].mean.has_value());
  EXPECT_EQ(RenderModelFile(loaded.model, loaded.info), text);
  const Log test = MakeLog(120, 43);
  EXPECT_EQ(drift::PredictOneStep(model, test.rate, Eigen::VectorXd(), 20, drift::Protocol::kPaper),
            drift::PredictOneStep(loaded.model, test.rate, Eigen::VectorXd(), 20,
                                  drift::Protocol::kPaper));
  json j = json::parse(text);
  j["model"]["sub_models"][0]["mean"] = "nan";
  ExpectRefused(Reseal(j), "mean' must be a finite number");
  j = json::parse(text);
  j["model"]["sub_models"][1]["mean"] = 0.5;
  ExpectRefused(Reseal(j), "mean' is for a predict-mode sub-model without a learner");
}

TEST(ModelFile, FilesOnDisk) {
  const std::string dir = test::TempDir("model_file");
  const Log log = MakeLog(200, 31);
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, Small(Mode::kCompensate, Method::kPoly));
  WriteModelFile(dir + "/m.json", model, Info());
  const LoadedModel loaded = ReadModelFile(dir + "/m.json");
  EXPECT_EQ(drift::EstimateDrift(loaded.model, log.temperature),
            drift::EstimateDrift(model, log.temperature));
  EXPECT_THROW(ReadModelFile(dir + "/missing.json"), IoError);
  EXPECT_THROW(WriteModelFile(dir + "/no/such/dir/m.json", model, Info()), IoError);
  EXPECT_FALSE(test::FileExists(dir + "/no/such/dir/m.json"));
}

}  // namespace
}  // namespace gyrodrift::io
