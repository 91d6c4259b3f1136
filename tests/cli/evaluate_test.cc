// gyrodrift evaluate, run as a user would: the table, its sidecar, repeats, and every bad-input
// case.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class EvaluateCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::TempDir("cli_evaluate");
    input_ = dir_ + "/log.csv";
    io::WriteFileAtomically(input_, test::ThermalLogCsv(400, 1));
  }
  std::string dir_, input_;
};

TEST_F(EvaluateCli, CompensateTableAgainstTruth) {
  const std::string out = dir_ + "/table.csv";
  const auto r = test::RunCli("evaluate '" + input_ +
                              "' -t rate_dph -T temperature_c --truth drift_dph --mode compensate "
                              "--methods ms-elm,poly -I 10 --seed 3 -o '" +
                              out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.err.empty()) << r.err;  // no progress line: stderr is not a terminal
  EXPECT_NE(r.out.find("against drift_dph"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("method        protocol"), std::string::npos) << r.out;
  const std::string text = io::ReadTextFile(out);
  EXPECT_EQ(text.substr(0, text.find('\n')),
            "method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,train_s,"
            "predict_s");
  // 120 test samples at 1 Hz: shorter than one 10-min block, no slow variation to score ("nan",
  // which this reader refuses: the column is dropped to read the others).
  EXPECT_NE(text.find(",nan,"), std::string::npos);
  std::string finite;
  for (size_t at = 0, end; at < text.size(); at = end + 1) {
    end = text.find('\n', at);
    std::string line = text.substr(at, end - at);
    const size_t slow = line.find(",nan,");
    if (slow != std::string::npos) line.replace(slow, 5, ",");
    const size_t name = line.find(",slow_removed,");
    if (name != std::string::npos) line.replace(name, 14, ",");
    finite += line + "\n";
  }
  const auto table = io::CsvTable::Parse(finite, out);
  ASSERT_EQ(table.rows(), 8);  // none, constant and 2 methods x 2 protocols
  EXPECT_NE(text.find("\nnone,paper,"), std::string::npos);
  EXPECT_NE(text.find("\nconstant,causal,"), std::string::npos);
  EXPECT_NE(text.find("\nms-elm,paper,"), std::string::npos);
  EXPECT_NE(text.find("\nms-elm,causal,"), std::string::npos);
  EXPECT_NE(text.find("\npoly,paper,"), std::string::npos);
  const Eigen::VectorXd rmse = table.Column("rmse"), mae = table.Column("mae"),
                        max_abs = table.Column("max_abs");
  for (Eigen::Index i = 0; i < 8; ++i) {
    EXPECT_GT(rmse[i], 0.0);
    EXPECT_LE(mae[i], rmse[i]);
    EXPECT_LE(rmse[i], max_abs[i]);
  }
  EXPECT_EQ(table.Column("rmse_std"), Eigen::VectorXd::Zero(8));  // one repeat
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["command"], "evaluate");
  EXPECT_EQ(json["options"]["methods"], nlohmann::json({"ms-elm", "poly"}));
  EXPECT_EQ(json["options"]["protocols"], nlohmann::json({"paper", "causal"}));
  EXPECT_EQ(json["options"]["split"], 0.7);
  EXPECT_EQ(json["options"]["truth_column"], "drift_dph");
  EXPECT_EQ(json["options"]["drift"]["seed"], 3);
  EXPECT_EQ(json["options"]["drift"]["decomposition"]["ensemble_size"], 10);
  EXPECT_EQ(json["result"]["first_test_sample"], 281);
  EXPECT_EQ(json["result"]["rows"].size(), 8u);
  EXPECT_EQ(json["result"]["rows"][4]["rmse"].get<double>(), rmse[4]);
  EXPECT_TRUE(json["result"]["rows"][0]["slow_removed"].is_null());
}

