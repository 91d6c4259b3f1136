// The log rules every command shares: time stamps that must increase, and gaps refused or filled
// by linear interpolation under an explicit policy.
#include "gyrodrift/io/gyro_log.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/statistics.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::io {
namespace {

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = test::TempDir("gyro_log") + "/" + name;
  WriteFileAtomically(path, text);
  return path;
}

TEST(GyroLog, GapsAreRefusedByDefaultAndFilledLinearlyOnRequest) {
  // 1-s steps, a 3-s step after row 3 (two samples missing) and a 2-s step after row 5.
  const std::string path =
      Write("gaps.csv", "time_s,rate,status\n0,1,0\n1,2,0\n2,3,x\n5,6,0\n6,8,0\n8,10,0\n9,11,0\n");
  try {
    ReadLog(path);
    ADD_FAILURE() << "a gap was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("time_s jumps by 3 s before data row 4 (2 missing"),
              std::string::npos)
        << e.what();
  }
  std::string note;
  const CsvTable t = ReadLog(path, {GapPolicy::kInterpolate}, &note);
  EXPECT_EQ(t.rows(), 10);
  const Eigen::VectorXd time = t.Column("time_s");
  for (Eigen::Index i = 0; i < time.size(); ++i) EXPECT_DOUBLE_EQ(time[i], static_cast<double>(i));
  EXPECT_DOUBLE_EQ(t.Column("rate")[3], 4.0);
  EXPECT_DOUBLE_EQ(t.Column("rate")[4], 5.0);
  EXPECT_DOUBLE_EQ(t.Column("rate")[7], 9.0);
  EXPECT_EQ(note, "note: time_s has 2 gaps (median step 1 s): 3 samples filled by linear "
                  "interpolation (gaps = 'interpolate')");
  // A bad cell is still named by its row in the file.
  try {
    t.Column("status");
    ADD_FAILURE() << "a text cell was read";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("data row 3 is 'x'"), std::string::npos) << e.what();
  }
  // A uniform log is untouched and gets no note.
  note = "stale";
  EXPECT_EQ(ReadLog(Write("u.csv", "time_s,r\n0,1\n1,2\n2,3\n"), {GapPolicy::kInterpolate}, &note)
                .rows(),
            3);
  EXPECT_TRUE(note.empty());
}

TEST(GyroLog, AClockJumpIsNotFilled) {
  // A jump of 1e6 steps in a 4-row log: not lost samples, a clock that jumped.
  const std::string path = Write("jump.csv", "time_s,r\n0,1\n1,2\n1000001,3\n1000002,4\n");
  EXPECT_THROW(ReadLog(path, {GapPolicy::kInterpolate}), DataError);
  EXPECT_EQ(GapPolicyFromString("interpolate"), GapPolicy::kInterpolate);
  EXPECT_EQ(GapPolicyFromString("split"), GapPolicy::kSplit);
  EXPECT_THROW(GapPolicyFromString("drop"), UsageError);
}

TEST(GyroLog, SplitKeepsTheRowsAndSaysWhereRecordsStart) {
  // Gaps after data rows 3 and 5 (0-based rows 3 and 5 start new records); a clock jump is a
  // record break too (nothing is made up).
  const std::string path =
      Write("split.csv", "time_s,r\n0,1\n1,2\n2,3\n5,6\n6,8\n8,10\n9,11\n1000009,12\n");
  std::string note;
  std::vector<Eigen::Index> starts{99};
  const CsvTable t = ReadLog(path, {GapPolicy::kSplit}, &note, &starts);
  EXPECT_EQ(t.rows(), 8);
  EXPECT_EQ(starts, (std::vector<Eigen::Index>{3, 5, 7}));
  EXPECT_NE(note.find("3 gaps"), std::string::npos) << note;
  EXPECT_NE(note.find("split into 4 records"), std::string::npos) << note;
  // The jitter note does not count the gaps a policy handled.
  EXPECT_EQ(NonUniformTimeNote(t), "");
  // A uniform log: one record, no note.
  EXPECT_EQ(ReadLog(Write("u2.csv", "time_s,r\n0,1\n1,2\n2,3\n"), {GapPolicy::kSplit}, &note,
                    &starts)
                .rows(),
            3);
  EXPECT_TRUE(starts.empty());
  EXPECT_TRUE(note.empty());
  // A caller that cannot take records cannot ask for a split.
  EXPECT_THROW(ReadLog(path, {GapPolicy::kSplit}), UsageError);
}

