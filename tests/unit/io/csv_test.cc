#include "gyrodrift/io/csv.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::io {
namespace {

TEST(CsvTable, ParsesHeaderCommentsCrlfAndQuotedNames) {
  const auto t = CsvTable::Parse("# comment\n\"time_s\", rate\r\n0,1.5\r\n1,-2e-3\r\n\n", "mem");
  ASSERT_EQ(t.header().size(), 2u);
  EXPECT_EQ(t.header()[0], "time_s");
  EXPECT_EQ(t.rows(), 2);
  EXPECT_EQ(t.Column("rate")[1], -2e-3);
  EXPECT_EQ(t.Column("1")[1], 1.0);
}

TEST(CsvTable, TabAndSemicolonFilesAreReadWhenTheHeaderHasNoComma) {
  const CsvTable tab = CsvTable::Parse("time_s\trate_dph\n0\t1.5\n1\t-2\n", "tab");
  EXPECT_EQ(tab.header(), (std::vector<std::string>{"time_s", "rate_dph"}));
  EXPECT_EQ(tab.Column("rate_dph"), (Eigen::VectorXd(2) << 1.5, -2.0).finished());
  // The BOM literal ends before "a": "\xBFa" would be one (out of range) hex escape, and the
  // file would start with a garbled byte instead of a byte-order mark.
  const CsvTable semi = CsvTable::Parse("\xEF\xBB\xBF" "a;b\r\n1;2\r\n3;4\r\n", "semi");
  EXPECT_EQ(semi.header(), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(semi.Column("b"), (Eigen::VectorXd(2) << 2.0, 4.0).finished());
  // Decimal commas are not read: the cell is named, not silently split.
  const CsvTable decimal = CsvTable::Parse("a;b\n1,5;2\n", "decimal");
  EXPECT_THROW(decimal.Column("a"), DataError);
  // A comma in the header wins: a tab inside a comma file is a cell's padding.
  const CsvTable comma = CsvTable::Parse("a,\tb\n1,\t2\n", "comma");
  EXPECT_EQ(comma.header(), (std::vector<std::string>{"a", "b"}));
}

TEST(CsvTable, NamesMissingColumn) {
  const auto t = CsvTable::Parse("a,b\n1,2\n", "f.csv");
  try {
    t.Column("c");
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("column 'c' not found in f.csv"), std::string::npos);
  }
  EXPECT_THROW(t.Column("3"), UsageError);
  EXPECT_THROW(t.Column("0"), UsageError);
}

TEST(CsvTable, NonNumericAndNonFiniteCellsNameTheRow) {
  const auto t = CsvTable::Parse("a,b,c\n1,x,1\n2,3,nan\n3,4,inf\n", "f.csv");
  EXPECT_EQ(t.Column("a").size(), 3);
  try {
    t.Column("b");
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("data row 1 is 'x'"), std::string::npos) << e.what();
  }
  try {
    t.Column("c");
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("data row 2 is 'nan'"), std::string::npos) << e.what();
  }
}

TEST(CsvTable, DuplicateHeaderNamesAreErrors) {
  try {
    CsvTable::Parse("a,b,a\n1,2,3\n", "dup.csv");
    FAIL();
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("names column 'a' twice (1 and 3)"), std::string::npos)
        << e.what();
  }
}

TEST(CsvTable, RaggedRowsAndEmptyFilesAreErrors) {
  EXPECT_THROW(CsvTable::Parse("a,b\n1\n", "f"), DataError);
  EXPECT_THROW(CsvTable::Parse("", "f"), DataError);
  EXPECT_THROW(CsvTable::Parse("a,b\n", "f"), DataError);
  EXPECT_THROW(CsvTable::Read("/nonexistent/file.csv"), IoError);
}

TEST(Csv, WriteReadRoundTripIsExact) {
  const std::string dir = test::TempDir("csv_roundtrip");
  Eigen::VectorXd a(3), b(3);
  a << 0.1, 1.0 / 3.0, -1e-300;
  b << 1e300, std::nextafter(1.0, 2.0), 0.0;
  WriteCsv(dir + "/x.csv", {{"a", a}, {"b", b}});
  const auto t = CsvTable::Read(dir + "/x.csv");
  EXPECT_EQ(t.Column("a"), a);
  EXPECT_EQ(t.Column("b"), b);
}