// Every table opens with none and constant, scores against the measured output beside the
// truth, and gives the share of the slow variation removed (10-min blocks: a 40-min log).
TEST_F(EvaluateCli, ReferencesBaselinesAndSlowVariationInEveryTable) {
  const std::string log = dir_ + "/long.csv", out = dir_ + "/base.csv";
  io::WriteFileAtomically(log, test::ThermalLogCsv(2400, 2));
  const auto r = test::RunCli("evaluate '" + log +
                              "' -t rate_dph --truth drift_dph --mode predict --protocol causal "
                              "--methods persistence,trailing-mean,exp-smoothing,kalman-level,"
                              "kalman-trend --horizon 10 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("slow_rm"), std::string::npos) << r.out;
  const std::string text = io::ReadTextFile(out);
  EXPECT_EQ(text.substr(0, text.find('\n')),
            "method,protocol,rmse,rmse_std,mae,max_abs,rmse_measured,slow_removed,train_s,"
            "predict_s");
  const auto table = io::CsvTable::Parse(text, out);
  ASSERT_EQ(table.rows(), 7);
  EXPECT_EQ(text.find("\nnone,causal,"), text.find('\n'));  // the first row
  EXPECT_NE(text.find("\nconstant,causal,"), std::string::npos);
  EXPECT_NE(text.find("\nkalman-trend,causal,"), std::string::npos);
  const Eigen::VectorXd slow = table.Column("slow_removed"), rmse = table.Column("rmse"),
                        measured = table.Column("rmse_measured");
  EXPECT_EQ(slow[0], 0.0);  // doing nothing removes nothing
  for (Eigen::Index i = 0; i < 7; ++i) {
    EXPECT_TRUE(std::isfinite(slow[i]));
    EXPECT_LE(slow[i], 1.0);
    EXPECT_GT(measured[i], rmse[i]);  // the measured output carries the white noise too
  }
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["result"]["slow_variation_block_s"], 600.0);
  EXPECT_EQ(json["result"]["rows"][1]["method"], "constant");
  EXPECT_EQ(json["result"]["rows"][1]["slow_removed"].get<double>(), slow[1]);
}

TEST_F(EvaluateCli, HorizonScoresPredictionsAhead) {
  const std::string one = dir_ + "/h1.csv", ahead = dir_ + "/h8.csv";
  const std::string run = "evaluate '" + input_ +
                          "' -t rate_dph --truth drift_dph --mode predict --methods poly "
                          "--protocol causal ";
  ASSERT_EQ(test::RunCli(run + "-q -o '" + one + "'").exit_code, 0);
  const auto r = test::RunCli(run + "--horizon 8 -o '" + ahead + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("predict mode (8-step-ahead predictions)"), std::string::npos) << r.out;
  // Row 2: poly, after none and constant (which do not depend on the horizon).
  EXPECT_NE(io::CsvTable::Read(one).Column("rmse")[2], io::CsvTable::Read(ahead).Column("rmse")[2]);
  EXPECT_EQ(io::CsvTable::Read(one).Column("rmse")[0], io::CsvTable::Read(ahead).Column("rmse")[0]);
  const auto json = nlohmann::json::parse(io::ReadTextFile(ahead + ".json"));
  EXPECT_EQ(json["options"]["horizon"], 8);
}

// Predictions several steps ahead by a method given the temperature read it up to the predicted
// sample: a note says so, and only where such a method is scored.
TEST_F(EvaluateCli, AHorizonWithTemperatureIsNoted) {
  const std::string run = "evaluate '" + input_ +
                          "' -t rate_dph -T temperature_c --truth drift_dph --mode predict "
                          "--protocol causal --horizon 3 -o '" +
                          dir_ + "/noted.csv' --methods ";
  const auto poly = test::RunCli(run + "poly");
  ASSERT_EQ(poly.exit_code, 0) << poly.err;
  const std::string note =
      "3-step predictions of the methods given a temperature read it up to "
      "the predicted sample";
  EXPECT_NE(poly.out.find(note), std::string::npos) << poly.out;
  const auto smoother = test::RunCli(run + "trailing-mean");
  ASSERT_EQ(smoother.exit_code, 0) << smoother.err;
  EXPECT_EQ(smoother.out.find(note), std::string::npos) << smoother.out;
}

TEST_F(EvaluateCli, RepeatsGiveASpreadOnlyWhereTheSeedMatters) {
  const std::string out = dir_ + "/t.csv";
  const auto r = test::RunCli("evaluate '" + input_ +
                              "' -t rate_dph --mode predict --protocol causal --methods elm,poly "
                              "--repeats 3 --split 0.6 -q -o '" +
                              out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty());
  const auto table = io::CsvTable::Read(out);
  ASSERT_EQ(table.rows(), 4);  // none, constant, elm, poly
  const Eigen::VectorXd spread = table.Column("rmse_std");
  EXPECT_GT(spread[2], 0.0);  // elm: random hidden layer per seed
  EXPECT_EQ(spread[3], 0.0);  // poly: no randomness
  EXPECT_EQ(spread[1], 0.0);  // constant: no randomness
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["result"]["first_test_sample"], 241);
  EXPECT_EQ(json["result"]["scored_against"], "rate_dph");
}