TEST(GyroLog, CarryFillsTheGapsAndSaysWhichRowsWereLogged) {
  // As the interpolate case: 1-s steps, two samples missing after row 3, one after row 5.
  const std::string path =
      Write("carry.csv", "time_s,rate,temp\n0,1,10\n1,2,11\n2,3,12\n5,6,18\n6,8,20\n8,10,24\n9,11,26\n");
  std::string note;
  std::vector<bool> logged{false};  // stale: cleared
  const CsvTable t = ReadLog(path, {GapPolicy::kCarry}, &note, nullptr, {}, &logged);
  ASSERT_EQ(t.rows(), 10);
  EXPECT_EQ(logged, (std::vector<bool>{true, true, true, false, false, true, true, false, true,
                                       true}));
  // The made-up rows are the interpolate policy's: every column linear across the gap.
  EXPECT_DOUBLE_EQ(t.Column("temp")[3], 14.0);
  EXPECT_DOUBLE_EQ(t.Column("temp")[4], 16.0);
  EXPECT_DOUBLE_EQ(t.Column("temp")[7], 22.0);
  EXPECT_DOUBLE_EQ(t.Column("rate")[7], 9.0);
  EXPECT_NE(note.find("3 of 10 rows (30.0 %) filled by linear interpolation"), std::string::npos)
      << note;
  EXPECT_NE(note.find("the 7 logged rows only (gaps = 'carry')"), std::string::npos) << note;
  // Interpolate hands out the same mask to a caller that marks the made-up rows.
  std::vector<bool> filled;
  ReadLog(path, {GapPolicy::kInterpolate}, nullptr, nullptr, {}, &filled);
  EXPECT_EQ(filled, logged);
  // No gap: an empty mask (every row logged).
  ReadLog(Write("u3.csv", "time_s,r\n0,1\n1,2\n2,3\n"), {GapPolicy::kCarry}, &note, nullptr, {},
          &logged);
  EXPECT_TRUE(logged.empty());
  EXPECT_TRUE(note.empty());
  // A caller that would use the made-up rows as data cannot ask for carry.
  EXPECT_THROW(ReadLog(path, {GapPolicy::kCarry}), UsageError);
  EXPECT_EQ(GapPolicyFromString("carry"), GapPolicy::kCarry);
}