TEST(Files, FailedSetLeavesNothingBehind) {
  const std::string dir = test::TempDir("atomic_set");
  EXPECT_THROW(WriteFilesAtomically({{dir + "/ok.txt", "x"}, {dir + "/missing/dir/f.txt", "y"}}),
               IoError);
  EXPECT_FALSE(test::FileExists(dir + "/ok.txt"));
  // A directory among the targets or a target named twice: refused before anything is written,
  // and existing files keep their contents.
  WriteFileAtomically(dir + "/old.txt", "old");
  std::filesystem::create_directory(dir + "/sub");
  EXPECT_THROW(WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/sub", "z"}}), IoError);
  EXPECT_THROW(WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/./old.txt", "z"}}),
               IoError);
  EXPECT_EQ(ReadTextFile(dir + "/old.txt"), "old");
  // A set that succeeds replaces existing files and leaves no temporary or backup behind.
  WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/other.txt", "o"}});
  EXPECT_EQ(ReadTextFile(dir + "/old.txt"), "new");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3);  // old.txt, other.txt, sub
}

TEST(Csv, StreamedTextEqualsRenderedText) {
  const std::string dir = test::TempDir("csv_streamed");
  // Enough rows for several 1-MiB blocks.
  const Eigen::Index n = 120000;
  Eigen::MatrixXd m(n, 3);
  for (Eigen::Index r = 0; r < n; ++r) {
    m(r, 0) = r * 0.1;
    m(r, 1) = std::sin(r * 1e-3) / 3.0;
    m(r, 2) = -1e-300 * r;
  }
  const std::string path = dir + "/s.csv";
  WriteStreamedFilesAtomically({{path, [&](std::FILE* out) {
                                   WriteCsvTo(out, {{"a", m.col(0).data(), n},
                                                    {"b", m.col(1).data(), n},
                                                    {"c", m.col(2).data(), n}});
                                 }}});
  const std::string text = ReadTextFile(path);
  EXPECT_GT(text.size(), size_t{3} << 20);
  EXPECT_TRUE(text == RenderCsv({{"a", m.col(0)}, {"b", m.col(1)}, {"c", m.col(2)}}));
  // Columns of different lengths: a DataError, and the previous file stays as it was.
  EXPECT_THROW(WriteStreamedFilesAtomically({{path, [&](std::FILE* out) {
                                                WriteCsvTo(out, {{"a", m.col(0).data(), n},
                                                                 {"b", m.col(1).data(), n - 1}});
                                              }}}),
               DataError);
  EXPECT_TRUE(ReadTextFile(path) == text);
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);
}

TEST(Files, StaleTemporariesOfKilledWritersAreRemovedByTheNextWrite) {
  const std::string dir = test::TempDir("atomic_stale");
  // A pid that no longer runs: a child that has exited and been reaped.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child);
  const std::string alive = std::to_string(::getppid());
  const std::vector<std::string> stale = {"x.csv.tmp." + dead, "x.csv.bak." + dead};
  const std::vector<std::string> kept = {
      "x.csv.tmp." + alive,  // a writer that still runs
      "y.csv.tmp." + dead,   // another target's: that write cleans it
      "x.csv.tmp.12ab",      // not our naming pattern
      "x.csv.old"};
  for (const auto& name : stale) WriteFileAtomically(dir + "/" + name, "partial");
  for (const auto& name : kept) WriteFileAtomically(dir + "/" + name, "other");
  WriteFileAtomically(dir + "/x.csv", "complete");
  EXPECT_EQ(ReadTextFile(dir + "/x.csv"), "complete");
  for (const auto& name : stale) EXPECT_FALSE(test::FileExists(dir + "/" + name)) << name;
  for (const auto& name : kept) EXPECT_EQ(ReadTextFile(dir + "/" + name), "other") << name;
}

}  // namespace
}  // namespace gyrodrift::io
