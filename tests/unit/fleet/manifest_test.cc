// The calibration manifest (fleet/manifest.h): its fit keys map onto the model options as fit's
// flags do (drift::MakeDriftOptions), a refusal names the manifest's line and key, and a unit's
// fingerprint changes with every setting that shapes its results, the hysteresis term included.
#include "gyrodrift/fleet/manifest.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::fleet {
namespace {

class ManifestTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::TempDir("manifest");
    for (const char* log : {"cal.csv", "ver.csv"}) {
      io::WriteFileAtomically(dir_ + "/" + log, "time_s,gyro,temp\n0,1,20\n1,2,21\n");
    }
  }
  // The manifest `top` (its first lines) followed by one axis and one unit.
  Manifest Parse(const std::string& top) const {
    return ParseManifest(top +
                             "[[axis]]\ntarget = \"gyro\"\ntemperature = \"temp\"\n"
                             "[[unit]]\nserial = \"SN1\"\ncalibration = \"cal.csv\"\n"
                             "verification = \"ver.csv\"\n",
                         dir_ + "/fleet.toml");
  }
  // The one-line refusal of the manifest `top`.
  std::string Refusal(const std::string& top) const {
    try {
      Parse(top);
    } catch (const UsageError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      return e.what();
    }
    return "";
  }
  std::string dir_;
};

TEST_F(ManifestTest, FitKeysMapOntoTheOptionsAsFitsFlagsDo) {
  const drift::DriftOptions defaults = Parse("").FitOptions();
  EXPECT_EQ(defaults.mode, drift::Mode::kCompensate);
  EXPECT_EQ(defaults.method, drift::Method::kThermal);
  EXPECT_EQ(defaults.thermal.hysteresis, drift::HysteresisTerm::kAuto);
  EXPECT_FALSE(defaults.reference_c.has_value());
  EXPECT_TRUE(defaults.linear_compensation);

  const drift::DriftOptions o =
      Parse("method = \"ms-elm\"\nseed = 5\nnonlinear = true\nhysteresis = \"off\"\n"
            "reference_temperature_c = 20\n")
          .FitOptions();
  EXPECT_EQ(o.method, drift::Method::kMsElm);
  EXPECT_EQ(o.seed, 5u);
  EXPECT_FALSE(o.linear_compensation);
  EXPECT_EQ(o.thermal.hysteresis, drift::HysteresisTerm::kOff);
  EXPECT_EQ(o.reference_c, 20.0);
}

TEST_F(ManifestTest, RefusalsNameTheLineAndTheKey) {
  const std::string file = dir_ + "/fleet.toml:";
  EXPECT_EQ(Refusal(""), "");
  EXPECT_EQ(Refusal("seed = 1\nhysteresis = \"sometimes\"\n"),
            file + "2: hysteresis = 'sometimes': must be one of auto, on, off");
  EXPECT_EQ(Refusal("rate_unit = \"mph\"\n"),
            file + "1: rate_unit = 'mph': must be one of dph, dps, rads");
  EXPECT_EQ(Refusal("method = \"poly\"\nhysteresis = \"on\"\n"),
            file + "2: hysteresis = 'on': must be auto unless mode is 'compensate' with method "
                   "thermal, ms-elm or emd-elm");
  EXPECT_EQ(Refusal("method = \"poly\"\nnonlinear = true\n"),
            file + "2: nonlinear = true: must be false unless mode is 'compensate' with method "
                   "thermal, ms-elm or emd-elm");
  EXPECT_EQ(Refusal("reference_temperature_c = 500\n"),
            file + "1: reference_temperature_c = 500: must be in [-100, 200]");
}

