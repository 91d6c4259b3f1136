// CSV input and output.
//
// Input: a header row, then one row per sample, separated by commas, or by tabs or semicolons
// when the header has no comma (instrument and spreadsheet exports; decimal commas are not read),
// or by the delimiter the caller names.
// Lines starting with '#' and blank lines are skipped; CRLF endings, a UTF-8 byte-order mark and
// quoted header names are accepted. Every cell is parsed
// as a number up front; a column with a non-numeric cell can still be loaded as long as nobody
// asks for it, and asking for it names the first bad cell.
// Output: full double precision (shortest text that reads back to the same double), written to a
// temporary file and renamed, so a file is written completely or not at all.
#pragma once

#include <Eigen/Core>
#include <cstdio>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gyrodrift::io {

// The cell delimiter: auto = a comma where the header has one, else a tab, else a semicolon.
enum class Delimiter { kAuto, kComma, kTab, kSemicolon };
std::string_view ToString(Delimiter delimiter);  // "auto", "comma", "tab", "semicolon"
Delimiter DelimiterFromString(std::string_view text);  // OptionError naming the choices

class CsvTable {
 public:
  // Reads the whole file. Throws IoError (missing/unreadable file) or DataError (no header,
  // ragged rows, no data rows).
  static CsvTable Read(const std::string& path, Delimiter delimiter = Delimiter::kAuto);
  // Parses CSV text; `source` names it in messages.
  static CsvTable Parse(const std::string& text, const std::string& source,
                        Delimiter delimiter = Delimiter::kAuto);

  const std::vector<std::string>& header() const { return header_; }
  Eigen::Index rows() const { return rows_; }
  const std::string& source() const { return source_; }

  // Column index for a header name or a 1-based index ("3"). Throws UsageError naming the
  // available columns.
  int ResolveColumn(const std::string& spec) const;
  bool HasColumn(const std::string& name) const;
  // The column's values. Throws DataError naming the row of the first non-numeric, NaN or
  // infinite cell.
  Eigen::VectorXd Column(const std::string& spec) const;
  Eigen::VectorXd Column(int index) const;

  // A copy with rows inserted by linear interpolation: for each (row, count), `count` rows evenly
  // spaced between data rows `row` and `row + 1` (0-based), in every column. Messages about a bad
  // cell keep naming its row in the file.
  CsvTable WithInterpolatedRows(const std::vector<std::pair<Eigen::Index, int>>& insert) const;

 private:
  struct BadCell {
    Eigen::Index row = -1;  // 1-based data row; -1 if the column is clean
    std::string text;
  };
  std::string source_;
  std::vector<std::string> header_;
  std::vector<std::vector<double>> columns_;
  std::vector<BadCell> first_bad_;
  Eigen::Index rows_ = 0;
};

// A named column for writing.
struct CsvColumn {
  std::string name;
  Eigen::VectorXd values;
};

// Formats a double as the shortest text that reads back to the same value.
std::string FormatDouble(double value);

// Writes header + rows; all columns must have the same length. Atomic (temp file + rename).
void WriteCsv(const std::string& path, const std::vector<CsvColumn>& columns);
// Renders the same text as WriteCsv without touching the file system.
std::string RenderCsv(const std::vector<CsvColumn>& columns);

// A named column of `rows` contiguous doubles owned by the caller: a large table (a
// decomposition's N x K matrix, one column each) is streamed to a file without a copy.
struct CsvColumnView {
  std::string name;
  const double* values = nullptr;
  Eigen::Index rows = 0;
};
// Writes the text RenderCsv gives for the same columns to `out`, a block at a time (memory is
// independent of the table's size). Throws DataError for columns of different lengths; a write
// error is left on `out` (see io::StreamedFile).
void WriteCsvTo(std::FILE* out, const std::vector<CsvColumnView>& columns);

}  // namespace gyrodrift::io
