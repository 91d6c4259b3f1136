// gyrodrift predict, run as a user would: rows and columns of both protocols, identity with the
// library's predictions, and every bad-input case.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

// Models are fitted once for the suite (through the CLI, as a user would).
class PredictCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_predict"));
    io::WriteFileAtomically(Dir() + "/train.csv", test::ThermalLogCsv(300, 1));
    io::WriteFileAtomically(Dir() + "/test.csv", test::ThermalLogCsv(120, 2));
    const std::string fit = "fit '" + Dir() + "/train.csv' -t rate_dph -I 10 -q ";
    ASSERT_EQ(test::RunCli(fit + "--mode predict -m ms-elm --lags 3 -o '" + Dir() + "/ms.json'")
                  .exit_code,
              0);
    ASSERT_EQ(
        test::RunCli(fit + "--mode predict -m elm -T temperature_c -o '" + Dir() + "/elm.json'")
            .exit_code,
        0);
    ASSERT_EQ(test::RunCli(fit + "--mode compensate -m poly -T temperature_c -o '" + Dir() +
                           "/comp.json'")
                  .exit_code,
              0);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static const std::string& Dir() { return *dir_; }
  static std::string* dir_;
};
std::string* PredictCli::dir_ = nullptr;

TEST_F(PredictCli, CausalMsElmStartsWhenAWindowCanBeDecomposed) {
  const std::string out = Dir() + "/causal.csv";
  const auto r = test::RunCli("predict '" + Dir() + "/ms.json' '" + Dir() +
                              "/test.csv' -W 64 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("predicted samples 17..120 (causal protocol)"), std::string::npos) << r.out;
  const auto table = io::CsvTable::Read(out);
  EXPECT_EQ(table.header(), (std::vector<std::string>{"sample", "time_s", "prediction"}));
  ASSERT_EQ(table.rows(), 120 - 16);
  EXPECT_EQ(table.Column("sample")[0], 17.0);
  EXPECT_EQ(table.Column("time_s")[0], 16.0);
  EXPECT_EQ(table.Column("sample")[table.rows() - 1], 120.0);
  EXPECT_TRUE(table.Column("prediction").allFinite());
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["command"], "predict");
  EXPECT_EQ(json["options"]["protocol"], "causal");
  EXPECT_EQ(json["options"]["window"], 64);
  EXPECT_EQ(json["first_predicted_sample"], 17);
  EXPECT_EQ(json["model"]["lags"], 3);

  // Same bytes with one thread.
  const std::string one = Dir() + "/causal1.csv";
  ASSERT_EQ(test::RunCli("predict '" + Dir() + "/ms.json' '" + Dir() +
                         "/test.csv' -W 64 -j 1 -q -o '" + one + "'")
                .exit_code,
            0);
  EXPECT_EQ(io::ReadTextFile(one), io::ReadTextFile(out));
}

