// gyrodrift demo: a reduced study runs end to end and writes a complete, valid folder; a user's log
// runs through --input; bad options fail with one line and the project's exit codes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

using test::RunCli;

bool HaveDygraphs() {
  return std::filesystem::exists(std::string(html::kDygraphsDir) + "/dygraph.min.js");
}

int Lines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

// Every (method, protocol) pair of a table, and that every score is finite.
std::set<std::string> Pairs(const std::string& path) {
  const io::CsvTable t = io::CsvTable::Read(path);
  std::set<std::string> pairs;
  const int method = t.ResolveColumn("method"), protocol = t.ResolveColumn("protocol");
  const std::string text = io::ReadTextFile(path);
  // method and protocol are text: read them from the lines.
  size_t start = text.find('\n') + 1;
  while (start < text.size()) {
    const size_t end = text.find('\n', start);
    std::vector<std::string> cells;
    size_t a = start;
    for (;;) {
      const size_t comma = text.find(',', a);
      if (comma == std::string::npos || comma > end) {
        cells.push_back(text.substr(a, end - a));
        break;
      }
      cells.push_back(text.substr(a, comma - a));
      a = comma + 1;
    }
    pairs.insert(cells[static_cast<size_t>(method)] + "/" + cells[static_cast<size_t>(protocol)]);
    start = end + 1;
  }
  const Eigen::VectorXd rmse = t.Column("rmse");
  for (Eigen::Index i = 0; i < rmse.size(); ++i)
    EXPECT_TRUE(std::isfinite(rmse[i]) && rmse[i] >= 0.0) << path;
  return pairs;
}

const char* kMethods[] = {"ms-elm", "elm", "emd-elm", "poly", "svr", "bp"};

TEST(DemoCli, ReducedSimulatedStudyWritesAValidFolder) {
  if (!HaveDygraphs()) GTEST_SKIP() << "libjs-dygraphs not installed";
  const std::string dir = test::TempDir("demo_sim") + "/out";
  // --seed 2 with fewer ensemble members than realisations: the grouping's white-noise level
  // draws its own realisations, from the study's seed (issue 25).
  const auto r = RunCli("demo -o " + dir +
                        " --duration 2h --ensemble 10 --realisations 20 --window 64 --seed 2"
                        " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;  // --quiet
  EXPECT_TRUE(r.err.empty()) << r.err;  // no progress bar off a terminal
  for (const char* f : {"run_a.csv", "run_b.csv", "imfs.csv", "selection.csv", "predict_table.csv",
                        "compensate_table.csv", "predict_estimates.csv", "compensate_estimates.csv",
                        "allan.csv", "noise_terms.csv", "demo.json", "report.html"}) {
    EXPECT_TRUE(test::FileExists(dir + "/" + f)) << f;
  }
  for (const char* m : kMethods) {
    EXPECT_TRUE(test::FileExists(dir + "/models/" + std::string(m) + "_compensate.json")) << m;
  }
  // Tables: a row per method and protocol.
  const std::set<std::string> predict = Pairs(dir + "/predict_table.csv");
  EXPECT_EQ(predict.size(), 26u);  // and none, constant and the five filters of the output
  for (const char* m : kMethods) {
    EXPECT_TRUE(predict.count(std::string(m) + "/paper")) << m;
    EXPECT_TRUE(predict.count(std::string(m) + "/causal")) << m;
  }
  const std::set<std::string> compensate = Pairs(dir + "/compensate_table.csv");
  EXPECT_EQ(compensate.size(), 9u);  // and thermal, none and constant
  EXPECT_TRUE(compensate.count("none/train A test B"));
  EXPECT_TRUE(compensate.count("constant/train A test B"));
  EXPECT_TRUE(predict.count("kalman-trend/causal"));
  EXPECT_FALSE(test::FileExists(dir + "/models/none_compensate.json"));
  for (const char* m : kMethods)
    EXPECT_TRUE(compensate.count(std::string(m) + "/train A test B")) << m;
  EXPECT_TRUE(compensate.count("thermal/train A test B"));
  // The grouping was computed with seed 2 (the selection's summary names its level's seed).
  const std::string record = io::ReadTextFile(dir + "/demo.json");
  EXPECT_NE(record.find("(level R=20 seed=2)"), std::string::npos);
  EXPECT_EQ(record.find("seed=1)"), std::string::npos);
  // Data: one row per simulated second.
  EXPECT_EQ(io::CsvTable::Read(dir + "/run_a.csv").rows(), 7200);
  EXPECT_EQ(io::CsvTable::Read(dir + "/imfs.csv").rows(), 7200);
  EXPECT_EQ(io::CsvTable::Read(dir + "/predict_estimates.csv").rows(), 7200 - 5040);
  // The report: well formed, every figure has data, dygraphs inlined, nothing external.
  const std::string html = io::ReadTextFile(dir + "/report.html");
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_GE(check.figures, 12);
  EXPECT_GE(check.tables, 4);
  EXPECT_LT(html.size(), 10u * 1000u * 1000u);
  for (const char* needle :
       {"Selection curves", "Allan deviation", "residual", "IMF 1 ", "compensate"}) {
    EXPECT_NE(html.find(needle), std::string::npos) << needle;
  }
}

TEST(DemoCli, UserLogStudy) {
  if (!HaveDygraphs()) GTEST_SKIP() << "libjs-dygraphs not installed";
  // A log of our own: simulate one (the demo reads any uniformly sampled CSV).
  const std::string work = test::TempDir("demo_user");
  ASSERT_EQ(RunCli("simulate --duration 30min -o " + work + "/log.csv").exit_code, 0);
  const auto r =
      RunCli("demo --input " + work +
             "/log.csv --target rate_dph --temperature temperature_c "
             "--ensemble 10 --realisations 20 --window 64 --methods ms-elm,elm,poly -o " +
             work + "/out");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("from the steps of time_s"), std::string::npos) << r.out;
  EXPECT_FALSE(test::FileExists(work + "/out/run_a.csv"));  // no simulation
  const std::set<std::string> compensate = Pairs(work + "/out/compensate_table.csv");
  EXPECT_EQ(compensate,
            (std::set<std::string>{"none/paper", "none/causal", "constant/paper", "constant/causal",
                                   "ms-elm/paper", "ms-elm/causal", "elm/paper", "elm/causal",
                                   "poly/paper", "poly/causal"}));
  EXPECT_EQ(Pairs(work + "/out/predict_table.csv").size(), 20u);  // and the 5 filters
  const std::string html = io::ReadTextFile(work + "/out/report.html");
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  // The saved models name the log's own columns, so `gyrodrift compensate` applies them to it.
  const auto c = RunCli("compensate " + work + "/out/models/ms-elm_compensate.json " + work +
                        "/log.csv -o " + work + "/compensated.csv --quiet");
  EXPECT_EQ(c.exit_code, 0) << c.err;
  EXPECT_TRUE(io::CsvTable::Read(work + "/compensated.csv").HasColumn("compensated"));
  EXPECT_EQ(html.find("compensate --model"), std::string::npos);  // no such option
}