// Every drift::FitSettings field is a key through the settings' one reader
// (tasks::FitSettingsFromJson), but those the fleet sets (mode, has_temperature, threads, rate_hz).
TEST_F(ManifestTest, EveryFitSettingIsAKeyThroughItsOneMapping) {
  const Manifest m = Parse(
      "decomposition = \"emd\"\nensemble = 7\nrealisations = 30\nthermal_features = "
      "\"classic\"\ntime_constants = [60, 600.5]\nseed = 18446744073709551\nmethod = \"auto\"\n"
      "standard_errors = 0.5\n");
  EXPECT_EQ(m.fit.decomposition, "emd");
  EXPECT_EQ(m.fit.ensemble, 7);
  EXPECT_EQ(m.fit.realisations, 30);
  EXPECT_EQ(m.fit.thermal_features, "classic");
  EXPECT_EQ(m.fit.time_constants, (std::vector<double>{60.0, 600.5}));
  EXPECT_EQ(m.fit.seed, 18446744073709551u);
  EXPECT_EQ(m.FitMethod(), drift::Method::kThermal);
  EXPECT_EQ(m.FitOptions().thermal.standard_errors, 0.5);
  EXPECT_EQ(m.fit.mode, "compensate");
  EXPECT_TRUE(m.fit.has_temperature);
  const drift::DriftOptions o = Parse("method = \"elm\"\nhidden = 20\n").FitOptions();
  EXPECT_EQ(o.learner.elm.hidden_units, 20);
  const std::string file = dir_ + "/fleet.toml:";
  EXPECT_EQ(Refusal("seed = 1\nensemble = \"many\"\n"),
            file + "2: ensemble = \"many\": must be an integer in [1, 100000]");
  EXPECT_EQ(Refusal("seed = -1\n"), file + "1: seed = -1: must be a non-negative integer");
  EXPECT_EQ(Refusal("ensemble = 0\n"), file + "1: ensemble = 0: must be an integer in [1, 100000]");
  EXPECT_EQ(Refusal("lags = 4\n"),
            file + "1: lags = 4: must be left unset in mode 'compensate' (a compensate-mode model "
                   "sees temperature only; lags apply to mode 'predict')");
  EXPECT_EQ(Refusal("method = \"ms-elm\"\nhidden = 0\n"),
            file + "2: hidden = '0': must be auto or an integer in [1, 10000]");
  for (const char* fleet_set : {"threads = 2\n", "mode = \"predict\"\n",
                                "has_temperature = true\n", "reference_temperature = 20\n"}) {
    EXPECT_NE(Refusal(fleet_set).find("unknown key"), std::string::npos) << fleet_set;
  }
  EXPECT_NE(Refusal("method = \"persistence\"\n")
                .find("1: method = 'persistence' does not compensate"),
            std::string::npos);
}

TEST_F(ManifestTest, TheFingerprintFollowsTheHysteresisSetting) {
  const Manifest a = Parse("");
  const Manifest off = Parse("hysteresis = \"off\"\n");
  ASSERT_EQ(a.units.size(), 1u);
  EXPECT_EQ(UnitFingerprint(a, a.units[0]), UnitFingerprint(Parse(""), a.units[0]));
  EXPECT_NE(UnitFingerprint(a, a.units[0]), UnitFingerprint(off, off.units[0]));
}

TEST_F(ManifestTest, EveryLogSettingIsAKeyThroughItsOneMapping) {
  const Manifest m =
      Parse("names = [\"time_s\", \"gyro\", \"temp\"]\nskip_rows = 2\nbad_lines = \"skip\"\n"
            "delimiter = \"comma\"\ngaps = \"interpolate\"\nulog_instance = 1\n"
            "ulog_units = \"rads\"\n");
  EXPECT_EQ(m.log.names, (std::vector<std::string>{"time_s", "gyro", "temp"}));
  EXPECT_EQ(m.log.skip_rows, 2);
  EXPECT_EQ(m.log.bad_lines, io::BadLines::kSkip);
  EXPECT_EQ(m.log.delimiter, io::Delimiter::kComma);
  EXPECT_EQ(m.log.gaps, io::GapPolicy::kInterpolate);
  EXPECT_EQ(m.log.ulog_instance, 1);
  EXPECT_EQ(m.log.ulog.units, allan::RateUnit::kRadPerSecond);
  const std::string file = dir_ + "/fleet.toml:";
  EXPECT_EQ(Refusal("seed = 1\nskip_rows = -1\n"),
            file + "2: skip_rows = -1: must be an integer in [0, 1000000]");
  EXPECT_EQ(Refusal("bad_lines = \"sometimes\"\n"),
            file + "1: bad_lines = 'sometimes': must be one of error, skip");
  EXPECT_EQ(Refusal("names = \"gyro\"\n"), file + "1: names = \"gyro\": must be an array of strings");
}

// The fingerprint is the settings' JSON (tasks::SettingsToJson) with the fleet's keys and the
// unit's logs: every setting, of the fit or of the log, changes it.
TEST_F(ManifestTest, EverySettingChangesTheFingerprint) {
  const Manifest a = Parse("");
  const std::string base = UnitFingerprint(a, a.units[0]);
  EXPECT_EQ(base, UnitFingerprint(Parse(""), a.units[0]));
  EXPECT_EQ(FingerprintJson(a, a.units[0])["settings"]["version"], 1);
  for (const char* top : {"hysteresis = \"off\"\n", "seed = 2\n", "method = \"poly\"\n",
                          "nonlinear = true\n", "reference_temperature_c = 20\n",
                          "ensemble = 50\n", "time_constants = [60]\n",
                          "skip_rows = 1\n", "bad_lines = \"skip\"\n", "delimiter = \"comma\"\n",
                          "gaps = \"interpolate\"\n", "ulog_instance = 1\n", "rate_hz = 2\n",
                          "drift_window_s = 50\n", "rate_unit = \"dps\"\n",
                          "[limits]\nresidual_drift_rms = 1\n"}) {
    const Manifest b = Parse(top);
    EXPECT_NE(UnitFingerprint(b, b.units[0]), base) << top;
  }
}

}  // namespace
}  // namespace gyrodrift::fleet