TEST_F(PredictCli, PaperProtocolMatchesTheLibraryToTheBit) {
  const std::string out = Dir() + "/paper.csv";
  const auto r = test::RunCli("predict '" + Dir() + "/ms.json' '" + Dir() +
                              "/test.csv' --protocol paper -q -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const auto table = io::CsvTable::Read(out);
  ASSERT_EQ(table.rows(), 120 - 3);  // from sample p + 1 = 4
  EXPECT_EQ(table.Column("sample")[0], 4.0);
  const io::LoadedModel loaded = io::ReadModelFile(Dir() + "/ms.json");
  const Eigen::VectorXd y = io::CsvTable::Read(Dir() + "/test.csv").Column("rate_dph");
  const Eigen::VectorXd expected =
      drift::PredictOneStep(loaded.model, y, Eigen::VectorXd(), 3, drift::Protocol::kPaper);
  EXPECT_EQ(table.Column("prediction"), expected);
}

TEST_F(PredictCli, HorizonPredictsRecursivelyAsTheLibrary) {
  const std::string out = Dir() + "/ahead.csv";
  const auto r = test::RunCli("predict '" + Dir() + "/ms.json' '" + Dir() +
                              "/test.csv' --protocol paper --horizon 5 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("predicted samples 8..120 (5-step-ahead, paper protocol)"),
            std::string::npos)
      << r.out;
  const auto table = io::CsvTable::Read(out);
  ASSERT_EQ(table.rows(), 120 - 7);  // p = 3 lags before the origin, 4 steps after it
  EXPECT_EQ(table.Column("sample")[0], 8.0);
  const io::LoadedModel loaded = io::ReadModelFile(Dir() + "/ms.json");
  const Eigen::VectorXd y = io::CsvTable::Read(Dir() + "/test.csv").Column("rate_dph");
  EXPECT_EQ(table.Column("prediction"),
            drift::PredictAhead(loaded.model, y, Eigen::VectorXd(), 7, 5, drift::Protocol::kPaper));
  EXPECT_EQ(nlohmann::json::parse(io::ReadTextFile(out + ".json"))["options"]["horizon"], 5);

  // Causal: the first origin needs a 16-sample window, so predictions start at 16 + 5.
  const std::string causal = Dir() + "/ahead_causal.csv";
  ASSERT_EQ(test::RunCli("predict '" + Dir() + "/ms.json' '" + Dir() + "/test.csv' -W 64 -H 5 -q " +
                         "-o '" + causal + "'")
                .exit_code,
            0);
  const auto windows = io::CsvTable::Read(causal);
  ASSERT_EQ(windows.rows(), 120 - 20);
  EXPECT_EQ(windows.Column("sample")[0], 21.0);
  drift::CausalOptions options;
  options.window = 64;
  EXPECT_EQ(windows.Column("prediction"),
            drift::PredictAhead(loaded.model, y, Eigen::VectorXd(), 20, 5, drift::Protocol::kCausal,
                                options));
}

TEST_F(PredictCli, SingleModelsAreCausalUnderBothProtocols) {
  const std::string a = Dir() + "/a.csv", b = Dir() + "/b.csv";
  const std::string base = "predict '" + Dir() + "/elm.json' '" + Dir() + "/test.csv' -q ";
  ASSERT_EQ(test::RunCli(base + "--protocol paper -o '" + a + "'").exit_code, 0);
  ASSERT_EQ(test::RunCli(base + "--protocol causal -o '" + b + "'").exit_code, 0);
  EXPECT_EQ(io::ReadTextFile(a), io::ReadTextFile(b));
  EXPECT_EQ(io::CsvTable::Read(a).rows(), 120 - 4);  // default p = 4
}

// A baseline's model file: fitted, written, read back and run by predict as the library runs it,
// h steps ahead (the filters need one sample before the first origin).
TEST_F(PredictCli, BaselinesRoundTripThroughTheModelFile) {
  const std::string model = Dir() + "/trend.json", out = Dir() + "/trend.csv";
  ASSERT_EQ(test::RunCli("fit '" + Dir() + "/train.csv' -t rate_dph -q --mode predict "
                         "-m kalman-trend -o '" + model + "'")
                .exit_code,
            0);
  const auto r =
      test::RunCli("predict '" + model + "' '" + Dir() + "/test.csv' --horizon 3 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const io::LoadedModel loaded = io::ReadModelFile(model);
  ASSERT_TRUE(loaded.model.sub_models.front().baseline);
  EXPECT_EQ(nlohmann::json::parse(io::ReadTextFile(model))["format_version"],
            io::kModelFormatVersion);
  const Eigen::VectorXd y = io::CsvTable::Read(Dir() + "/test.csv").Column("rate_dph");
  const io::CsvTable predicted = io::CsvTable::Read(out);
  EXPECT_EQ(predicted.rows(), 120 - 3);
  EXPECT_EQ(predicted.Column("prediction"),
            drift::PredictAhead(loaded.model, y, Eigen::VectorXd(), 3, 3,
                                drift::Protocol::kCausal));
  // The filters forecast the output: compensate mode refuses them, naming the mode to use.
  const auto refused = test::RunCli("fit '" + Dir() + "/train.csv' -t rate_dph -T temperature_c "
                                    "--mode compensate -m exp-smoothing -o '" + Dir() + "/x.json'");
  EXPECT_NE(refused.exit_code, 0);
  EXPECT_NE(refused.err.find("mode = predict"), std::string::npos) << refused.err;
}

struct BadCase {
  const char* name;
  std::string args;  // %DIR% is substituted
  int exit_code;
  const char* message;
};

TEST_F(PredictCli, BadInputGivesOneLineErrorAndNoOutput) {
  io::WriteFileAtomically(Dir() + "/no_rate.csv",
                          "time_s,gyro,temperature_c\n0,1,20\n1,2,21\n2,3,22\n");
  std::string no_temp = test::ThermalLogCsv(60, 3);
  no_temp.replace(0, no_temp.find('\n') + 1, "time_s,rate_dph,temp_c,drift_dph\n");
  io::WriteFileAtomically(Dir() + "/no_temp.csv", no_temp);
  io::WriteFileAtomically(Dir() + "/short.csv", test::ThermalLogCsv(12, 4));
  io::WriteFileAtomically(Dir() + "/ten_hz.csv", test::ThermalLogCsv(200, 4, 0.1));
  io::WriteFileAtomically(Dir() + "/nan.csv", "rate_dph\n1\n2\n3\n4\n5\nnan\n7\n8\n");
  std::string damaged = io::ReadTextFile(Dir() + "/ms.json");
  const size_t digit = damaged.find_first_of("123456789", damaged.find("\"output_weights\""));
  damaged[digit] = damaged[digit] == '9' ? '8' : static_cast<char>(damaged[digit] + 1);
  io::WriteFileAtomically(Dir() + "/damaged.json", damaged);
  const std::vector<BadCase> cases = {
      {"missing model", "predict %DIR%/nope.json %DIR%/test.csv", 2, "no such file"},
      {"missing input", "predict %DIR%/ms.json %DIR%/nope.csv", 2, "no such file"},
      {"compensate model", "predict %DIR%/comp.json %DIR%/test.csv", 2,
       "use 'gyrodrift compensate'"},
      {"bad protocol", "predict %DIR%/ms.json %DIR%/test.csv --protocol future", 2,
       "protocol = 'future'"},
      {"small window", "predict %DIR%/ms.json %DIR%/test.csv -W 8", 2, "--window = 8"},
      {"mirror past the window", "predict %DIR%/ms.json %DIR%/test.csv --mirror 1.5", 2,
       "--mirror = 1.5"},
      {"no window", "predict %DIR%/ms.json %DIR%/test.csv --windows 0", 2, "--windows = 0"},
      {"negative causal ensemble", "predict %DIR%/ms.json %DIR%/test.csv --causal-ensemble -1", 2,
       "--causal-ensemble = -1"},
      {"zero horizon", "predict %DIR%/ms.json %DIR%/test.csv --horizon 0", 2, "--horizon = 0"},
      {"horizon past the file", "predict %DIR%/ms.json %DIR%/test.csv --horizon 110", 3,
       "needs more than 125"},
      {"not a model", "predict %DIR%/test.csv %DIR%/test.csv", 3, "not a gyrodrift model file"},
      {"damaged model", "predict %DIR%/damaged.json %DIR%/test.csv", 3, "checksum mismatch"},
      {"target column missing", "predict %DIR%/ms.json %DIR%/no_rate.csv", 3,
       "model needs column 'rate_dph' (trained with --target rate_dph); "},
      {"temperature column missing", "predict %DIR%/elm.json %DIR%/no_temp.csv", 3,
       "model needs column 'temperature_c' (trained with --temperature temperature_c); "},
      {"too short", "predict %DIR%/ms.json %DIR%/short.csv", 3, "needs more than 16"},
      {"another sample rate given", "predict %DIR%/ms.json %DIR%/test.csv --rate-hz 2", 3,
       "(given by --rate-hz)"},
      {"another sample rate", "predict %DIR%/ms.json %DIR%/ten_hz.csv", 3,
       "was fitted at 1 Hz: its lags and windows, counted in samples, would span 10 times less "
       "time"},
      {"file without temperature", "predict %DIR%/elm.json %DIR%/nan.csv", 3,
       "model needs column 'temperature_c'"},
      {"nan target", "predict %DIR%/ms.json %DIR%/nan.csv", 3, "data row 6"},
  };
  const std::string out = Dir() + "/bad.csv";
  for (const auto& c : cases) {
    const auto r = test::RunCli(test::Substitute(c.args, {{"%DIR%", Dir()}}) + " -o " + out);
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
  const auto r = test::RunCli("predict '" + Dir() + "/elm.json' '" + Dir() + "/test.csv' -o '" +
                              Dir() + "/no/dir/p.csv'");
  EXPECT_EQ(r.exit_code, 4) << r.err;
}

TEST(PredictHelp, ShowsAWorkedExample) {
  const auto r = test::RunCli("predict --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("gyrodrift predict model.json test.csv"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gyrodrift
