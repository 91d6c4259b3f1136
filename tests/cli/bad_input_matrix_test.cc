// Bad input across every command, table-driven (issue 14): each case gets its exit code, one
// stderr line "gyrodrift: error: ..." naming the problem, no output (nor sidecar) left behind, and
// every input file byte-identical afterwards. Messy but readable input (CRLF, a byte-order mark,
// tab- or semicolon-separated files) is accepted instead.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift {
namespace {

struct Case {
  std::string args;     // %D% = the fixture folder, %O% = the output path
  int exit_code;
  std::string message;  // part of the stderr line
};

class BadInput : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(test::TempDir("cli_bad_input_matrix"));
    const std::string good = test::ThermalLogCsv(600, 7);
    const std::string& d = *dir_;
    Write("good.csv", good);
    Write("empty.csv", "");
    Write("header.csv", "time_s,rate_dph,temperature_c,drift_dph\n");
    Write("comments.csv", "# only a comment\n\n");
    Write("onerow.csv", good.substr(0, good.find('\n', good.find('\n') + 1) + 1));
    Write("cell_nan.csv", ReplaceRow(good, 100, "99,nan,20,0"));
    Write("cell_inf.csv", ReplaceRow(good, 100, "99,inf,20,0"));
    Write("cell_huge.csv", ReplaceRow(good, 100, "99,1e999,20,0"));
    Write("cell_big.csv", ReplaceRow(good, 100, "99,1e200,20,0"));  // parses, but overflows
    Write("temperature_big.csv", ReplaceRow(good, 100, "99,0.1,1e300,0"));
    Write("cell_text.csv", ReplaceRow(good, 100, "99,abc,20,0"));
    Write("cell_empty.csv", ReplaceRow(good, 100, "99,,20,0"));
    Write("ragged.csv", ReplaceRow(good, 100, "99,0.1,20"));
    Write("dup.csv", "t,rate_dph,rate_dph\n" + std::string("1,2,3\n2,3,4\n"));
    Write("noname.csv", "time_s,,temperature_c\n1,2,3\n");
    std::string garbage;
    for (int i = 0; i < 4000; ++i) garbage += static_cast<char>((i * 7919 + 13) % 256);
    Write("garbage.csv", garbage);
    Write("hugeline.csv", "time_s,rate_dph\n1," + std::string(1 << 20, '9') + "\n");
    Write("backwards.csv", ReplaceRow(good, 300, "250,0.1,20,0"));
    Write("before_start.csv", "time_s,temperature_c\n-3600,20\n0,40\n");
    Write("headerless.csv", "1,2,3\n2,3,5\n3,5,4\n4,1,2\n");
    Write("constant.csv", [] {
      std::string s = "time_s,rate_dph,temperature_c\n";
      for (int i = 0; i < 600; ++i) s += std::to_string(i) + ",0.5,20\n";
      return s;
    }());
    ASSERT_EQ(test::RunCli("fit '" + d + "/good.csv' -t rate_dph -T temperature_c --mode "
                           "compensate -q -o '" + d + "/comp.json'")
                  .exit_code,
              0);
    ASSERT_EQ(test::RunCli("fit '" + d + "/good.csv' -t rate_dph --mode predict -m poly -q -o '" +
                           d + "/pred.json'")
                  .exit_code,
              0);
    const std::string model = io::ReadTextFile(d + "/comp.json");
    Write("trunc.json", model.substr(0, model.size() / 2));
    std::string edited = model;
    edited.replace(edited.find("rate_dph"), 8, "rate_dpx");
    Write("edited.json", edited);
    Write("foreign.json", "{\"format\": \"other\", \"format_version\": 1}\n");
    Write("notjson.json", "model");
    for (const auto& entry : std::filesystem::directory_iterator(d)) {
      (*inputs_)[entry.path().string()] = io::ReadTextFile(entry.path().string());
    }
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static void Write(const std::string& name, const std::string& text) {
    io::WriteFileAtomically(*dir_ + "/" + name, text);
  }
  // `csv` with data row `row` (1-based) replaced by `line`.
  static std::string ReplaceRow(const std::string& csv, int row, const std::string& line) {
    size_t start = csv.find('\n') + 1;
    for (int r = 1; r < row; ++r) start = csv.find('\n', start) + 1;
    const size_t end = csv.find('\n', start);
    return csv.substr(0, start) + line + csv.substr(end);
  }
  static std::string* dir_;
  static std::map<std::string, std::string>* inputs_;
};
std::string* BadInput::dir_ = nullptr;
std::map<std::string, std::string>* BadInput::inputs_ = new std::map<std::string, std::string>();

