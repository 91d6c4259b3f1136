// The one mapping of the drift settings (fit_settings.h): what the CLI's flags, the Python
// keywords and a manifest's keys set, and a refusal that names the setting, whichever field of
// the options it reached; DriftOptions' own refusals name the dotted path of the field.
#include "gyrodrift/drift/fit_settings.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>

#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {
namespace {

// The option a refusal names ("" when accepted).
std::string Refused(const std::function<void()>& f) {
  try {
    f();
  } catch (const OptionError& e) {
    return e.option();
  }
  return "";
}

FitSettings Compensate() {
  FitSettings s;
  s.mode = "compensate";
  s.has_temperature = true;
  return s;
}

TEST(FitSettings, MapOntoTheOptions) {
  const DriftOptions predict = MakeDriftOptions({.mode = "predict"});
  EXPECT_EQ(predict.method, Method::kMsElm);  // auto in predict mode
  EXPECT_EQ(predict.features.lags, 4);
  EXPECT_FALSE(predict.auto_lags);
  EXPECT_FALSE(predict.features.use_temperature);

  FitSettings s = Compensate();
  s.reference_temperature = 20.0;
  s.nonlinear = true;
  s.hysteresis = "off";
  s.ensemble = 30;
  s.seed = 9;
  s.standard_errors = 0.5;
  const DriftOptions o = MakeDriftOptions(s);
  EXPECT_EQ(o.thermal.standard_errors, 0.5);
  EXPECT_EQ(MakeDriftOptions(Compensate()).thermal.standard_errors,
            ThermalModelOptions{}.standard_errors);
  EXPECT_EQ(o.method, Method::kThermal);  // auto in compensate mode
  EXPECT_EQ(o.reference_c, 20.0);
  EXPECT_FALSE(o.linear_compensation);
  EXPECT_EQ(o.thermal.hysteresis, HysteresisTerm::kOff);
  EXPECT_EQ(o.decomposition.ensemble_size, 30);
  EXPECT_EQ(o.seed, 9u);

  FitSettings p{.mode = "predict", .lags = "auto", .hidden = "12", .has_temperature = true};
  const DriftOptions q = MakeDriftOptions(p);
  EXPECT_TRUE(q.auto_lags);
  EXPECT_EQ(q.learner.elm.hidden_units, 12);
  EXPECT_EQ(q.learner.elm.selection, elm::Selection::kFixed);
  EXPECT_TRUE(q.features.use_temperature);
}

TEST(FitSettings, RefusalsNameTheSetting) {
  auto refused = [](std::function<void(FitSettings&)> change) {
    FitSettings s = Compensate();
    change(s);
    return Refused([&] { MakeDriftOptions(s); });
  };
  EXPECT_EQ(refused([](FitSettings&) {}), "");
  EXPECT_EQ(refused([](FitSettings& s) { s.mode = "guess"; }), "mode");
  EXPECT_EQ(refused([](FitSettings& s) { s.method = "lstm"; }), "method");
  EXPECT_EQ(refused([](FitSettings& s) { s.decomposition = "wavelet"; }), "decomposition");
  EXPECT_EQ(refused([](FitSettings& s) { s.thermal_features = "all"; }), "thermal_features");
  EXPECT_EQ(refused([](FitSettings& s) { s.hysteresis = "sometimes"; }), "hysteresis");
  EXPECT_EQ(refused([](FitSettings& s) { s.lags = "8"; }), "lags");  // compensate mode
  EXPECT_EQ(refused([](FitSettings& s) { s.hidden = "0"; }), "hidden");
  EXPECT_EQ(refused([](FitSettings& s) { s.hidden = "20"; }), "hidden");  // linear thermal
  EXPECT_EQ(refused([](FitSettings& s) { s.reference_temperature = 500.0; }),
            "reference_temperature");
  EXPECT_EQ(refused([](FitSettings& s) {
              s.method = "poly";
              s.hysteresis = "on";
            }),
            "hysteresis");
  EXPECT_EQ(refused([](FitSettings& s) {
              s.method = "poly";
              s.nonlinear = true;
            }),
            "nonlinear");
  EXPECT_EQ(refused([](FitSettings& s) {
              s.method = "poly";
              s.standard_errors = 2.0;
            }),
            "standard_errors");
  // Ranges DriftOptions::Validate owns, named by the setting that set the field.
  EXPECT_EQ(refused([](FitSettings& s) { s.standard_errors = -1.0; }), "standard_errors");
  EXPECT_EQ(refused([](FitSettings& s) { s.ensemble = 0; }), "ensemble");
  EXPECT_EQ(refused([](FitSettings& s) { s.realisations = 5; }), "realisations");
  EXPECT_EQ(refused([](FitSettings& s) { s.time_constants = {0.5}; }), "time_constants");
  EXPECT_EQ(refused([](FitSettings& s) { s.rate_hz = -1.0; }), "rate_hz");
  EXPECT_EQ(refused([](FitSettings& s) { s.threads = -1; }), "threads");
  // Compensate mode without a temperature channel is a usage error, not an option's range.
  FitSettings none = Compensate();
  none.has_temperature = false;
  EXPECT_THROW(MakeDriftOptions(none), UsageError);
}

TEST(DriftOptions, RefusalsNameTheDottedPathOfTheField) {
  auto refused = [](std::function<void(DriftOptions&)> change) {
    DriftOptions o;
    change(o);
    return Refused([&] { o.Validate(); });
  };
  EXPECT_EQ(refused([](DriftOptions&) {}), "");
  EXPECT_EQ(refused([](DriftOptions& o) { o.decomposition.ensemble_size = 0; }),
            "decomposition.ensemble_size");
  EXPECT_EQ(refused([](DriftOptions& o) { o.decomposition.sifting.s_number = 0; }),
            "decomposition.sifting.s_number");
  EXPECT_EQ(refused([](DriftOptions& o) { o.selection.monte_carlo.realisations = 3; }),
            "selection.monte_carlo.realisations");
  EXPECT_EQ(refused([](DriftOptions& o) { o.selection.kde.grid_points = 2; }),
            "selection.kde.grid_points");
  EXPECT_EQ(refused([](DriftOptions& o) { o.features.time_constants_s = {0.5}; }),
            "features.time_constants_s");
  EXPECT_EQ(refused([](DriftOptions& o) { o.thermal.folds = 1; }), "thermal.folds");
  EXPECT_EQ(refused([](DriftOptions& o) { o.learner.elm.ridge_c = -1.0; }),
            "learner.elm.ridge_c");
  EXPECT_EQ(refused([](DriftOptions& o) { o.lag_candidates = {0}; }), "lag_candidates");
}

}  // namespace
}  // namespace gyrodrift::drift
