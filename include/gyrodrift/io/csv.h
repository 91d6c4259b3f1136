// CSV input and output.
//
// Input: a header row, then one row per sample, separated by commas, or by tabs or semicolons
// when the header has no comma (instrument and spreadsheet exports; decimal commas are not read),
// or by the delimiter the caller names.
// Lines starting with '#' and blank lines are skipped; CRLF endings, a UTF-8 byte-order mark and
// quoted header names are accepted. Every cell of a kept column (all of them unless the caller
// names the ones it needs) is parsed as a number up front; a column with a non-numeric cell can
// still be loaded as long as nobody asks for it, and asking for it names the first bad cell.
// A file is read a block at a time, never whole: memory is the kept columns, 8 bytes per row
// each, plus one block (4 MiB by default).
// Output: full double precision (shortest text that reads back to the same double), written to a
// temporary file and renamed, so a file is written completely or not at all.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdio>
#include <iosfwd>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "gyrodrift/io/time_axis.h"

namespace gyrodrift::io {

// The cell delimiter: auto = a comma where the header has one, else a tab, else a semicolon.
enum class Delimiter { kAuto, kComma, kTab, kSemicolon };
std::string_view ToString(Delimiter delimiter);  // "auto", "comma", "tab", "semicolon"
Delimiter DelimiterFromString(std::string_view text);  // OptionError naming the choices

// What to do with a damaged data row: one with another number of cells than the header, or a
// cell of a kept column that is not a finite number. error: refuse the table, naming the line
// (the default, as for any table); skip: leave the row out and list its line (serial-terminal
// captures: a line cut by a reset, two values run together).
enum class BadLines { kError, kSkip };
std::string_view ToString(BadLines bad_lines);         // "error", "skip"
BadLines BadLinesFromString(std::string_view text);    // OptionError naming the choices

// How a table is read.
struct CsvReadOptions {
  Delimiter delimiter = Delimiter::kAuto;
  // The columns to keep, named as Column() takes them (a header name, else a 1-based index);
  // empty = every column. The cells of the others are still counted, so a ragged row is refused
  // as before, but not parsed or stored: a 1e8-row log costs 800 MB per kept column. A name that
  // matches no column is not an error here; Column() refuses it as it refuses any unknown name.
  std::vector<std::string> columns = {};
  // Bytes read at a time; a line that crosses a block is carried to the next. In [1, 2^30],
  // default 4 MiB (the smallest values are for tests of the block boundaries).
  size_t block_bytes = size_t{4} << 20;
  // The file has no header row: these name its columns, in order (empty: the first row is the
  // header). Serial captures print values only.
  std::vector<std::string> names = {};
  // Lines skipped at the start of the file, before the header (or the first data row), in
  // [0, 1e6]: a terminal program's banner. Lines starting with '#' are skipped anyway.
  int skip_rows = 0;
  BadLines bad_lines = BadLines::kError;
  // A column read as a time axis: its cells are parsed and checked as a kept column's (a bad one
  // is refused or skipped alike), but only what a log's checks need of them is kept
  // (CsvTable::time_axis), not the values: 8 bytes a row less. Empty: none. A column also named
  // in `columns`, or not in the header, is read as the other columns are.
  std::string time_axis = {};
  // Throws OptionError naming block_bytes, skip_rows or names (empty or repeated names).
  void Validate() const;
};

class CsvTable {
 public:
  // Reads a file, a block at a time. Throws IoError (missing/unreadable file) or DataError (no
  // header, ragged rows, no data rows; the same messages, with the same line numbers, for every
  // block size and column choice).
  static CsvTable Read(const std::string& path, Delimiter delimiter = Delimiter::kAuto);
  static CsvTable Read(const std::string& path, const CsvReadOptions& options);
  // Reads a stream to its end; `source` names it in messages. The columns are reserved from the
  // stream's size when it can seek (a file, a string).
  static CsvTable Read(std::istream& in, const std::string& source, const CsvReadOptions& options);
  // Parses CSV text (as a file holding it would be read); `source` names it in messages.
  static CsvTable Parse(const std::string& text, const std::string& source,
                        Delimiter delimiter = Delimiter::kAuto);

  const std::vector<std::string>& header() const { return header_; }
  // The file lines (1-based) of the rows BadLines::kSkip left out, in order.
  const std::vector<Eigen::Index>& skipped_lines() const { return skipped_lines_; }
  // The column read as CsvReadOptions::time_axis, or nullptr when none was (the column is then
  // not kept: ColumnRef refuses it).
  const TimeAxis* time_axis() const { return time_axis_index_ >= 0 ? &time_axis_ : nullptr; }
  Eigen::Index rows() const { return rows_; }
  const std::string& source() const { return source_; }

  // Column index for a header name or a 1-based index ("3"). Throws UsageError naming the
  // available columns.
  int ResolveColumn(const std::string& spec) const;
  // Whether the header names the column (kept or not).
  bool HasColumn(const std::string& name) const;
  // Whether the reader kept the column's values (CsvReadOptions::columns).
  bool IsKept(int index) const;
  // The column's values. Throws DataError naming the row of the first non-numeric, NaN or
  // infinite cell, UsageError for a column the reader did not keep.
  Eigen::VectorXd Column(const std::string& spec) const;
  Eigen::VectorXd Column(int index) const;
  // The same values without a copy (the table's own; valid while the table lives): what a
  // caller that only reads a long column uses.
  const Eigen::VectorXd& ColumnRef(const std::string& spec) const;
  const Eigen::VectorXd& ColumnRef(int index) const;
  // Moves the values out of the table (checked as Column, no copy); the column then counts as not
  // kept. For a caller that needs one long column and not the rest of the table.
  Eigen::VectorXd TakeColumn(const std::string& spec);

  // A copy with rows inserted by linear interpolation: for each (row, count), `count` rows evenly
  // spaced between data rows `row` and `row + 1` (0-based), in every kept column. Messages about
  // a bad cell keep naming its row in the file. The copy has no time axis (its steps changed).
  CsvTable WithInterpolatedRows(const std::vector<std::pair<Eigen::Index, int>>& insert) const;

 private:
  class Parser;  // the line parser every reading function feeds (csv.cc)
  struct BadCell {
    Eigen::Index row = -1;  // 1-based data row; -1 if the column is clean
    std::string text;
  };
  std::string source_;
  std::vector<std::string> header_;
  // One per header column; a column that was not kept is empty. Eigen vectors rather than
  // std::vector: they are handed out without a copy (ColumnRef), and they grow by realloc, which
  // moves the pages of a large block instead of copying them (no second copy while a column grows).
  std::vector<Eigen::VectorXd> columns_;
  std::vector<bool> kept_;
  std::vector<BadCell> first_bad_;
  std::vector<Eigen::Index> skipped_lines_;
  TimeAxis time_axis_;
  int time_axis_index_ = -1;  // the header column read as time_axis_, -1 for none
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