TEST(GyroLog, MostlyMadeUpRowsAreAWarningThatSuggestsCarry) {
  // A duty-cycled logger: 2 samples of every 10 s, so 8 of every 10 rows would be made up.
  std::string text = "time_s,r\n";
  for (int burst = 0; burst < 5; ++burst) {
    for (int k = 0; k < 2; ++k) text += std::to_string(10 * burst + k) + "," + std::to_string(k) + "\n";
  }
  const std::string path = Write("bursts.csv", text);
  std::string note;
  const CsvTable t = ReadLog(path, {GapPolicy::kInterpolate, Delimiter::kAuto, "--gaps"}, &note);
  EXPECT_EQ(t.rows(), 42);
  EXPECT_EQ(note.rfind("warning: ", 0), 0U) << note;
  EXPECT_NE(note.find("32 of 42 rows (76.2 %) are made up"), std::string::npos) << note;
  // Spelt as the caller's user sets it: a flag here.
  EXPECT_NE(note.find("(--gaps interpolate)"), std::string::npos) << note;
  EXPECT_NE(note.find("--gaps carry fits, scores and reports on the 10 logged rows only"),
            std::string::npos)
      << note;
  // The error policy names the choices the same way, those the caller takes: records and logged
  // rows here, neither for a caller that passes no place for them.
  const LogOptions error{GapPolicy::kError, Delimiter::kAuto, "--gaps"};
  std::vector<Eigen::Index> starts;
  std::vector<bool> logged;
  try {
    ReadLog(path, error, nullptr, &starts, {}, &logged);
    ADD_FAILURE() << "a gap was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("(--gaps interpolate, or --gaps carry to fit on the "
                                         "logged rows only)"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("(--gaps split)"), std::string::npos) << e.what();
  }
  try {
    ReadLog(path, error);
    ADD_FAILURE() << "a gap was accepted";
  } catch (const DataError& e) {
    const std::string what = e.what();
    const std::string only = "fill gaps by linear interpolation (--gaps interpolate)";
    EXPECT_EQ(what.substr(what.size() - only.size()), only) << what;
  }
  EXPECT_EQ(SpellGaps({}, GapPolicy::kSplit), "gaps = 'split'");
}

TEST(GyroLog, ACallerNamingItsColumnsGetsTheSameChecksWithoutTheTimeColumn) {
  // Regular with short steps (a note), a gap, a repeat, a bad cell: each gives the same table,
  // notes, rate and messages read with its columns named (time_s then kept as steps only, or
  // read whole again for a fault or a gap) as read whole.
  const std::string regular = "time_s,r,x\n0,1,a\n1,2,a\n1.2,3,a\n2,4,a\n3,5,a\n4,6,a\n";
  const std::string gap = "time_s,r,x\n0,1,a\n1,2,a\n2,3,a\n5,4,a\n6,5,a\n";
  const std::string repeat = "time_s,r,x\n0,1,a\n1,2,a\n1,3,a\n";
  const std::string bad = "time_s,r,x\n0,1,a\n1,2,a\nx,3,a\n3,4,a\n";
  int n = 0;
  for (const std::string& text : {regular, gap, repeat, bad}) {
    const std::string path = Write("named" + std::to_string(n++) + ".csv", text);
    for (const GapPolicy gaps : {GapPolicy::kError, GapPolicy::kInterpolate}) {
      std::string whole_note, named_note, whole_error, named_error;
      std::optional<CsvTable> whole, named;
      try {
        whole = ReadLog(path, {gaps}, &whole_note);
      } catch (const Error& e) {
        whole_error = e.what();
      }
      try {
        named = ReadLog(path, {gaps}, &named_note, nullptr, {"r"});
      } catch (const Error& e) {
        named_error = e.what();
      }
      EXPECT_EQ(named_error, whole_error) << path;
      ASSERT_EQ(named.has_value(), whole.has_value()) << path;
      if (!named) continue;
      EXPECT_EQ(named_note, whole_note) << path;
      EXPECT_EQ(named->Column("r"), whole->Column("r")) << path;
      EXPECT_EQ(NonUniformTimeNote(*named), NonUniformTimeNote(*whole)) << path;
      std::string how_named, how_whole, rate_named, rate_whole;
      try {
        rate_whole = std::to_string(ResolveSampleRate(*whole, 0.0, &how_whole));
      } catch (const Error& e) {
        rate_whole = e.what();
      }
      try {
        rate_named = std::to_string(ResolveSampleRate(*named, 0.0, &how_named));
      } catch (const Error& e) {
        rate_named = e.what();
      }
      EXPECT_EQ(rate_named, rate_whole) << path;
      EXPECT_EQ(how_named, how_whole) << path;
    }
  }
  // The regular log's time_s is not held, only its steps.
  const CsvTable t = ReadLog(Write("named_regular.csv", regular), {}, nullptr, nullptr, {"r"});
  EXPECT_FALSE(t.IsKept(0));
  ASSERT_NE(t.time_axis(), nullptr);
  EXPECT_NE(NonUniformTimeNote(t).find("1 of 5 steps are shorter than half the median step 1 s "
                                       "(shortest 0.2 s, before data row 3)"),
            std::string::npos)
      << NonUniformTimeNote(t);
}