struct BadCase {
  const char* name;
  std::string args;  // %IN% and %DIR% are substituted
  int exit_code;
  const char* message;
};

TEST_F(EvaluateCli, BadInputGivesOneLineErrorAndNoOutput) {
  io::WriteFileAtomically(dir_ + "/short.csv", test::ThermalLogCsv(50, 2));
  io::WriteFileAtomically(dir_ + "/seventy.csv", test::ThermalLogCsv(70, 2));
  std::string nan_truth = test::ThermalLogCsv(200, 3);
  nan_truth.replace(nan_truth.rfind(',') + 1, std::string::npos, "nan\n");
  io::WriteFileAtomically(dir_ + "/nan_truth.csv", nan_truth);
  const std::string p = "evaluate %IN% -t rate_dph --mode predict -I 10 ";
  const std::vector<BadCase> cases = {
      {"missing file", "evaluate %DIR%/nope.csv -t rate_dph --mode predict", 2, "no such file"},
      {"unknown method", p + "--methods elm,lstm", 2, "'lstm' is none of them"},
      {"zero horizon", p + "--horizon 0", 2, "--horizon = 0"},
      {"horizon in compensate mode",
       "evaluate %IN% -t rate_dph -T temperature_c --mode compensate --horizon 2", 2,
       "--horizon = 2: must be 1 in compensate mode"},
      {"repeated method", p + "--methods elm,elm", 2, "without repeats"},
      {"empty methods", p + "--methods ,", 2, "--methods"},
      {"trailing comma", p + "--methods elm,", 2, "--methods = 'elm,'"},
      {"bad protocol", p + "--protocol future", 2, "--protocol = 'future'"},
      {"bad split", p + "--split 0.99", 2, "--split = 0.99"},
      {"zero repeats", p + "--repeats 0", 2, "--repeats = 0"},
      {"small window", p + "--window 4", 2, "--window = 4"},
      {"negative mirror", p + "--mirror -0.5", 2, "--mirror = -0.5"},
      {"too many windows", p + "--windows 17", 2, "--windows = 17"},
      {"huge causal ensemble", p + "--causal-ensemble 100001", 2, "--causal-ensemble = 100001"},
      {"compensate without temperature", "evaluate %IN% -t rate_dph --mode compensate", 2,
       "needs a temperature channel"},
      {"missing truth", p + "--truth drift", 2, "column 'drift' not found"},
      {"truth is target", p + "--truth rate_dph", 2, "must differ from --target"},
      {"temperature is target", "evaluate %IN% -t rate_dph -T rate_dph --mode compensate", 2,
       "--temperature = rate_dph: must differ from --target"},
      {"truth is a temperature",
       "evaluate %IN% -t rate_dph -T temperature_c --truth temperature_c --mode compensate", 2,
       "--truth = temperature_c: must differ from --temperature"},
      {"too short", "evaluate %DIR%/short.csv -t rate_dph --mode predict --methods poly", 3,
       "at least 64"},
      {"test block too small",
       "evaluate %DIR%/seventy.csv -t rate_dph --mode predict --methods poly --split 0.9", 3,
       "too little data"},
      {"nan truth",
       "evaluate %DIR%/nan_truth.csv -t rate_dph --truth drift_dph --mode predict --methods poly",
       3, "data row 200"},
  };
  const std::string out = dir_ + "/bad.csv";
  for (const auto& c : cases) {
    const auto r =
        test::RunCli(test::Substitute(c.args, {{"%IN%", input_}, {"%DIR%", dir_}}) + " -o " + out);
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
  const auto r =
      test::RunCli("evaluate '" + input_ + "' -t rate_dph --mode predict --methods poly -o '" +
                   dir_ + "/no/dir/t.csv'");
  EXPECT_EQ(r.exit_code, 4) << r.err;
}

TEST(EvaluateHelp, ShowsAWorkedExample) {
  const auto r = test::RunCli("evaluate --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("gyrodrift evaluate fog.csv --target rate_dph"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace gyrodrift