TEST(DemoCli, BadOptionsGiveOneLineAndTheRightExitCode) {
  const std::string dir = test::TempDir("demo_bad");
  const std::string csv = dir + "/tiny.csv";
  io::WriteFileAtomically(csv, "time_s,rate,temp\n1,0.1,20\n2,0.2,20\n3,0.1,21\n");
  const std::string not_a_folder = dir + "/a_file";
  io::WriteFileAtomically(not_a_folder, "x\n");
  struct Case {
    std::string args;
    int code;
    std::string says;
  };
  const std::vector<Case> cases = {
      {"demo --input " + csv + " --temperature temp", 2, "--target"},
      {"demo --input " + csv + " --target rate", 2, "--temperature"},
      {"demo --target rate", 2, "--input"},
      {"demo --input " + csv + " --target rate --temperature temp --duration 2h", 2,
       "--duration sets the simulated runs' length: a log given by --input is studied whole"},
      {"demo --input " + dir + "/missing.csv --target a --temperature b", 2, "no such file"},
      {"demo --duration 0s", 2, "--duration"},
      {"demo --duration '8 hours'", 2, "--duration"},
      {"demo --duration 90min", 2, "at least 2h"},
      {"demo --ensemble 0", 2, "--ensemble"},
      {"demo --window 4", 2, "--window"},
      {"demo --mirror nan", 2, "--mirror = nan"},
      {"demo --windows 0", 2, "--windows = 0"},
      {"demo --methods ms-elm,nope", 2, "nope"},
      // Two model files of one name: refused before the work, not half-written after it.
      {"demo --methods elm,poly,elm -o " + dir + "/o", 2, "--methods"},
      {"demo --units furlongs", 2, "--units"},
      {"demo --realisations 3", 2, "--realisations"},
      // Found out before the study (a full one takes half a minute), not when writing.
      {"demo -o " + not_a_folder, 4, "not a folder"},
      {"demo -o " + not_a_folder + "/sub", 4, "not a folder"},
      {"demo --input " + csv + " --target nope --temperature temp -o " + dir + "/o", 2, "nope"},
      {"demo --input " + csv + " --target rate --temperature rate -o " + dir + "/o", 2,
       "temperature column 'rate' is the target column: they must differ"},
      {"demo --input " + csv + " --target rate --temperature temp -o " + dir + "/o", 3,
       "at least 64"},
  };
  for (const auto& c : cases) {
    const auto r = RunCli(c.args);
    EXPECT_EQ(r.exit_code, c.code) << c.args << "\n" << r.err;
    EXPECT_EQ(Lines(r.err), 1) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.says), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("gyrodrift: error: ", 0), 0u) << r.err;
  }
  EXPECT_FALSE(test::FileExists(dir + "/o/report.html"));
}

}  // namespace
}  // namespace gyrodrift

namespace gyrodrift {
namespace {

// The simulated output is in deg/h: a unit or gap policy without --input would be applied to it.
TEST(DemoCliOptions, LogOnlyOptionsNeedInput) {
  const std::string dir = test::TempDir("cli_demo_log_only");
  for (const char* flags : {"--units dps", "--gaps interpolate"}) {
    const auto r = test::RunCli(std::string("demo ") + flags + " -o '" + dir + "/out'");
    EXPECT_EQ(r.exit_code, 2) << flags << ": " << r.err;
    EXPECT_NE(r.err.find("need --input"), std::string::npos) << r.err;
  }
}

}  // namespace
}  // namespace gyrodrift
