// The study's results table (study/table.h): one row kept three ways, every number at full
// precision for the CSV (reads back to the same double), rounded to its cell's significant
// digits for the terminal and the report, NaN shown as "-"; text columns aligned as documented.
#include "gyrodrift/study/table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "gyrodrift/io/csv.h"

namespace gyrodrift::study {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

TEST(StudyTable, KeepsFullPrecisionForCsvAndRoundsForDisplay) {
  Table t;
  t.title = "Scores";
  t.header = {"method", "protocol", "rmse", "train_s"};
  t.Add({"ms-elm", "paper", 0.123456789, {1.5, 3}});
  t.Add({"poly", "causal", std::numeric_limits<double>::quiet_NaN(), {12.345, 3}});
  EXPECT_EQ(t.Csv(),
            "method,protocol,rmse,train_s\n"
            "ms-elm,paper," +
                io::FormatDouble(0.123456789) +
                ",1.5\n"
                "poly,causal," +
                io::FormatDouble(std::nan("")) + ",12.345\n");
  // Names left-aligned, numbers right-aligned, each column as wide as its widest cell.
  EXPECT_EQ(t.Text(),
            "Scores\n"
            "  method protocol   rmse train_s\n"
            "  ms-elm paper    0.1235     1.5\n"
            "  poly   causal        -    12.3\n");
  const html::ReportTable r = t.Report();
  EXPECT_EQ(r.title, "Scores");
  EXPECT_EQ(r.header, t.header);
  EXPECT_EQ(r.rows, t.shown);
  EXPECT_EQ(RoundedText(std::nan("")), "-");
  EXPECT_EQ(RoundedText(2.0 / 3.0, 3), "0.667");
}

TEST(RoundedText, SignificantDigitsNotDecimals) {
  // "{:.4g}": four significant digits wherever the decimal point is, exponent form beyond 1e4.
  EXPECT_EQ(RoundedText(0.000123456), "0.0001235");
  EXPECT_EQ(RoundedText(1234.4), "1234");
  EXPECT_EQ(RoundedText(12344.0), "1.234e+04");
  EXPECT_EQ(RoundedText(-2.0 / 3.0), "-0.6667");
  EXPECT_EQ(RoundedText(2.5), "2.5");  // no padding zeros
  EXPECT_EQ(RoundedText(0.0), "0");
  EXPECT_EQ(RoundedText(2.0 / 3.0, 1), "0.7");
  EXPECT_EQ(RoundedText(2.0 / 3.0, 6), "0.666667");
  // Only NaN is "not applicable"; an infinity is a value and says so.
  EXPECT_EQ(RoundedText(-kNan), "-");
  EXPECT_EQ(RoundedText(std::numeric_limits<double>::infinity()), "inf");
}

TEST(StudyTable, CsvCellsReadBackToTheSameDouble) {
  const std::vector<double> values = {0.1,    1.0 / 3.0, -2.718281828459045, 6.02214076e23,
                                      5e-324, 1e-300,    123456789.123456789};
  Table t;
  t.header = {"name", "value"};
  for (double v : values) t.Add({"x", v});
  ASSERT_EQ(t.csv.size(), values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    // strtod, not stod: stod refuses the subnormal 5e-324 as out of range.
    EXPECT_EQ(std::strtod(t.csv[i][1].c_str(), nullptr), values[i]) << t.csv[i][1];
    // The shown cell is the same number rounded, not another one.
    EXPECT_EQ(t.shown[i][1], RoundedText(values[i]));
  }
}

TEST(StudyTable, EachCellKeepsItsOwnDigitsAndTextStaysText) {
  Table t;
  t.header = {"stage", "seconds", "share_%", "note"};
  // A number-like text cell is not reformatted: it is shown and written as given.
  t.Add({"decompose", {1.23456, 3}, {98.76543, 2}, "0.1234567"});
  EXPECT_EQ(t.shown[0], (std::vector<std::string>{"decompose", "1.23", "99", "0.1234567"}));
  EXPECT_EQ(t.csv[0], (std::vector<std::string>{"decompose", "1.23456", "98.76543", "0.1234567"}));
}

TEST(StudyTable, TextAlignsTheFirstTwoColumnsLeftAndTheRestRight) {
  Table t;
  t.title = "T";
  t.header = {"a", "b", "c", "d"};
  t.Add({"long name", "x", "text", 1.0});
  t.Add({"n", "longer", "t", 12345.0});
  // Columns 3 and 4 right-aligned, even the text cell of column 3; every column as wide as its
  // widest cell; each line starts with two spaces.
  EXPECT_EQ(t.Text(),
            "T\n"
            "  a         b         c         d\n"
            "  long name x      text         1\n"
            "  n         longer    t 1.234e+04\n");
}

// A row of another width is the caller's bug: refused, not drawn past the header's columns.
TEST(StudyTable, ARowMustHaveAsManyCellsAsTheHeader) {
  Table t;
  t.title = "Scores";
  t.header = {"method", "rmse"};
  EXPECT_THROW(t.Add({"ms-elm", 0.1, 0.2}), std::logic_error);
  EXPECT_THROW(t.Add({"ms-elm"}), std::logic_error);
  EXPECT_TRUE(t.csv.empty());
  t.Add({"ms-elm", 0.1});
  EXPECT_EQ(t.csv.size(), 1u);
}

TEST(StudyTable, AHeaderWithoutRowsRendersItsHeader) {
  Table t;
  t.title = "Empty";
  t.caption = "nothing ran";
  t.header = {"method", "rmse"};
  EXPECT_EQ(t.Csv(), "method,rmse\n");
  EXPECT_EQ(t.Text(), "Empty\n  method rmse\n");
  const html::ReportTable r = t.Report();
  EXPECT_EQ(r.caption, "nothing ran");
  EXPECT_TRUE(r.rows.empty());
  EXPECT_TRUE(r.links.empty());  // the study's tables link nothing
}

}  // namespace
}  // namespace gyrodrift::study
