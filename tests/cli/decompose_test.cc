// gyrodrift decompose, run as a user would: outputs, the sidecar, and every bad-input case.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

class DecomposeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::TempDir("cli_decompose");
    input_ = dir_ + "/in.csv";
    std::string csv = "time_s,rate_dph\n";
    for (int i = 0; i < 600; ++i) {
      const double t = i;
      csv += std::to_string(t) + "," +
             std::to_string(std::sin(t / 5.0) + 0.3 * std::sin(t / 37.0) + 1e-3 * t +
                            0.05 * std::cos(1.7 * t * t)) +
             "\n";
    }
    io::WriteFileAtomically(input_, csv);
  }
  std::string dir_, input_;
};

TEST_F(DecomposeCli, WritesImfsAndSidecar) {
  const std::string out = dir_ + "/imfs.csv";
  const auto r =
      test::RunCli("decompose '" + input_ +
                   "' --column rate_dph --method iceemdan -I 10 --seed 3 -o '" + out + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto table = io::CsvTable::Read(out);
  EXPECT_EQ(table.rows(), 600);
  EXPECT_EQ(table.header().back(), "residue");
  EXPECT_EQ(table.header().front(), "imf1");
  // Completeness through the text round trip (shortest round-trip formatting is exact).
  const auto in = io::CsvTable::Read(input_).Column("rate_dph");
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(600);
  for (int c = 0; c < static_cast<int>(table.header().size()); ++c) sum += table.Column(c);
  EXPECT_LE((sum - in).cwiseAbs().maxCoeff(), 1e-12);
  const auto json = nlohmann::json::parse(io::ReadTextFile(out + ".json"));
  EXPECT_EQ(json["options"]["method"], "iceemdan");
  EXPECT_EQ(json["options"]["seed"], 3);
  EXPECT_EQ(json["report"]["ensemble_size"], 10);
  EXPECT_EQ(json["report"]["imfs"].get<int>() + 1, static_cast<int>(table.header().size()));
}

TEST_F(DecomposeCli, ColumnByIndexAndSameSeedSameBytes) {
  const std::string a = dir_ + "/a.csv", b = dir_ + "/b.csv";
  ASSERT_EQ(
      test::RunCli("decompose '" + input_ + "' -c 2 -m beemdan -I 8 --seed 5 -q -o '" + a + "'")
          .exit_code,
      0);
  ASSERT_EQ(test::RunCli("decompose '" + input_ +
                         "' -c rate_dph -m beemdan -I 8 --seed 5 -j 1 -q -o '" + b + "'")
                .exit_code,
            0);
  EXPECT_EQ(io::ReadTextFile(a), io::ReadTextFile(b));
}

TEST_F(DecomposeCli, SuppliedNoiseFile) {
  std::string noise = "w0,w1\n";
  for (int i = 0; i < 600; ++i)
    noise += std::to_string(std::sin(i * 12.9898) * 1.7) + "," +
             std::to_string(std::cos(i * 78.233) * 1.7) + "\n";
  io::WriteFileAtomically(dir_ + "/w.csv", noise);
  const auto r = test::RunCli("decompose '" + input_ + "' -c rate_dph -m iceemdan --noise-file '" +
                              dir_ + "/w.csv' -o '" + dir_ + "/o.csv'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto json = nlohmann::json::parse(io::ReadTextFile(dir_ + "/o.csv.json"));
  EXPECT_EQ(json["report"]["ensemble_size"], 2);
  EXPECT_EQ(json["report"]["supplied_noise"], true);
}

struct BadCase {
  const char* name;
  std::string args;  // %IN% and %DIR% are substituted
  int exit_code;
  const char* message;
};

TEST_F(DecomposeCli, BadInputGivesOneLineErrorAndNoOutput) {
  io::WriteFileAtomically(dir_ + "/nan.csv", "x\n1\n2\nnan\n4\n5\n");
  io::WriteFileAtomically(dir_ + "/text.csv", "x\n1\n2\nabc\n4\n5\n");
  io::WriteFileAtomically(dir_ + "/short.csv", "x\n1\n2\n3\n");
  // Squares that underflow: the CEEMDAN family's scaling gave NaN IMFs, exit 0.
  io::WriteFileAtomically(dir_ + "/tiny.csv", "x\n1e-200\n3e-200\n2e-200\n5e-200\n1e-200\n");
  io::WriteFileAtomically(dir_ + "/empty.csv", "");
  io::WriteFileAtomically(dir_ + "/ragged.csv", "a,b\n1,2\n3\n");
  io::WriteFileAtomically(dir_ + "/w_short.csv", "w0\n1\n2\n");
  io::WriteFileAtomically(dir_ + "/inf.csv", "x\n1\ninf\n3\n4\n5\n");
  io::WriteFileAtomically(dir_ + "/constant.csv", "x\n2\n2\n2\n2\n2\n");
  const std::vector<BadCase> cases = {
      {"missing file", "decompose %DIR%/nope.csv -c x", 2, "no such file"},
      {"missing column", "decompose %IN% -c gyro", 2, "column 'gyro' not found"},
      {"column index out of range", "decompose %IN% -c 9", 2, "not found"},
      {"nan", "decompose %DIR%/nan.csv -c x", 3, "data row 3"},
      {"text cell", "decompose %DIR%/text.csv -c x", 3, "'abc'"},
      {"too short", "decompose %DIR%/short.csv -c x", 3, "at least 4"},
      {"empty file", "decompose %DIR%/empty.csv -c x", 3, "empty file"},
      {"ragged", "decompose %DIR%/ragged.csv -c a", 3, "line 3"},
      {"unknown method", "decompose %IN% -c 2 -m wavelet", 2, "--method = 'wavelet'"},
      {"unknown stop", "decompose %IN% -c 2 --stop never", 2, "--stop = 'never'"},
      {"zero ensemble", "decompose %IN% -c 2 -I 0", 2, "--ensemble = 0"},
      {"negative noise", "decompose %IN% -c 2 --noise -1", 2, "--noise = -1"},
      {"bad band", "decompose %IN% -c 2 --band 0.5", 2, "--band = 0.5"},
      {"negative imfs", "decompose %IN% -c 2 --max-imfs -2", 2, "--max-imfs = -2"},
      // Fields of the nested sifting options (sifting.s_number, ...), named by their flags.
      {"zero s-number", "decompose %IN% -c 2 --stop snumber --s-number 0", 2,
       "--s-number = 0: must be"},
      {"negative sift cap", "decompose %IN% -c 2 --max-sifts -5", 2, "--max-sifts = -5: must be"},
      {"zero sd", "decompose %IN% -c 2 --stop sd --sd 0", 2, "--sd = 0: must be"},
      {"not a number", "decompose %IN% -c 2 --seed many", 2, "seed"},
      {"negative seed", "decompose %IN% -c 2 --seed -1", 2, "[0, 2^64)"},
      {"noise rows", "decompose %IN% -c 2 --noise-file %DIR%/w_short.csv", 3, "supplied noise"},
      {"noise with emd", "decompose %IN% -c 2 -m emd --noise-file %DIR%/w_short.csv", 2,
       "--noise-file"},
      {"unused option still checked", "decompose %IN% -c 2 -m emd -I 0", 2, "--ensemble = 0"},
      {"inf cell", "decompose %DIR%/inf.csv -c x", 3, "data row 2"},
      {"negative threads", "decompose %IN% -c 2 -j -3", 2, "threads"},
      {"constant column", "decompose %DIR%/constant.csv -c x", 3, "column 'x' is constant"},
      {"tiny magnitudes", "decompose %DIR%/tiny.csv -c x -m iceemdan", 3,
       "column 'x' varies only below 1e-100 in magnitude"},
  };
  const std::string out = dir_ + "/bad.csv";
  for (const auto& c : cases) {
    const auto r =
        test::RunCli(test::Substitute(c.args, {{"%IN%", input_}, {"%DIR%", dir_}}) + " -o " + out);
    test::ExpectCleanFailure(r, c.exit_code, c.message, out, c.name);
  }
}

TEST_F(DecomposeCli, RefusesMoreSamplesThanFitInMemory) {
  // One sample over the limit (docs/errors.md): a data error before any sifting, with the count.
  std::string csv = "x\n";
  const int n = 20'000'001;
  csv.reserve(static_cast<size_t>(2 * n + 2));
  for (int i = 0; i < n; ++i) csv += (i % 2 ? "1\n" : "2\n");
  const std::string big = dir_ + "/big.csv";
  io::WriteFileAtomically(big, csv);
  csv.clear();
  csv.shrink_to_fit();
  const std::string out = dir_ + "/big_imfs.csv";
  const test::CommandResult r =
      test::RunCli("decompose '" + big + "' -c x --method emd -o '" + out + "'");
  test::ExpectCleanFailure(r, 3, "has 20000001 samples: decompose takes at most 20000000", out,
                           "20000001 samples");
  std::filesystem::remove(big);
}

TEST(Cli, HelpShowsWorkedExamples) {
  const auto top = test::RunCli("--help");
  EXPECT_EQ(top.exit_code, 0);
  EXPECT_NE(top.out.find("Example"), std::string::npos);
  const auto sub = test::RunCli("decompose --help");
  EXPECT_EQ(sub.exit_code, 0);
  EXPECT_NE(sub.out.find("gyrodrift decompose fog.csv"), std::string::npos);
  EXPECT_EQ(test::RunCli("frobnicate").exit_code, 2);
}

}  // namespace
}  // namespace gyrodrift
