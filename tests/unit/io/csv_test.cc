#include "gyrodrift/io/csv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
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
  // Taking a bad column out is refused the same way, and leaves it in the table.
  CsvTable u = t;
  EXPECT_THROW(u.TakeColumn("b"), DataError);
  EXPECT_TRUE(u.IsKept(1));
}

// Messages a user can act on: a quoted cell shows its control bytes (a NUL would end the message)
// and at most 40 bytes; CR-only line endings and UTF-16 text are named as such.
TEST(CsvTable, UnreadableTextIsNamedForWhatItIs) {
  const auto quoted = [](const std::string& text) {
    try {
      CsvTable::Parse(text, "f.csv").Column("b");
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(quoted(std::string("a,b\n1,2\n2,3\0x\n", 14)),
            "f.csv: column 'b' data row 2 is '3\\x00x': every value must be a finite number");
  EXPECT_EQ(quoted("a,b\n1," + std::string(100, '9') + "x\n"),
            "f.csv: column 'b' data row 1 is '" + std::string(40, '9') +
                "... (101 bytes)': every value must be a finite number");
  // A character across byte 40 is left out whole ("\xC3\xA0" is a UTF-8 a-grave at bytes 39-40).
  EXPECT_EQ(quoted("a,b\n1," + std::string(39, 'x') + "\xC3\xA0" + "yz\n"),
            "f.csv: column 'b' data row 1 is '" + std::string(39, 'x') +
                "... (43 bytes)': every value must be a finite number");
  const auto refusal = [](const std::string& text) {
    try {
      CsvTable::Parse(text, "f.csv");
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(
      refusal("a,b\r1,2\r2,3\r"),
      "f.csv: lines end in CR alone (classic Mac text): save it with LF or CRLF line endings");
  EXPECT_EQ(refusal(std::string("\xFF\xFE"
                                "a\0,\0b\0\n\0",
                                10)),
            "f.csv: UTF-16 text (its byte-order mark): save it as UTF-8");
  EXPECT_EQ(refusal("a,b\r\n1,2\r\n"), "");  // CRLF stays fine
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
  // A file that opens but cannot be read (a directory) is an I/O error, not an empty file.
  EXPECT_THROW(CsvTable::Read(test::TempDir("csv_directory")), IoError);
}

// What a reading gave: the table, or the message it was refused with.
struct Reading {
  std::optional<CsvTable> table;
  std::string error;
};

Reading ParseText(const std::string& text, Delimiter delimiter = Delimiter::kAuto) {
  try {
    return {CsvTable::Parse(text, "f.csv", delimiter), ""};
  } catch (const Error& e) {
    return {std::nullopt, e.what()};
  }
}

Reading ReadBlocks(const std::string& text, const CsvReadOptions& options) {
  std::istringstream in(text);
  try {
    return {CsvTable::Read(in, "f.csv", options), ""};
  } catch (const Error& e) {
    return {std::nullopt, e.what()};
  }
}

// The block reader gave what the whole-text parse gives: the same message, or the same header,
// rows and, in every column it kept, the same values to the bit or the same bad-cell message.
void ExpectSameReading(const Reading& whole, const Reading& blocks, const std::string& label) {
  ASSERT_EQ(whole.table.has_value(), blocks.table.has_value()) << label << whole.error << blocks.error;
  if (!whole.table) {
    EXPECT_EQ(whole.error, blocks.error) << label;
    return;
  }
  const CsvTable& a = *whole.table;
  const CsvTable& b = *blocks.table;
  ASSERT_EQ(a.header(), b.header()) << label;
  ASSERT_EQ(a.rows(), b.rows()) << label;
  for (int c = 0; c < static_cast<int>(a.header().size()); ++c) {
    if (!b.IsKept(c)) continue;
    std::string error_a, error_b;
    Eigen::VectorXd va, vb;
    try {
      va = a.Column(c);
    } catch (const DataError& e) {
      error_a = e.what();
    }
    try {
      vb = b.Column(c);
    } catch (const DataError& e) {
      error_b = e.what();
    }
    EXPECT_EQ(error_a, error_b) << label << " column " << c;
    ASSERT_EQ(va.size(), vb.size()) << label << " column " << c;
    if (va.size() == 0) continue;  // refused: no values (and memcmp must not see null)
    EXPECT_EQ(std::memcmp(va.data(), vb.data(), sizeof(double) * static_cast<size_t>(va.size())), 0)
        << label << " column " << c;
  }
}

TEST(CsvTable, BlockReaderGivesTheWholeTextTableForEveryBlockSize) {
  // A byte-order mark, comments, blank lines, CRLF ends, quoted and padded names, a bad and a
  // non-finite cell, a last line without its newline: every line crosses some block end.
  const std::vector<std::string> texts = {
      "\xEF\xBB\xBF# logged 2026-11-25\r\n\"time_s\", rate_dph ,temp\r\n0,1.5,20\r\n\r\n"
      "0.01,-2e-3,x\r\n# pause\n0.02,+3,21\r\n0.03,inf,22",
      "a;b\n1;2\n3;4\n",
      "\xEF\xBB\xBF" "a\tb\r\n1\t2\r\n",
      "\xEF\xBB",  // the start of a byte-order mark only: a one-column header, no rows
      "a,b\n1,2\n3\n4,5\n",   // ragged: line 3 is named
      "a,b,a\n1,2,3\n",       // a name twice
      "a,,c\n1,2,3\n",        // a header cell without a name
      "a,b\n",                // no data rows
      "\n# only a comment\n",  // no header
      "",
  };
  for (size_t i = 0; i < texts.size(); ++i) {
    for (const Delimiter d : {Delimiter::kAuto, Delimiter::kComma, Delimiter::kTab}) {
      const Reading whole = ParseText(texts[i], d);
      for (const size_t block : {1, 2, 3, 5, 7, 64, 4 << 20}) {
        ExpectSameReading(whole, ReadBlocks(texts[i], {.delimiter = d, .block_bytes = block}),
                          "text " + std::to_string(i) + " block " + std::to_string(block));
      }
    }
  }
  EXPECT_THROW(CsvTable::Read("x.csv", CsvReadOptions{.block_bytes = 0}), OptionError);
}

TEST(CsvTable, KeepsOnlyTheNamedColumnsAndStillRefusesRaggedRows) {
  const std::string text = "time_s,rate_dph,status,temp\n0,1,ok,20\n1,2,ok,21\n2,3,ok,22\n";
  const Reading whole = ParseText(text);
  // By name, by 1-based index, and a name that is not there (ignored by the reader, refused by
  // Column with the message it gives for any unknown name).
  const Reading some = ReadBlocks(text, {.columns = {"rate_dph", "4", "nope"}, .block_bytes = 5});
  ExpectSameReading(whole, some, "rate_dph,4");
  const CsvTable& t = *some.table;
  EXPECT_FALSE(t.IsKept(0));
  EXPECT_TRUE(t.IsKept(1));
  EXPECT_FALSE(t.IsKept(2));  // a text column nobody asked for costs nothing
  EXPECT_TRUE(t.IsKept(3));
  EXPECT_EQ(t.ColumnRef("rate_dph"), (Eigen::VectorXd(3) << 1, 2, 3).finished());
  EXPECT_EQ(&t.ColumnRef("rate_dph"), &t.ColumnRef(1));  // no copy
  EXPECT_THROW(t.Column("time_s"), UsageError);
  // Taken out without a copy: the table no longer has it.
  CsvTable taken = t;
  const double* stored = taken.ColumnRef("4").data();
  const Eigen::VectorXd temp = taken.TakeColumn("temp");
  EXPECT_EQ(temp.data(), stored);
  EXPECT_EQ(temp, (Eigen::VectorXd(3) << 20, 21, 22).finished());
  EXPECT_FALSE(taken.IsKept(3));
  EXPECT_THROW(taken.TakeColumn("temp"), UsageError);
  EXPECT_EQ(taken.ColumnRef("rate_dph"), t.ColumnRef("rate_dph"));
  try {
    t.Column("nope");
    ADD_FAILURE() << "an unknown column was read";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()),
              "column 'nope' not found in f.csv (columns: time_s, rate_dph, status, temp; or a "
              "1-based index up to 4)");
  }
  // A row short of a cell in a column that is not kept is refused as the whole parse refuses it.
  const std::string ragged = "a,b,c\n1,2,3\n4,5\n";
  const Reading refused = ReadBlocks(ragged, {.columns = {"a"}, .block_bytes = 3});
  ASSERT_FALSE(refused.table.has_value());
  EXPECT_EQ(refused.error, "f.csv: line 3 has 2 cells, the header has 3");
  EXPECT_EQ(refused.error, ParseText(ragged).error);
}

TEST(CsvTable, FileReadInBlocksEqualsTheParseOfItsText) {
  // About 12 MiB of rows of varying length: lines cross the 4-MiB block ends of a file read with
  // the default options; CRLF ends, a comment now and then.
  const std::string dir = test::TempDir("csv_blocks");
  std::string text = "\xEF\xBB\xBF" "time_s,rate_dph,temperature_c\r\n";
  for (int i = 0; i < 400000; ++i) {
    text += FormatDouble(i * 0.01) + "," + FormatDouble(std::sin(i * 1e-3) / 3.0) + "," +
            FormatDouble(20.0 + i % 97) + "\r\n";
    if (i % 99991 == 0) text += "# marker\r\n";
  }
  ASSERT_GT(text.size(), size_t{12} << 20);
  WriteFileAtomically(dir + "/big.csv", text);
  const Reading whole = ParseText(text);
  Reading read;
  read.table = CsvTable::Read(dir + "/big.csv", CsvReadOptions{});
  // The source names the file, the text parse names "f.csv": compare the values.
  ExpectSameReading(whole, read, "default blocks");
  Reading kept;
  kept.table = CsvTable::Read(dir + "/big.csv", CsvReadOptions{.columns = {"rate_dph"}});
  ExpectSameReading(whole, kept, "rate_dph only");
  EXPECT_EQ(kept.table->ColumnRef("rate_dph").size(), 400000);
  EXPECT_FALSE(kept.table->IsKept(0));
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

}  // namespace
}  // namespace gyrodrift::io

namespace gyrodrift::io {
namespace {

// Serial-terminal captures (issue 26): no header, a banner, damaged lines.
std::string CaptureFile(const std::string& name, const std::string& text) {
  const std::string path = test::TempDir("csv_capture") + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(CsvCapture, NamesGivenForAFileWithoutAHeaderAfterItsBanner) {
  const std::string path = CaptureFile(
      "capture.csv", "=~=~= PuTTY log 2026.05.08 =~=~=\n13.25,0.5,1\n13.26,0.6,2\n13.27,0.7,3\n");
  const CsvTable t = CsvTable::Read(path, CsvReadOptions{.names = {"temp_c", "gx", "n"},
                                                         .skip_rows = 1});
  EXPECT_EQ(t.header(), (std::vector<std::string>{"temp_c", "gx", "n"}));
  ASSERT_EQ(t.rows(), 3);
  EXPECT_EQ(t.Column("gx")[2], 0.7);
  EXPECT_TRUE(t.skipped_lines().empty());
  // Without skipping the banner, it is a damaged first row.
  try {
    CsvTable::Read(path, CsvReadOptions{.names = {"temp_c", "gx", "n"}});
    ADD_FAILURE() << "the banner was read as data";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("line 1 has 1 cells, the header has 3 (the names given)"),
              std::string::npos)
        << e.what();
  }
}

TEST(CsvCapture, DamagedLinesAreSkippedAndListedOnRequest) {
  // Line 3 has a value run into the next, line 5 a cell too few, the last line is cut.
  const std::string text = "a,b,c\n1,2,3\n4,-0.3-0.31,6\n7,8,9\n10,11\n13,14,15\n1";
  const std::string path = CaptureFile("damaged.csv", text);
  EXPECT_THROW(CsvTable::Read(path), DataError);
  for (size_t block : {size_t{3}, size_t{4} << 20}) {
    const CsvTable t =
        CsvTable::Read(path, CsvReadOptions{.block_bytes = block, .bad_lines = BadLines::kSkip});
    ASSERT_EQ(t.rows(), 3) << block;
    EXPECT_EQ(t.Column("a"), (Eigen::VectorXd(3) << 1, 7, 13).finished());
    EXPECT_EQ(t.skipped_lines(), (std::vector<Eigen::Index>{3, 5, 7}));
  }
  // A cell of a column not kept is not checked: the row stays.
  const CsvTable only_a = CsvTable::Read(
      path, CsvReadOptions{.columns = {"a"}, .bad_lines = BadLines::kSkip});
  EXPECT_EQ(only_a.skipped_lines(), (std::vector<Eigen::Index>{5, 7}));
}

TEST(CsvTable, ATimeAxisIsCheckedAsAKeptColumnButNotStored) {
  const std::string text = "time_s,rate_dph,status\n0,1,ok\n0.5,2,ok\n1.5,3,ok\n2,4,ok\n";
  for (size_t block : {size_t{3}, size_t{4} << 20}) {
    const Reading r =
        ReadBlocks(text, {.columns = {"rate_dph"}, .block_bytes = block, .time_axis = "time_s"});
    ASSERT_TRUE(r.table.has_value()) << r.error;
    const CsvTable& t = *r.table;
    EXPECT_FALSE(t.IsKept(0));
    EXPECT_THROW(t.ColumnRef("time_s"), UsageError);
    ASSERT_NE(t.time_axis(), nullptr);
    EXPECT_EQ(t.time_axis()->rows(), 4);
    EXPECT_EQ(t.time_axis()->MedianStep(), 0.5);
    EXPECT_EQ(t.time_axis()->LargestStep(), 1.0);
    EXPECT_EQ(t.ColumnRef("rate_dph"), (Eigen::VectorXd(4) << 1, 2, 3, 4).finished());
  }
  // Named among the columns too: kept whole, no axis.
  const Reading both = ReadBlocks(text, {.columns = {"time_s"}, .time_axis = "time_s"});
  ASSERT_TRUE(both.table.has_value());
  EXPECT_EQ(both.table->time_axis(), nullptr);
  EXPECT_TRUE(both.table->IsKept(0));
  // A damaged time cell skips its row as a kept column's does; without kSkip the axis says so.
  const std::string damaged = "time_s,rate\n0,1\n1x,2\n2,3\n";
  const std::string path = CaptureFile("axis.csv", damaged);
  const CsvTable skipped = CsvTable::Read(
      path, {.columns = {"rate"}, .bad_lines = BadLines::kSkip, .time_axis = "time_s"});
  EXPECT_EQ(skipped.skipped_lines(), (std::vector<Eigen::Index>{3}));
  EXPECT_EQ(skipped.time_axis()->rows(), skipped.rows());
  EXPECT_TRUE(skipped.time_axis()->complete());
  const CsvTable kept_bad =
      CsvTable::Read(path, {.columns = {"rate"}, .time_axis = "time_s"});
  EXPECT_EQ(kept_bad.rows(), 3);
  EXPECT_FALSE(kept_bad.time_axis()->complete());
}

// What left no data is said: the lines skipped, the rows all bad, a binary header.
TEST(CsvCapture, AnEmptyResultSaysWhatEmptiedIt) {
  auto message = [](const std::string& text, const CsvReadOptions& options) {
    try {
      CsvTable::Read(CaptureFile("empty.csv", text), options);
    } catch (const DataError& e) {
      return std::string(e.what());
    }
    return std::string("read");
  };
  EXPECT_NE(message("a,b\n1,2\n", {.skip_rows = 5})
                .find("skipping its first 5 lines leaves nothing to read (the file has 2 lines)"),
            std::string::npos);
  // Lines left after the skipped ones but all comments: the file is empty, not over-skipped.
  EXPECT_NE(message("banner\n# only\n", {.skip_rows = 1}).find("empty file (no header row)"),
            std::string::npos);
  EXPECT_NE(message("a,b\nx,2\n1\n", {.bad_lines = BadLines::kSkip})
                .find("every data row is bad (2 skipped as bad lines, the first at line 2)"),
            std::string::npos);
  EXPECT_NE(message("a,b\n", {}).find("header but no data rows"), std::string::npos);
  EXPECT_NE(message(std::string("a,b\0c\n1,2\n", 10), {})
                .find("line 1 (the header) holds a NUL byte: not a text file"),
            std::string::npos);
  // Without a header the first line is data: a garbled first row of a serial capture is a bad
  // line like any other.
  EXPECT_EQ(
      message(std::string("1\0,2\n3,4\n", 9), {.names = {"a", "b"}, .bad_lines = BadLines::kSkip}),
      "read");
}

TEST(CsvCapture, BadOptionsAreRefused) {
  const std::string path = CaptureFile("ok.csv", "1,2\n");
  EXPECT_THROW(CsvTable::Read(path, CsvReadOptions{.names = {"a", "a"}}), OptionError);
  EXPECT_THROW(CsvTable::Read(path, CsvReadOptions{.names = {"a", ""}}), OptionError);
  EXPECT_THROW(CsvTable::Read(path, CsvReadOptions{.skip_rows = -1}), OptionError);
  EXPECT_THROW(BadLinesFromString("ignore"), OptionError);
  EXPECT_EQ(BadLinesFromString("skip"), BadLines::kSkip);
}

}  // namespace
}  // namespace gyrodrift::io
