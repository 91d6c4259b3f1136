// A results table of the study kept three ways: every number at full precision for the CSV files
// (io::FormatDouble, which round-trips), rounded for the terminal and the HTML report. Cells are
// text or numbers; a number that has no value (no simulator setting, a noise fit that failed) is
// NaN and shows as "-". Cost: O(cells) per rendering.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/html/report.h"

namespace gyrodrift::study {

// A number as the terminal and the report show it: `digits` significant digits ("{:.4g}"), NaN
// as "-" (a dash reads as "not applicable" where "nan" reads as a computation gone wrong).
std::string RoundedText(double value, int digits = 4);

struct Table {
  std::string title, caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> csv;    // rows at full precision
  std::vector<std::vector<std::string>> shown;  // the same rows rounded (RoundedText)

  struct Cell {
    std::string text;
    double value = std::numeric_limits<double>::quiet_NaN();
    bool numeric = false;
    int digits = 4;  // significant digits when shown
    Cell(std::string t) : text(std::move(t)) {}  // NOLINT: a row reads {"name", 1.5, {0.1, 3}}
    Cell(const char* t) : text(t) {}             // NOLINT
    Cell(double v, int d = 4) : value(v), numeric(true), digits(d) {}  // NOLINT
  };
  // Appends a row of as many cells as the header (std::logic_error otherwise).
  void Add(const std::vector<Cell>& cells);

  // Header and rows, comma-separated, one line each (cells hold no commas).
  std::string Csv() const;
  // The title, then the rounded rows in aligned columns: the first two left-aligned (names), the
  // rest right-aligned (numbers).
  std::string Text() const;
  // The rounded rows for html::HtmlReport::AddTable.
  html::ReportTable Report() const;
};

}  // namespace gyrodrift::study