// The rate is the clock's: epoch time stamps round every step (a 100 Hz log stamped near 1.76e9 s
// has a median step of 0.0099999905 s, 100.0000954 Hz: `--taus 1` was refused as not a whole
// number of periods), a decimal clock keeps its decimal rate, and an extra sample does not move it.
TEST(GyroLog, TheRateIsTheClocksWhateverItsStampsRoundTo) {
  auto rate_of = [](const std::string& path, bool whole) {
    const CsvTable t = whole ? ReadLog(path) : ReadLog(path, {}, nullptr, nullptr, {"r"});
    EXPECT_EQ(t.time_axis() == nullptr, whole) << path;
    std::string how;
    const double rate = ResolveSampleRate(t, 0.0, &how);
    EXPECT_EQ(how, "time_s");
    return rate;
  };
  std::string epoch = "time_s,r\n", decimal = "time_s,r\n";
  for (int i = 0; i < 3000; ++i) {
    epoch += fmt::format("{:.6f},{}\n", 1764230400.0 + i / 100.0, i % 7);
    decimal += fmt::format("{:.1f},{}\n", i / 10.0, i % 7);
  }
  // Write clears the folder: one file at a time.
  const std::string epoch_path = Write("epoch.csv", epoch);
  // What the median step gave.
  EXPECT_GT(std::abs(1.0 / MedianStep(ReadLog(epoch_path).Column("time_s")) - 100.0), 1e-5);
  EXPECT_NEAR(rate_of(epoch_path, false), 100.0, 1e-6);
  EXPECT_NEAR(rate_of(epoch_path, true), 100.0, 1e-6);
  const std::string decimal_path = Write("decimal.csv", decimal);
  const double decimal_rate = 1.0 / MedianStep(ReadLog(decimal_path).Column("time_s"));
  EXPECT_EQ(rate_of(decimal_path, false), decimal_rate);
  EXPECT_EQ(rate_of(decimal_path, true), decimal_rate);
  // One extra sample in a 1-Hz log (steps 1, 0.2, 0.8, 1, ...): still 1 Hz.
  std::string extra = "time_s,r\n0,1\n1,2\n1.2,3\n";
  for (int i = 2; i < 40; ++i) extra += fmt::format("{},{}\n", i, i % 5);
  const std::string extra_path = Write("extra.csv", extra);
  EXPECT_EQ(rate_of(extra_path, false), 1.0);
  EXPECT_EQ(rate_of(extra_path, true), 1.0);
}

TEST(GyroLog, TheDelimiterCanBeNamed) {
  // A semicolon file whose header holds a comma inside a name: auto-detection takes the comma,
  // naming the delimiter reads it right.
  const std::string path = Write("semi.csv", "time_s;rate,dph\n0;1\n1;2\n2;3\n");
  EXPECT_THROW(ReadLog(path), DataError);  // two header cells, one per row: ragged
  const CsvTable t = ReadLog(path, {GapPolicy::kError, Delimiter::kSemicolon});
  EXPECT_EQ(t.header(), (std::vector<std::string>{"time_s", "rate,dph"}));
  EXPECT_DOUBLE_EQ(t.Column("rate,dph")[2], 3.0);
  EXPECT_EQ(DelimiterFromString("tab"), Delimiter::kTab);
  EXPECT_EQ(ToString(Delimiter::kComma), "comma");
  EXPECT_THROW(DelimiterFromString("pipe"), UsageError);
}

}  // namespace
}  // namespace gyrodrift::io
