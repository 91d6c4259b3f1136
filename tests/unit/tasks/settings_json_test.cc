// The settings' JSON (tasks/settings_json.h): one writer and one reader of the fit and log
// settings; every field round-trips, a key of the wrong type is refused naming it, and another
// version or an unknown key is refused naming the source.
#include "gyrodrift/tasks/settings_json.h"

#include <gtest/gtest.h>

#include "gyrodrift/common/error.h"

namespace gyrodrift::tasks {
namespace {

TEST(SettingsJson, EveryFieldRoundTrips) {
  const drift::FitSettings fit{.mode = "predict",
                               .method = "elm",
                               .decomposition = "emd",
                               .lags = "8",
                               .hidden = "12",
                               .rate_hz = 2.5,
                               .thermal_features = "classic",
                               .time_constants = {60, 600},
                               .ensemble = 7,
                               .realisations = 30,
                               .seed = 18446744073709551615ull,
                               .threads = 3,
                               .nonlinear = true,
                               .reference_temperature = 21.5,
                               .hysteresis = "off",
                               .standard_errors = 2.5,
                               .has_temperature = true};
  const io::LogOptions log{.gaps = io::GapPolicy::kCarry,
                           .delimiter = io::Delimiter::kTab,
                           .names = {"a", "b"},
                           .skip_rows = 3,
                           .bad_lines = io::BadLines::kSkip,
                           .ulog = {.topic = "sensor_gyro_fifo",
                                    .axes = {"x"},
                                    .temperature = "",
                                    .units = allan::RateUnit::kRadPerSecond},
                           .ulog_instance = 2};
  const nlohmann::json j = SettingsToJson(fit, log);
  EXPECT_EQ(j["version"], kSettingsJsonVersion);
  drift::FitSettings fit2;
  io::LogOptions log2;
  SettingsFromJson(nlohmann::json::parse(j.dump()), "s.json", &fit2, &log2);
  EXPECT_EQ(SettingsToJson(fit2, log2), j);
  EXPECT_EQ(fit2.reference_temperature, 21.5);
  EXPECT_EQ(fit2.seed, fit.seed);
  EXPECT_EQ(fit2.standard_errors, 2.5);
  EXPECT_EQ(log2, log);  // gaps_name is how a front end spells gaps, not a setting
  // Unset reference: null, read back unset.
  SettingsFromJson(SettingsToJson({}, {}), "d.json", &fit2, &log2);
  EXPECT_FALSE(fit2.reference_temperature.has_value());
}

// lags and hidden ("auto" or an integer) are held as text: an integer is read as its digits.
TEST(SettingsJson, AutoOrIntegerSettingsTakeAnInteger) {
  drift::FitSettings fit;
  FitSettingsFromJson({{"lags", 8}, {"hidden", "auto"}}, &fit);
  EXPECT_EQ(fit.lags, "8");
  EXPECT_EQ(fit.hidden, "auto");
  EXPECT_THROW(FitSettingsFromJson({{"hidden", true}}, &fit), OptionError);
  EXPECT_THROW(FitSettingsFromJson({{"lags", 2.5}}, &fit), OptionError);
}

TEST(SettingsJson, RefusalsNameTheKeyOrTheSource) {
  drift::FitSettings fit;
  io::LogOptions log;
  try {
    FitSettingsFromJson({{"ensemble", "many"}}, &fit);
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "ensemble");
  }
  EXPECT_THROW(LogOptionsFromJson({{"gaps", "sometimes"}}, &log), OptionError);
  nlohmann::json j = SettingsToJson({}, {});
  j["log"]["colour"] = "blue";
  try {
    SettingsFromJson(j, "s.json", &fit, &log);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "s.json: unknown setting log.colour");
  }
  j = SettingsToJson({}, {});
  j["version"] = 0;
  EXPECT_THROW(SettingsFromJson(j, "s.json", &fit, &log), UsageError);
}

}  // namespace
}  // namespace gyrodrift::tasks