TEST_F(BadInput, EveryCaseFailsCleanlyAndLeavesTheInputsAlone) {
  const std::vector<Case> cases = {
      // Files every log-reading command refuses.
      {"decompose %D%/empty.csv -c rate_dph -o %O%", 3, "empty file"},
      {"decompose %D%/comments.csv -c rate_dph -o %O%", 3, "empty file"},
      {"decompose %D%/header.csv -c rate_dph -o %O%", 3, "header but no data rows"},
      {"decompose %D%/onerow.csv -c rate_dph -o %O%", 3,
       "column 'rate_dph' has 1 sample: decompose needs at least 4"},
      {"allan %D%/onerow.csv -c rate_dph -o %O%", 3,
       "onerow.csv has 1 data row: an Allan deviation needs at least 2 samples"},
      {"allan %D%/onerow.csv -c rate_dph --rate-hz 1 -o %O%", 3,
       "column 'rate_dph' has 1 sample: an Allan deviation needs at least 2"},
      {"decompose %D%/cell_nan.csv -c rate_dph -o %O%", 3, "data row 100"},
      {"decompose %D%/cell_inf.csv -c rate_dph -o %O%", 3, "data row 100"},
      {"decompose %D%/cell_huge.csv -c rate_dph -o %O%", 3, "data row 100"},
      {"decompose %D%/cell_text.csv -c rate_dph -o %O%", 3, "'abc'"},
      {"decompose %D%/cell_empty.csv -c rate_dph -o %O%", 3, "data row 100"},
      {"decompose %D%/ragged.csv -c rate_dph -o %O%", 3, "has 3 cells, the header has 4"},
      {"decompose %D%/dup.csv -c rate_dph -o %O%", 3, "twice"},
      {"decompose %D%/noname.csv -c 1 -o %O%", 3, "has no name"},
      {"decompose %D%/garbage.csv -c 1 -o %O%", 3, "garbage.csv"},
      {"decompose %D%/hugeline.csv -c rate_dph -o %O%", 3, "data row 1"},
      {"decompose %D%/backwards.csv -c rate_dph -o %O%", 3,
       "time_s goes backwards at data row 300"},
      {"decompose %D%/constant.csv -c rate_dph -o %O%", 3, "constant"},
      {"decompose %D%/missing.csv -c rate_dph -o %O%", 2, "no such file"},
      {"decompose %D%/good.csv -c nope -o %O%", 2, "'nope' not found"},
      {"decompose %D%/good.csv -c 99 -o %O%", 2, "99"},
      {"decompose %D%/good.csv -c rate_dph -o %D%/nodir/out.csv", 4, "cannot open for writing"},
      // Absurd options.
      {"decompose %D%/good.csv -c rate_dph --ensemble 0 -o %O%", 2, "--ensemble = 0"},
      {"decompose %D%/good.csv -c rate_dph --ensemble 1e9 -o %O%", 2, "--ensemble"},
      {"decompose %D%/good.csv -c rate_dph --noise-strength=-1 -o %O%", 2, "noise"},
      {"decompose %D%/good.csv -c rate_dph --method foo -o %O%", 2, "--method = 'foo'"},
      {"decompose %D%/good.csv -c rate_dph --bogus -o %O%", 2, "--bogus"},
      {"decompose %D%/good.csv -c rate_dph --threads -1 -o %O%", 2, "threads"},
      {"allan %D%/good.csv -c rate_dph --rate-hz 0 -o %O%", 2, "--rate-hz = 0"},
      {"allan %D%/good.csv -c rate_dph --rate-hz nan -o %O%", 2, "--rate-hz = nan"},
      {"allan %D%/good.csv -c rate_dph --rate-hz 1 --taus 0 -o %O%", 2, "--taus = 0"},
      {"allan %D%/good.csv -c rate_dph --rate-hz 1 --taus 1,,2 -o %O%", 2, "--taus"},
      {"allan %D%/constant.csv -c rate_dph --rate-hz 1 -o %O%", 3, "constant"},
      {"allan %D%/cell_nan.csv -c rate_dph --rate-hz 1 -o %O%", 3, "data row 100"},
      {"allan %D%/backwards.csv -c rate_dph --rate-hz 1 -o %O%", 3, "goes backwards"},
      // Finite but beyond any instrument: the squares would overflow into inf and NaN results.
      {"decompose %D%/cell_big.csv -c rate_dph -m eemd -I 5 -o %O%", 3,
       "sample 100 is 1e+200: no instrument logs a magnitude above 1e+100"},
      {"allan %D%/cell_big.csv -c rate_dph --rate-hz 1 -o %O%", 3, "sample 100 is 1e+200"},
      {"fit %D%/cell_big.csv -t rate_dph -T temperature_c --mode compensate -m poly -o %O%", 3,
       "sample 100 is 1e+200"},
      {"fit %D%/temperature_big.csv -t rate_dph -T temperature_c --mode compensate -o %O%", 3,
       "sample 100 is 1e+300"},
      {"evaluate %D%/cell_big.csv -t rate_dph -T temperature_c --mode compensate --methods poly "
       "-o %O%",
       3, "sample 100 is 1e+200"},
      {"allan %D%/good.csv -c rate_dph --confidence 0.9999999999999999 -o %O%", 2, "--confidence"},
      {"fit %D%/good.csv -t rate_dph --mode compensate -o %O%", 2, "needs a temperature channel"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c --mode foo -o %O%", 2, "--mode = 'foo'"},
      {"fit %D%/good.csv -t rate_dph -T rate_dph --mode compensate -o %O%", 2, "must differ"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c, --mode compensate -o %O%", 2,
       "without empty items"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c --mode compensate --reference-temperature "
       "1000 -o %O%",
       2, "--reference-temperature = 1000"},
      {"fit %D%/good.csv -t rate_dph --mode predict --nonlinear -o %O%", 2, "--nonlinear"},
      {"fit %D%/good.csv -t rate_dph --mode predict --lags 0 -o %O%", 2, "--lags = '0'"},
      {"fit %D%/good.csv -t rate_dph --mode predict --seed -1 -o %O%", 2, "--seed"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c --mode compensate -m poly --time-constants "
       "0 -o %O%",
       2, "--time-constants = 0"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c --mode predict -m thermal -o %O%", 2,
       "thermal"},
      {"fit %D%/onerow.csv -t rate_dph -T temperature_c --mode compensate -o %O%", 3, "at least"},
      {"fit %D%/constant.csv -t rate_dph -T temperature_c --mode compensate -o %O%", 3, "constant"},
      {"fit %D%/backwards.csv -t rate_dph -T temperature_c --mode compensate -o %O%", 3,
       "goes backwards"},
      // Model files.
      {"compensate %D%/trunc.json %D%/good.csv -o %O%", 3, "not valid JSON"},
      {"compensate %D%/notjson.json %D%/good.csv -o %O%", 3, "not valid JSON"},
      {"compensate %D%/edited.json %D%/good.csv -o %O%", 3, "checksum mismatch"},
      {"compensate %D%/foreign.json %D%/good.csv -o %O%", 3, "not a gyrodrift model file"},
      {"compensate %D%/pred.json %D%/good.csv -o %O%", 2, "predict-mode model"},
      {"compensate %D%/missing.json %D%/good.csv -o %O%", 2, "no such file"},
      {"compensate %D%/comp.json %D%/good.csv --truth nope -o %O%", 2, "'nope' not found"},
      {"compensate %D%/comp.json %D%/cell_nan.csv -o %O%", 3, "data row 100"},
      {"compensate %D%/comp.json %D%/temperature_big.csv -o %O%", 3,
       "sample 100 is 1e+300: no instrument logs a magnitude above 1e+100"},
      {"predict %D%/pred.json %D%/cell_big.csv -o %O%", 3, "sample 100 is 1e+200"},
      {"compensate %D%/comp.json %D%/dup.csv -o %O%", 3, "twice"},
      {"predict %D%/comp.json %D%/good.csv -o %O%", 2, "compensate-mode model"},
      {"predict %D%/edited.json %D%/good.csv -o %O%", 3, "checksum mismatch"},
      {"predict %D%/pred.json %D%/good.csv --horizon 0 -o %O%", 2, "--horizon = 0"},
      {"predict %D%/pred.json %D%/onerow.csv -o %O%", 3, "onerow.csv"},
      {"export %D%/missing.json -o %O%", 2, "no such file"},
      {"export %D%/comp.json --format h -o %O%", 2, "--format = 'h': must be one of c, "},
      {"export %D%/comp.json --prefix 2x -o %O%", 2, "--prefix = '2x': must be a C identifier"},
      {"export %D%/comp.json -o %D%/comp.json", 2, "is the input"},
      {"export %D%/pred.json -o %O%", 2, "predict-mode model"},
      {"export %D%/comp.json --format json-coefficients --float -o %O%", 2, "--float = true"},
      {"export %D%/edited.json -o %O%", 3, "checksum mismatch"},
      {"export %D%/comp.json -o %D%/nodir/gyro_comp.h", 4, "cannot open for writing"},
      {"evaluate %D%/good.csv -t rate_dph -T temperature_c --mode compensate --methods foo -o %O%",
       2, "'foo'"},
      {"evaluate %D%/good.csv -t rate_dph -T temperature_c --mode compensate --methods poly,poly "
       "-o %O%",
       2, "without repeats"},
      {"evaluate %D%/good.csv -t rate_dph -T temperature_c --mode compensate --split 2 -o %O%", 2,
       "--split = 2"},
      {"evaluate %D%/good.csv -t rate_dph --mode predict --methods thermal -o %O%", 2, "thermal"},
      {"evaluate %D%/good.csv -t rate_dph -T temperature_c --mode compensate --methods poly "
       "--horizon 5 -o %O%",
       2, "--horizon = 5"},
      {"simulate --duration 0 -o %O%", 2, "--duration = 0"},
      {"simulate --duration abc -o %O%", 2, "--duration = abc"},
      {"simulate --profile %D%/missing.csv -o %O%", 2, "--profile"},
      {"simulate --profile %D%/backwards.csv -o %O%", 3, "must strictly increase"},
      {"simulate --profile %D%/dup.csv -o %O%", 3, "twice"},
      {"simulate --rate-hz 0 -o %O%", 2, "--rate-hz = 0"},
      {"demo --duration 1h -o %O%", 2, "--duration = 1h"},
      {"demo --ensemble 0 -o %O%", 2, "--ensemble = 0"},
      {"demo --input %D%/good.csv --target rate_dph -o %O%", 2, "--temperature"},
      {"demo --methods ms-elm,exp-smoothing -o %O%", 2,
       "--methods = 'ms-elm,exp-smoothing': must be methods of compensate mode (exp-smoothing is "
       "not one)"},
      {"simulate --profile %D%/before_start.csv -o %O%", 3,
       "before_start.csv time_s ends at 0 s: a profile's times are seconds from the start"},
      {"decompose %D%/headerless.csv --no-header --columns a,a,b -c b -o %O%", 2,
       "--columns = 'a'"},
      {"fit %D%/good.csv -t rate_dph -T temperature_c --mode compensate -o /dev/null", 4,
       "/dev/null: is not a regular file"},
      {"frobnicate", 2, "frobnicate"},
  };
  const std::string out = *dir_ + "/out.csv";
  for (const Case& c : cases) {
    std::filesystem::remove(out);
    std::filesystem::remove(out + ".json");
    const std::string args = test::Substitute(c.args, {{"%D%", *dir_}, {"%O%", out}});
    test::ExpectCleanFailure(test::RunCli(args), c.exit_code, c.message, out, args);
  }
  EXPECT_GE(cases.size(), 60u);
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/null"));  // not replaced by a file
  for (const auto& [path, text] : *inputs_) {
    EXPECT_EQ(io::ReadTextFile(path), text) << path << " changed";
  }
}

TEST_F(BadInput, MessyButReadableLogsAreAccepted) {
  const std::string good = io::ReadTextFile(*dir_ + "/good.csv");
  std::string crlf, tab, semi;
  for (char ch : good) {
    crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
    tab += ch == ',' ? '\t' : ch;
    semi += ch == ',' ? ';' : ch;
  }
  Write("m_crlf.csv", crlf);
  Write("m_bom.csv", "\xEF\xBB\xBF" + good);
  Write("m_tab.csv", tab);
  Write("m_semi.csv", semi);
  for (const char* name : {"m_crlf.csv", "m_bom.csv", "m_tab.csv", "m_semi.csv"}) {
    const std::string out = *dir_ + "/" + name + ".imfs.csv";
    const test::CommandResult r = test::RunCli("decompose '" + *dir_ + "/" + name +
                                               "' -c rate_dph --method emd -q -o '" + out + "'");
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_TRUE(test::FileExists(out)) << name;
  }
}

}  // namespace
}  // namespace gyrodrift
