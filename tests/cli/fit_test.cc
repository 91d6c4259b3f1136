// gyrodrift fit, run as a user would: the model file, what it records, and every bad-input case.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "gyrodrift/drift/thermal_coefficients.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class FitCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::TempDir("cli_fit");
    input_ = dir_ + "/train.csv";
    io::WriteFileAtomically(input_, test::ThermalLogCsv(400, 1));
  }
  test::CommandResult Fit(const std::string& args, const std::string& model) {
    return test::RunCli("fit '" + input_ + "' " + args + " -o '" + model + "'");
  }
  std::string dir_, input_;
};

TEST_F(FitCli, MsElmCompensateWritesAModelThatLoads) {
  const std::string model = dir_ + "/m.json";
  const auto r =
      Fit("--target rate_dph --temperature temperature_c --mode compensate -m ms-elm -I 10 "
          "--realisations 20 --seed 4",
          model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;
  EXPECT_NE(r.out.find("ms-elm (compensate)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("decomposition: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("selection: "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrote " + model), std::string::npos) << r.out;
  const auto json = nlohmann::json::parse(io::ReadTextFile(model));
  EXPECT_EQ(json["format"], "gyrodrift-model");
  EXPECT_EQ(json["format_version"], io::kModelFormatVersion);
  EXPECT_EQ(json["training"]["target_column"], "rate_dph");
  EXPECT_EQ(json["training"]["temperature_column"], "temperature_c");
  EXPECT_EQ(json["training"]["samples"], 400);
  EXPECT_EQ(json["options"]["mode"], "compensate");
  EXPECT_EQ(json["options"]["method"], "ms-elm");
  EXPECT_EQ(json["options"]["decomposition"]["method"], "beemdan");
  EXPECT_EQ(json["options"]["decomposition"]["ensemble_size"], 10);
  EXPECT_EQ(json["options"]["seed"], 4);
  EXPECT_EQ(json["options"]["selection"]["monte_carlo"]["realisations"], 20);
  EXPECT_EQ(json["options"]["features"]["rate_hz"], 1.0);  // from time_s
  EXPECT_EQ(json["options"]["learner"]["elm"]["selection"], "auto");
  EXPECT_EQ(json["options"]["learner"]["elm"]["hidden_units"], 50);
  const io::LoadedModel loaded = io::ReadModelFile(model);
  EXPECT_GE(loaded.model.sub_models.size(), 2u);
  EXPECT_EQ(loaded.model.options.mode, drift::Mode::kCompensate);
}

TEST_F(FitCli, SameSeedSameBytesForAnyThreadCount) {
  const std::string a = dir_ + "/a.json", b = dir_ + "/b.json";
  ASSERT_EQ(Fit("-t rate_dph --mode predict -m emd-elm -I 10 --seed 9 -q", a).exit_code, 0);
  const auto r = Fit("-t 2 --mode predict -m emd-elm -I 10 --seed 9 -j 1 -q", b);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  // The thread count is not part of the model: the files are the same bytes.
  const std::string text = io::ReadTextFile(a);
  EXPECT_EQ(text, io::ReadTextFile(b));
  EXPECT_EQ(text.find("threads"), std::string::npos);
  const auto jb = nlohmann::json::parse(io::ReadTextFile(b));
  EXPECT_EQ(jb["training"]["target_column"], "rate_dph");  // resolved from the index
}

TEST_F(FitCli, LagsHiddenAndRateOptions) {
  const std::string model = dir_ + "/m.json";
  auto r =
      Fit("-t rate_dph -T temperature_c --mode predict -m elm --lags auto --hidden 7 --rate-hz 4",
          model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("chosen by validation RMSE"), std::string::npos) << r.out;
  auto json = nlohmann::json::parse(io::ReadTextFile(model));
  EXPECT_EQ(json["options"]["auto_lags"], true);
  EXPECT_EQ(json["options"]["features"]["use_temperature"], true);
  EXPECT_EQ(json["options"]["features"]["rate_hz"], 4.0);
  EXPECT_EQ(json["options"]["learner"]["elm"]["selection"], "fixed");
  EXPECT_EQ(json["options"]["learner"]["elm"]["hidden_units"], 7);
  EXPECT_EQ(json["model"]["sub_models"][0]["learner"]["scalars"]["hidden_units"], 7.0);
  EXPECT_EQ(json["model"]["lag_validation_rmse"].size(), 5u);

  // A time_s column sampled at 0.5 s gives 2 Hz.
  io::WriteFileAtomically(dir_ + "/fast.csv", test::ThermalLogCsv(300, 2, 0.5));
  r = test::RunCli("fit '" + dir_ + "/fast.csv' -t rate_dph --mode predict -m poly --lags 3 -o '" +
                   model + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  json = nlohmann::json::parse(io::ReadTextFile(model));
  EXPECT_EQ(json["options"]["features"]["rate_hz"], 2.0);
  EXPECT_EQ(json["model"]["lags"], 3);
  EXPECT_EQ(json["model"]["sub_models"][0]["learner"]["kind"], "poly");
}

TEST_F(FitCli, ThermalFeatureSetAndTimeConstantsAreStoredAndUsed) {
  const std::string model = dir_ + "/m.json";
  auto r =
      Fit("-t rate_dph -T temperature_c --mode compensate -m poly --thermal-features "
          "lag-bank --time-constants 120,600",
          model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("5 inputs"), std::string::npos) << r.out;  // T, 2 lags, 2 rates
  const auto json = nlohmann::json::parse(io::ReadTextFile(model));
  EXPECT_EQ(json["options"]["features"]["thermal_set"], "lag-bank");
  EXPECT_EQ(json["options"]["features"]["time_constants_s"], nlohmann::json({120.0, 600.0}));
  const io::LoadedModel loaded = io::ReadModelFile(model);
  EXPECT_EQ(loaded.model.options.features.thermal_set, drift::ThermalSet::kLagBank);
  EXPECT_EQ(loaded.model.num_inputs(), 5);
  r = test::RunCli("compensate '" + model + "' '" + input_ + "' -o '" + dir_ + "/c.csv'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
}

// --standard-errors (drift::FitSettings::standard_errors) reaches the identification and the
// model file, and the model file reads it back.
TEST_F(FitCli, StandardErrorsAreStoredAndReadBack) {
  const std::string model = dir_ + "/se.json";
  auto r = Fit("-t rate_dph -T temperature_c --mode compensate --standard-errors 0", model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto json = nlohmann::json::parse(io::ReadTextFile(model));
  EXPECT_EQ(json["options"]["thermal"]["standard_errors"], 0.0);
  EXPECT_EQ(io::ReadModelFile(model).model.options.thermal.standard_errors, 0.0);
  r = Fit("-t rate_dph -T temperature_c --mode compensate", model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(io::ReadModelFile(model).model.options.thermal.standard_errors,
            drift::ThermalModelOptions{}.standard_errors);
}

TEST_F(FitCli, SaysWhenTheTimeAxisHasGaps) {
  // Rows 101.. shifted by 300 s: a logging gap the models cannot see. Refused by default, naming
  // the row; filled by linear interpolation when asked, and said so.
  std::string csv = test::ThermalLogCsv(300, 4);
  const auto table = io::CsvTable::Parse(csv, "log");
  Eigen::VectorXd t = table.Column("time_s");
  t.tail(200).array() += 300.0;
  io::WriteCsv(dir_ + "/gap.csv", {{"time_s", t}, {"rate_dph", table.Column("rate_dph")}});
  const std::string fit = "fit '" + dir_ + "/gap.csv' -t rate_dph --mode predict -m poly ";
  auto r = test::RunCli(fit + "-o '" + dir_ + "/g.json'");
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("time_s jumps by 301 s before data row 101 (300 missing samples at the "
                       "median step 1 s): fill gaps by linear interpolation (--gaps interpolate, "
                       "or --gaps carry to fit on the logged rows only) or split the log into "
                       "records at its gaps (--gaps split)"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(test::FileExists(dir_ + "/g.json"));
  r = test::RunCli(fit + "--gaps interpolate -o '" + dir_ + "/g.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("note: time_s has 1 gap (median step 1 s): 300 samples filled by linear "
                       "interpolation"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(io::ReadModelFile(dir_ + "/g.json").model.training_samples, 600);
  // A split needs a model whose states can restart: the thermal method.
  r = test::RunCli(fit + "--gaps split -o '" + dir_ + "/s.json'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("--method poly: several records (--gaps split) are fitted by --method "
                       "thermal only"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(test::FileExists(dir_ + "/s.json"));
  // Steps shorter than the median are not missing samples: a note names the most irregular.
  t = table.Column("time_s");
  t.tail(150).array() -= 0.6;
  io::WriteCsv(dir_ + "/jitter.csv", {{"time_s", t}, {"rate_dph", table.Column("rate_dph")}});
  r = test::RunCli("fit '" + dir_ + "/jitter.csv' -t rate_dph --mode predict -m poly -o '" + dir_ +
                   "/j.json'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("(shortest 0.4 s, before data row 151)"), std::string::npos) << r.out;
  std::string broken = "time_s,rate_dph\n";
  for (int i = 0; i < 100; ++i) {
    broken += (i == 50 ? std::string("x") : std::to_string(i)) + "," + std::to_string(i % 7) + "\n";
  }
  io::WriteFileAtomically(dir_ + "/broken_time.csv", broken);
  r = test::RunCli("fit '" + dir_ + "/broken_time.csv' -t rate_dph --mode predict -m poly " +
                   "--rate-hz 1 -o '" + dir_ + "/b.json'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("note:"), std::string::npos) << r.out;
  r = Fit("-t rate_dph --mode predict -m poly", dir_ + "/u.json");  // the uniform log
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("not uniform"), std::string::npos) << r.out;
}

// The thermal model's coefficients in physical units around the reference temperature, the
// library's figures (drift::PhysicalCoefficients).
TEST_F(FitCli, PrintsTheCoefficientsInPhysicalUnits) {
  const std::string model = dir_ + "/m.json";
  auto r = Fit("-t rate_dph -T temperature_c --mode compensate", model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::LoadedModel loaded = io::ReadModelFile(model);
  const drift::ThermalRegression& t = *loaded.model.sub_models.at(0).thermal;
  drift::ThermalCoefficients c = drift::PhysicalCoefficients(t, std::nullopt, {"temperature_c"});
  char line[200];
  std::snprintf(line, sizeof line, "around %.6g degC (the calibration's mean):", t.centre_c[0]);
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out << line;
  for (const drift::PhysicalCoefficient& term : c.terms) {
    std::snprintf(line, sizeof line, "%-40s %12.6g +- ", term.term.c_str(), term.value);
    EXPECT_NE(r.out.find(line), std::string::npos) << r.out << line;
    EXPECT_NE(r.out.find("dph" + term.unit), std::string::npos) << r.out << term.unit;
  }
  // Around a stated reference: the bias there.
  r = Fit("-t rate_dph -T temperature_c --mode compensate --reference-temperature 20", model);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("around 20 degC (--reference-temperature):"), std::string::npos) << r.out;
  c = drift::PhysicalCoefficients(*io::ReadModelFile(model).model.sub_models.at(0).thermal, 20.0);
  std::snprintf(line, sizeof line, "%-40s %12.6g +- ", "bias", c.terms[0].value);
  EXPECT_NE(r.out.find(line), std::string::npos) << r.out << line;
}

// Before the work: a sample rate assumed for a log without time_s, and a temperature that does
// not look like degC, each with what the tool assumes.
TEST_F(FitCli, WarnsUpFrontOfAnAssumedRateAndATemperatureInCounts) {
  const auto input = io::CsvTable::Read(input_);
  const std::string untimed = dir_ + "/untimed.csv";
  io::WriteCsv(untimed, {{"rate_dph", input.Column("rate_dph")},
                         {"temperature_c", input.Column("temperature_c")},
                         {"counts", (input.Column("temperature_c").array() * 512.0).round().eval()}});
  const std::string model = dir_ + "/m.json";
  const std::string rate_warning = "warning: " + untimed +
                                   " has no time_s column: its sample rate is taken as 1 Hz "
                                   "(give --rate-hz if it is not)\n";
  auto r = test::RunCli("fit '" + untimed + "' -t rate_dph -T temperature_c --mode compensate "
                        "-o '" + model + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind(rate_warning, 0), 0u) << r.out;  // the first line, before the model
  EXPECT_NE(r.out.find("sample rate: 1 Hz (assumed: no --rate-hz and no time_s column)"),
            std::string::npos)
      << r.out;
  // Given, the rate is no assumption.
  r = test::RunCli("fit '" + untimed + "' -t rate_dph -T temperature_c --mode compensate "
                   "--rate-hz 1 -o '" + model + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("warning: " + untimed), std::string::npos) << r.out;
  // A temperature in counts: named up front, the fit goes on as degC.
  r = test::RunCli("fit '" + untimed + "' -t rate_dph -T counts --mode compensate --rate-hz 1 "
                   "-o '" + model + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("warning: " + untimed + ": temperature column 'counts' runs from ", 0),
            0u)
      << r.out;
  EXPECT_NE(r.out.find("whole numbers only: raw ADC counts?; it is taken as degC as given"),
            std::string::npos)
      << r.out;
  // Quiet means quiet.
  r = test::RunCli("fit '" + untimed + "' -t rate_dph -T counts --mode compensate -q -o '" +
                   model + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
}

TEST_F(FitCli, EveryBaselineFits) {
  for (const char* method : {"elm", "poly", "svr", "bp"}) {
    const std::string model = dir_ + "/" + method + ".json";
    const auto r =
        Fit(std::string("-t rate_dph -T temperature_c --mode compensate -q -m ") + method, model);
    ASSERT_EQ(r.exit_code, 0) << method << ": " << r.err;
    EXPECT_EQ(io::ReadModelFile(model).model.sub_models.size(), 1u) << method;
  }
}

struct BadCase {
  const char* name;
  std::string args;  // %IN% and %DIR% are substituted
  int exit_code;
  const char* message;
};

TEST_F(FitCli, BadInputGivesOneLineErrorAndNoOutput) {
  io::WriteFileAtomically(dir_ + "/nan.csv", "rate_dph,temperature_c\n1,2\n2,3\nnan,4\n");
  io::WriteFileAtomically(dir_ + "/short.csv", test::ThermalLogCsv(20, 3));
  // 6000 rows with 59,999 samples missing after every third: each gap fillable (under 10 times
  // the log), 1.2e8 rows in all (a GB a column).
  std::string sparse = "time_s,rate_dph,temperature_c\n";
  for (int i = 0, t = 0; i < 6000; ++i, t += i % 3 == 0 ? 60000 : 1) {
    sparse += std::to_string(t) + "," + std::to_string(i % 5) + "," + std::to_string(20 + i) + "\n";
  }
  io::WriteFileAtomically(dir_ + "/sparse.csv", sparse);
  io::WriteFileAtomically(dir_ + "/backwards.csv", "time_s,rate_dph\n5,1\n4,2\n3,3\n2,4\n");
  std::string microseconds = "time_s,rate_dph\n";  // time_s in microseconds, as if seconds
  for (int i = 0; i < 200; ++i) {
    microseconds += std::to_string(i) + "e-7," + std::to_string((i * 37) % 11) + "\n";
  }
  io::WriteFileAtomically(dir_ + "/microseconds.csv", microseconds);
  std::string constant = "time_s,rate_dph,temperature_c\n";
  for (int i = 0; i < 100; ++i)
    constant += std::to_string(i) + "," + std::to_string(i % 7) + ",30\n";
  io::WriteFileAtomically(dir_ + "/constant.csv", constant);
  // 60 rows missing after the 100th: a gap.
  std::string gap, line;
  std::istringstream lines(test::ThermalLogCsv(400, 3));
  for (int row = 0; std::getline(lines, line); ++row) {
    if (row <= 100 || row > 160) gap += line + "\n";
  }
  io::WriteFileAtomically(dir_ + "/gap.csv", gap);
  const std::string ok = "-t rate_dph -T temperature_c --mode compensate -I 10";
  const std::vector<BadCase> cases = {
      {"constant temperature, named", "fit %DIR%/constant.csv " + ok, 3,
       "fitting 'rate_dph' on 'temperature_c' ("},
      {"two temperatures for poly",
       "fit %IN% -t rate_dph -T temperature_c,drift_dph --mode compensate -m poly", 2,
       "--temperature = 2 channels: must be one for method poly"},
      {"nonlinear with carry", "fit %DIR%/gap.csv " + ok + " --nonlinear --gaps carry", 2,
       "--nonlinear: the nonlinear correction needs every sample logged"},
      {"missing file", "fit %DIR%/nope.csv -t rate_dph --mode predict", 2, "no such file"},
      {"missing mode", "fit %IN% -t rate_dph", 2, "--mode is required"},
      {"rate from time_s out of range", "fit %DIR%/microseconds.csv -t rate_dph --mode predict", 3,
       "Hz outside [1e-09, 1e+06] Hz (seconds expected; or give rate_hz)"},
      {"missing target", "fit %IN% --mode predict", 2, "--target is required"},
      {"unknown column", "fit %IN% -t gyro --mode predict", 2, "column 'gyro' not found"},
      {"unknown temperature", "fit %IN% -t rate_dph -T temp --mode compensate", 2,
       "column 'temp' not found"},
      {"unknown mode", "fit %IN% -t rate_dph --mode guess", 2, "mode = 'guess'"},
      {"unknown method", "fit %IN% -t rate_dph --mode predict -m lstm", 2, "--method = 'lstm'"},
      {"unknown decomposition", "fit %IN% -t rate_dph --mode predict --decomposition wavelet", 2,
       "--decomposition = 'wavelet'"},
      {"compensate without temperature", "fit %IN% -t rate_dph --mode compensate", 2,
       "needs a temperature channel"},
      {"temperature is target", "fit %IN% -t rate_dph -T rate_dph --mode compensate", 2,
       "must differ from --target"},
      {"zero lags", "fit %IN% -t rate_dph --mode predict --lags 0", 2, "--lags = '0'"},
      {"text lags", "fit %IN% -t rate_dph --mode predict --lags many", 2, "--lags = 'many'"},
      {"zero hidden", "fit %IN% -t rate_dph --mode predict --hidden 0", 2, "--hidden = '0'"},
      {"hidden for poly", "fit %IN% -t rate_dph --mode predict -m poly --hidden 5", 2,
       "applies to the ELM methods"},
      {"hidden for linear compensation",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--hidden 20",
       2, "--hidden = 20: must be auto for method 'thermal'"},
      {"hidden for the nonlinear correction",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate -m ms-elm --nonlinear "
       "--hidden 20",
       2, "--hidden = 20: must be auto for compensate-mode ms-elm, which fits linear sub-models"},
      {"lags in compensate mode",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--lags 8",
       2, "--lags = 8: must be left unset in mode 'compensate'"},
      {"bad hysteresis",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate --hysteresis sometimes", 2,
       "--hysteresis = 'sometimes': must be one of auto, on, off"},
      {"hysteresis for poly",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate -m poly --hysteresis off", 2,
       "--hysteresis = 'off': must be auto unless mode is 'compensate'"},
      {"standard errors out of range",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate --standard-errors 11", 2,
       "--standard-errors = 11: must be in [0, 10]"},
      {"standard errors for poly",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate -m poly --standard-errors 2", 2,
       "--standard-errors = 2: must be left at its default unless mode is 'compensate'"},
      {"zero ensemble", "fit %IN% -t rate_dph --mode predict -I 0", 2, "--ensemble = 0"},
      {"few realisations", "fit %IN% -t rate_dph --mode predict --realisations 5", 2,
       "--realisations = 5"},
      {"negative rate", "fit %IN% -t rate_dph --mode predict --rate-hz -1", 2, "--rate-hz = -1"},
      {"negative seed", "fit %IN% -t rate_dph --mode predict --seed -1", 2, "seed"},
      {"unknown feature set",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--thermal-features spline",
       2, "--thermal-features = 'spline'"},
      {"zero time constant",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--time-constants 60,0",
       2, "--time-constants = 0"},
      {"text time constant",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--time-constants 60,slow",
       2, "--time-constants"},
      {"gaps that would make up most of memory",
       "fit %DIR%/sparse.csv -t rate_dph -T temperature_c --mode compensate --gaps carry", 3,
       "samples (at most 1e+08): split the log at its gaps (--gaps split)"},
      {"empty item in a list (CLI11 would drop it)",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--time-constants 60,,300",
       2, "--time-constants = 60,,300: an empty item in the list"},
      {"trailing comma in a list",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--time-constants 60,",
       2, "--time-constants = 60,: an empty item in the list"},
      {"integer in exponent form", "fit %IN% -t rate_dph --mode predict --ensemble 1e3", 2,
       "--ensemble = 1e3: must be an integer (write 1000)"},
      {"fractional integer", "fit %IN% -t rate_dph --mode predict --ensemble 2.5", 2,
       "--ensemble = 2.5: must be an integer"},
      {"repeated time constant",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate "
       "--time-constants 60,60",
       2, "--time-constants = 60: must be given once"},
      {"empty number (an unset shell variable)",
       "fit %IN% -t rate_dph -T temperature_c --mode compensate --reference-temperature ''", 2,
       "--reference-temperature: an empty value is not a number"},
      {"hidden beyond its range", "fit %IN% -t rate_dph --mode predict -m elm --hidden 100000", 2,
       "--hidden = '100000': must be auto or an integer in [1, 10000]"},
      {"negative threads", "fit %IN% -t rate_dph --mode predict -j -2", 2, "threads"},
      {"nan target", "fit %DIR%/nan.csv -t rate_dph --mode predict", 3, "data row 3"},
      {"too short", "fit %DIR%/short.csv -t rate_dph --mode predict -m elm", 3, "at least 32"},
      {"time runs backwards", "fit %DIR%/backwards.csv -t rate_dph --mode predict", 3, "time_s"},
      {"one log twice",
       "fit %IN% %DIR%/../" + std::filesystem::path(dir_).filename().string() + "/" +
           std::filesystem::path(input_).filename().string() + " " + ok,
       2, "are one file: each log is one record of the calibration (give it once)"},
  };
  const std::string out = dir_ + "/bad.json";
  for (const auto& c : cases) {
    const auto r =
        test::RunCli(test::Substitute(c.args, {{"%IN%", input_}, {"%DIR%", dir_}}) + " -o " + out);
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
  // An empty output name (an unset shell variable) is a usage error, found before the work.
  const auto unnamed = Fit(ok, "");
  EXPECT_EQ(unnamed.exit_code, 2) << unnamed.err;
  EXPECT_NE(unnamed.err.find("--output: an empty value is not a path"), std::string::npos)
      << unnamed.err;
  const auto dash = Fit(ok, "-");
  EXPECT_EQ(dash.exit_code, 2) << dash.err;
  EXPECT_NE(dash.err.find("--output: '-' (standard output) is not supported: name a file"),
            std::string::npos)
      << dash.err;
  // A device would be replaced by the rename that places the file: refused before the work.
  const auto device = Fit(ok, "/dev/null");
  EXPECT_EQ(device.exit_code, 4) << device.err;
  EXPECT_NE(device.err.find("/dev/null: is not a regular file"), std::string::npos) << device.err;
  const auto r = Fit(ok, dir_ + "/no/such/dir/m.json");
  EXPECT_EQ(r.exit_code, 4) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST(FitHelp, ShowsAWorkedExample) {
  const auto r = test::RunCli("fit --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("gyrodrift fit train.csv --target rate_dph"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gyrodrift
