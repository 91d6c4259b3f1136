#include "gyrodrift/io/csv.h"

#include <fmt/core.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <istream>
#include <limits>
#include <string_view>

#include "common/enum_names.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::io {
namespace {

// A cell as a message may quote it: control bytes as \xNN (a NUL would end the message), at most
// 40 bytes of it, cut before a UTF-8 continuation byte (half a character is not UTF-8, which the
// Python package's strings must be).
std::string Printable(std::string_view cell) {
  constexpr size_t kLongest = 40;
  size_t end = std::min(cell.size(), kLongest);
  while (end > 0 && end < cell.size() && (static_cast<unsigned char>(cell[end]) & 0xC0) == 0x80) {
    --end;
  }
  std::string out;
  for (size_t i = 0; i < end; ++i) {
    const auto byte = static_cast<unsigned char>(cell[i]);
    if (byte < 0x20 || byte == 0x7F) {
      out += fmt::format("\\x{:02X}", byte);
    } else {
      out += cell[i];
    }
  }
  if (end < cell.size()) out += "... (" + std::to_string(cell.size()) + " bytes)";
  return out;
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string_view Unquote(std::string_view s) {
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') return s.substr(1, s.size() - 2);
  return s;
}

// The delimiter of a file, from its header line: a comma where there is one, else a tab, else a
// semicolon (what instrument and spreadsheet exports write), else a comma (one column).
char DetectDelimiter(std::string_view header) {
  for (char d : {',', '\t', ';'}) {
    if (header.find(d) != std::string_view::npos) return d;
  }
  return ',';
}

// Splits one line at the delimiter (no quoted delimiters: numeric files do not need them).
void SplitLine(std::string_view line, char delimiter, std::vector<std::string_view>& cells) {
  cells.clear();
  size_t start = 0;
  for (;;) {
    const size_t comma = line.find(delimiter, start);
    if (comma == std::string_view::npos) {
      cells.push_back(Trim(line.substr(start)));
      return;
    }
    cells.push_back(Trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

bool ParseDouble(std::string_view cell, double& value) {
  cell = Unquote(cell);
  if (cell.empty()) return false;
  if (cell.front() == '+') cell.remove_prefix(1);
  auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return ec == std::errc() && end == cell.data() + cell.size();
}

bool IsSkippable(std::string_view line) {
  const std::string_view t = Trim(line);
  return t.empty() || t.front() == '#';
}

// Index of the column a spec names: a header name, else a 1-based index; -1 for none.
int FindColumn(const std::vector<std::string>& header, const std::string& spec) {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == spec) return static_cast<int>(i);
  }
  int index = 0;
  auto [end, ec] = std::from_chars(spec.data(), spec.data() + spec.size(), index);
  if (ec == std::errc() && end == spec.data() + spec.size() && index >= 1 &&
      index <= static_cast<int>(header.size())) {
    return index - 1;
  }
  return -1;
}

constexpr gyrodrift::internal::EnumNames<Delimiter, 4> kDelimiters{{
    {Delimiter::kAuto, "auto"},
    {Delimiter::kComma, "comma"},
    {Delimiter::kTab, "tab"},
    {Delimiter::kSemicolon, "semicolon"},
}};

}  // namespace

std::string_view ToString(Delimiter delimiter) {
  return gyrodrift::internal::EnumName(delimiter, kDelimiters);
}

Delimiter DelimiterFromString(std::string_view text) {
  return gyrodrift::internal::EnumFromName(text, "delimiter", kDelimiters);
}

void CsvReadOptions::Validate() const {
  if (block_bytes < 1 || block_bytes > (size_t{1} << 30)) {
    throw OptionError("block_bytes", std::to_string(block_bytes), "an integer in [1, 1073741824]");
  }
  if (skip_rows < 0 || skip_rows > 1000000) {
    throw OptionError("skip_rows", std::to_string(skip_rows), "an integer in [0, 1000000]");
  }
  for (size_t i = 0; i < names.size(); ++i) {
    if (names[i].empty() || std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(i),
                                      names[i]) != names.begin() + static_cast<std::ptrdiff_t>(i)) {
      throw OptionError("names", "'" + names[i] + "'", "non-empty column names, each once");
    }
  }
}

namespace {
constexpr gyrodrift::internal::EnumNames<BadLines, 2> kBadLines{
    {{BadLines::kError, "error"}, {BadLines::kSkip, "skip"}}};
}  // namespace

std::string_view ToString(BadLines bad_lines) {
  return gyrodrift::internal::EnumName(bad_lines, kBadLines);
}

BadLines BadLinesFromString(std::string_view text) {
  return gyrodrift::internal::EnumFromName(text, "bad_lines", kBadLines);
}

// Lines in, a table out. The text comes in blocks of any size (a whole string is one block); a
// line cut by a block's end is carried to the next, so the table, and every message with its line
// number, is the same for every block size.
class CsvTable::Parser {
 public:
  // `size_hint`: the bytes to come (0 = unknown), to reserve the kept columns.
  Parser(const std::string& source, const CsvReadOptions& options, std::uint64_t size_hint)
      : given_(options.delimiter),
        specs_(options.columns),
        time_axis_spec_(options.time_axis),
        names_(options.names),
        skip_rows_(options.skip_rows),
        skip_bad_(options.bad_lines == BadLines::kSkip),
        size_hint_(size_hint) {
    table_.source_ = source;
  }

  void Feed(std::string_view block) {
    if (started_) {
      Scan(block);
    } else if (head_.empty() && block.size() >= 3) {
      started_ = true;
      Scan(WithoutBom(block));
    } else {
      // The byte-order mark is told from the first three bytes, wherever the blocks end.
      head_.append(block);
      if (head_.size() >= 3) Start();
    }
  }

  CsvTable Finish() {
    if (!started_) Start();
    // The whole file one line with CRs inside: lines that end in CR alone (classic Mac text).
    const size_t cr = carry_.find('\r');
    if (!have_header_ && cr != std::string::npos && cr + 1 < carry_.size()) {
      throw DataError(table_.source_ +
                      ": lines end in CR alone (classic Mac text): save it with LF or CRLF line "
                      "endings");
    }
    if (!carry_.empty()) Line(carry_);  // the last line has no newline
    if (!have_header_ && skip_rows_ > 0 && line_number_ > 0 && line_number_ <= skip_rows_) {
      throw DataError(
          fmt::format("{}: skipping its first {} line{} leaves nothing to read (the "
                      "file has {} line{})",
                      table_.source_, skip_rows_, skip_rows_ == 1 ? "" : "s", line_number_,
                      line_number_ == 1 ? "" : "s"));
    }
    if (!have_header_) throw DataError(table_.source_ + ": empty file (no header row)");
    if (table_.rows_ == 0 && !table_.skipped_lines_.empty()) {
      throw DataError(table_.source_ + ": every data row is bad (" +
                      std::to_string(table_.skipped_lines_.size()) +
                      " skipped as bad lines, the first at line " +
                      std::to_string(table_.skipped_lines_.front()) + ")");
    }
    if (table_.rows_ == 0) throw DataError(table_.source_ + ": header but no data rows");
    for (size_t c = 0; c < table_.columns_.size(); ++c) {
      // Gives back the reserve beyond the last row (realloc shrinks a large block in place).
      if (table_.kept_[c]) table_.columns_[c].conservativeResize(table_.rows_);
    }
    return std::move(table_);
  }

 private:
  // The text after a UTF-8 byte-order mark; UTF-16 (told by its mark) is refused by name.
  std::string_view WithoutBom(std::string_view text) const {
    if (text.substr(0, 2) == "\xFF\xFE" || text.substr(0, 2) == "\xFE\xFF") {
      throw DataError(table_.source_ + ": UTF-16 text (its byte-order mark): save it as UTF-8");
    }
    if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
    return text;
  }

  void Start() {
    started_ = true;
    const std::string head = std::move(head_);
    Scan(WithoutBom(head));
  }

  // Parses the complete lines of `block`; the bytes after its last newline wait in carry_.
  void Scan(std::string_view block) {
    size_t eol = block.find('\n');
    if (eol == std::string_view::npos) {
      carry_.append(block);
      return;
    }
    if (!carry_.empty()) {
      carry_.append(block.substr(0, eol));
      Line(carry_);
      carry_.clear();
    } else {
      Line(block.substr(0, eol));
    }
    for (;;) {
      block.remove_prefix(eol + 1);
      eol = block.find('\n');
      if (eol == std::string_view::npos) break;
      Line(block.substr(0, eol));
    }
    carry_.assign(block);
  }

  void Line(std::string_view line) {
    ++line_number_;
    parsed_bytes_ += line.size() + 1;
    if (line_number_ <= skip_rows_ || IsSkippable(line)) return;
    if (!have_header_) {
      Header(line);
      if (names_.empty()) return;  // else the line is the first data row
    }
    CsvTable& t = table_;
    SplitLine(line, delimiter_, cells_);
    if (cells_.size() != t.header_.size()) {
      if (skip_bad_) {
        t.skipped_lines_.push_back(line_number_);
        return;
      }
      throw DataError(t.source_ + ": line " + std::to_string(line_number_) + " has " +
                      std::to_string(cells_.size()) + " cells, the header has " +
                      std::to_string(t.header_.size()) +
                      (names_.empty() ? "" : " (the names given)"));
    }
    if (skip_bad_) {
      for (const size_t c : kept_) {
        if (!IsFinite(cells_[c])) {
          t.skipped_lines_.push_back(line_number_);
          return;
        }
      }
      if (t.time_axis_index_ >= 0 && !IsFinite(cells_[AxisColumn()])) {
        t.skipped_lines_.push_back(line_number_);
        return;
      }
    }
    if (t.rows_ == capacity_) Reserve();
    const Eigen::Index row = t.rows_++;
    for (const size_t c : kept_) t.columns_[c][row] = Value(c);
    if (t.time_axis_index_ >= 0) t.time_axis_.Add(Value(AxisColumn()));
  }

  static bool IsFinite(std::string_view cell) {
    double value;
    return ParseDouble(cell, value) && std::isfinite(value);
  }

  size_t AxisColumn() const { return static_cast<size_t>(table_.time_axis_index_); }

  // Cell c of the current row, recorded as the column's first bad cell when it is one (NaN when
  // it is not a number).
  double Value(size_t c) {
    CsvTable& t = table_;
    double value;
    if (!ParseDouble(cells_[c], value)) {
      value = std::numeric_limits<double>::quiet_NaN();
      if (t.first_bad_[c].row < 0) t.first_bad_[c] = {t.rows_, std::string(cells_[c])};
    } else if (!std::isfinite(value) && t.first_bad_[c].row < 0) {
      t.first_bad_[c] = {t.rows_, std::string(cells_[c])};
    }
    return value;
  }

  void Header(std::string_view line) {
    CsvTable& t = table_;
    if (names_.empty() && line.find('\0') != std::string_view::npos) {  // a header read
      throw DataError(t.source_ + ": line " + std::to_string(line_number_) +
                      " (the header) holds a NUL byte: not a text file");
    }
    delimiter_ = given_ == Delimiter::kComma       ? ','
                 : given_ == Delimiter::kTab       ? '\t'
                 : given_ == Delimiter::kSemicolon ? ';'
                                                   : DetectDelimiter(line);
    SplitLine(line, delimiter_, cells_);
    if (names_.empty()) {
      for (auto cell : cells_) t.header_.emplace_back(Unquote(cell));
    } else {
      t.header_ = names_;
    }
    for (size_t i = 0; i < t.header_.size(); ++i) {
      if (t.header_[i].empty()) {
        throw DataError(t.source_ + ": header column " + std::to_string(i + 1) + " has no name");
      }
      for (size_t j = 0; j < i; ++j) {
        // A column is chosen by name: two of one name would make the choice silent guesswork.
        if (t.header_[j] == t.header_[i]) {
          throw DataError(t.source_ + ": header names column '" + t.header_[i] + "' twice (" +
                          std::to_string(j + 1) + " and " + std::to_string(i + 1) + ")");
        }
      }
    }
    t.columns_.resize(t.header_.size());
    t.first_bad_.resize(t.header_.size());
    t.kept_.assign(t.header_.size(), specs_.empty());
    for (const auto& spec : specs_) {
      const int c = FindColumn(t.header_, spec);
      if (c >= 0) t.kept_[static_cast<size_t>(c)] = true;
    }
    for (size_t c = 0; c < t.header_.size(); ++c) {
      if (t.kept_[c]) kept_.push_back(c);
    }
    if (!time_axis_spec_.empty()) {
      const int c = FindColumn(t.header_, time_axis_spec_);
      if (c >= 0 && !t.kept_[static_cast<size_t>(c)]) t.time_axis_index_ = c;
    }
    have_header_ = true;
  }

  // Room for more rows in every kept column. From the bytes per row so far and the bytes still to
  // come (10 % over, for rows that get longer), else half as many again. Untouched reserve costs
  // address space, not memory, and is given back by Finish.
  void Reserve() {
    const Eigen::Index rows = table_.rows_;
    Eigen::Index next = std::max<Eigen::Index>(1024, capacity_ + capacity_ / 2);
    if (rows >= 1024 && size_hint_ > parsed_bytes_) {
      const double bytes_per_row = static_cast<double>(parsed_bytes_) / static_cast<double>(rows);
      const double to_come = static_cast<double>(size_hint_ - parsed_bytes_) / bytes_per_row;
      next = std::max(capacity_ + 1024, rows + static_cast<Eigen::Index>(1.1 * to_come) + 1024);
    }
    for (const size_t c : kept_) table_.columns_[c].conservativeResize(next);
    capacity_ = next;
  }

  const Delimiter given_;
  const std::vector<std::string> specs_;
  const std::string time_axis_spec_;
  const std::vector<std::string> names_;  // the header, when the file has none
  const Eigen::Index skip_rows_;
  const bool skip_bad_;
  const std::uint64_t size_hint_;
  CsvTable table_;
  bool started_ = false;
  std::string head_;   // the first bytes, until the byte-order mark can be told
  std::string carry_;  // a line cut by the end of a block
  bool have_header_ = false;
  char delimiter_ = ',';
  Eigen::Index line_number_ = 0;
  std::uint64_t parsed_bytes_ = 0;
  Eigen::Index capacity_ = 0;
  std::vector<size_t> kept_;  // indices of the kept columns
  std::vector<std::string_view> cells_;
};

CsvTable CsvTable::Read(const std::string& path, Delimiter delimiter) {
  return Read(path, CsvReadOptions{.delimiter = delimiter});
}

CsvTable CsvTable::Read(const std::string& path, const CsvReadOptions& options) {
  options.Validate();
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path + ": cannot open for reading (" + std::strerror(errno) + ")");
  }
  return Read(in, path, options);
}

CsvTable CsvTable::Read(std::istream& in, const std::string& source,
                        const CsvReadOptions& options) {
  options.Validate();
  std::uint64_t size_hint = 0;
  const std::istream::pos_type start = in.tellg();
  if (start != std::istream::pos_type(-1) && in.seekg(0, std::ios::end)) {
    const std::istream::pos_type end = in.tellg();
    if (end != std::istream::pos_type(-1) && end > start) {
      size_hint = static_cast<std::uint64_t>(end - start);
    }
    in.seekg(start);
  }
  in.clear();
  Parser parser(source, options, size_hint);
  std::string block(options.block_bytes, '\0');
  while (in) {
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    const std::streamsize got = in.gcount();
    if (got > 0) parser.Feed(std::string_view(block.data(), static_cast<size_t>(got)));
  }
  if (in.bad()) throw IoError(source + ": read failed");
  return parser.Finish();
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& source, Delimiter delimiter) {
  Parser parser(source, CsvReadOptions{.delimiter = delimiter}, text.size());
  parser.Feed(text);
  return parser.Finish();
}

bool CsvTable::HasColumn(const std::string& name) const {
  for (const auto& h : header_) {
    if (h == name) return true;
  }
  return false;
}

int CsvTable::ResolveColumn(const std::string& spec) const {
  const int index = FindColumn(header_, spec);
  if (index >= 0) return index;
  std::string names;
  for (const auto& h : header_) names += (names.empty() ? "" : ", ") + h;
  throw UsageError("column '" + spec + "' not found in " + source_ + " (columns: " + names +
                   "; or a 1-based index up to " + std::to_string(header_.size()) + ")");
}

bool CsvTable::IsKept(int index) const { return kept_.at(static_cast<size_t>(index)); }

Eigen::VectorXd CsvTable::Column(const std::string& spec) const { return ColumnRef(spec); }

Eigen::VectorXd CsvTable::Column(int index) const { return ColumnRef(index); }

const Eigen::VectorXd& CsvTable::ColumnRef(const std::string& spec) const {
  return ColumnRef(ResolveColumn(spec));
}

const Eigen::VectorXd& CsvTable::ColumnRef(int index) const {
  const size_t c = static_cast<size_t>(index);
  if (!kept_.at(c)) {
    throw UsageError(source_ + ": column '" + header_[c] +
                     "' was not kept by the reader (CsvReadOptions::columns)");
  }
  const auto& bad = first_bad_[c];
  if (bad.row >= 0) {
    throw DataError(source_ + ": column '" + header_[c] + "' data row " + std::to_string(bad.row) +
                    " is '" + Printable(bad.text) + "': every value must be a finite number");
  }
  return columns_[c];
}

Eigen::VectorXd CsvTable::TakeColumn(const std::string& spec) {
  const int index = ResolveColumn(spec);
  (void)ColumnRef(index);  // the checks
  const size_t c = static_cast<size_t>(index);
  Eigen::VectorXd values = std::move(columns_[c]);
  columns_[c] = Eigen::VectorXd();
  kept_[c] = false;
  return values;
}

CsvTable CsvTable::WithInterpolatedRows(
    const std::vector<std::pair<Eigen::Index, int>>& insert) const {
  CsvTable out;
  out.source_ = source_;
  out.header_ = header_;
  out.kept_ = kept_;
  out.first_bad_ = first_bad_;
  out.skipped_lines_ = skipped_lines_;
  out.columns_.resize(columns_.size());
  // The rows the loop below adds: it takes the insertions in order, each at a row after the
  // previous one and before the last row (an insertion out of order stops it).
  Eigen::Index added = 0;
  Eigen::Index previous = -1;
  for (const auto& [row, count] : insert) {
    if (row <= previous || row + 1 >= rows_) break;
    added += std::max(count, 0);
    previous = row;
  }
  out.rows_ = rows_ + added;
  for (size_t c = 0; c < columns_.size(); ++c) {
    if (!kept_[c]) continue;
    const Eigen::VectorXd& in = columns_[c];
    Eigen::VectorXd& v = out.columns_[c];
    v.resize(out.rows_);
    Eigen::Index k = 0;
    size_t next = 0;
    for (Eigen::Index r = 0; r < rows_; ++r) {
      v[k++] = in[r];
      if (next < insert.size() && insert[next].first == r && r + 1 < rows_) {
        const int m = insert[next].second;
        for (int j = 1; j <= m; ++j) {
          const double f = static_cast<double>(j) / static_cast<double>(m + 1);
          v[k++] = in[r] + f * (in[r + 1] - in[r]);
        }
        ++next;
      }
    }
  }
  return out;
}

std::string FormatDouble(double value) {
  char buffer[64];
  auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, end);
}

std::string RenderCsv(const std::vector<CsvColumn>& columns) {
  std::string out;
  if (columns.empty()) return out;
  const Eigen::Index rows = columns.front().values.size();
  for (size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].values.size() != rows) {
      throw DataError("CSV column '" + columns[c].name + "' has " +
                      std::to_string(columns[c].values.size()) + " rows, expected " +
                      std::to_string(rows));
    }
    out += (c ? "," : "") + columns[c].name;
  }
  out += '\n';
  out.reserve(out.size() + static_cast<size_t>(rows * static_cast<Eigen::Index>(columns.size()) * 24));
  char buffer[64];
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) out += ',';
      auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), columns[c].values[r]);
      out.append(buffer, end);
    }
    out += '\n';
  }
  return out;
}

void WriteCsvTo(std::FILE* out, const std::vector<CsvColumnView>& columns) {
  if (columns.empty()) return;
  const Eigen::Index rows = columns.front().rows;
  std::string block;
  for (size_t c = 0; c < columns.size(); ++c) {
    if (columns[c].rows != rows) {
      throw DataError("CSV column '" + columns[c].name + "' has " +
                      std::to_string(columns[c].rows) + " rows, expected " +
                      std::to_string(rows));
    }
    block += (c ? "," : "") + columns[c].name;
  }
  block += '\n';
  // Flushed at about 1 MiB: few fwrite calls, and the memory stays that of one block.
  constexpr size_t kBlockBytes = size_t{1} << 20;
  block.reserve(kBlockBytes + 64 * columns.size());
  char buffer[64];
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (size_t c = 0; c < columns.size(); ++c) {
      if (c) block += ',';
      auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), columns[c].values[r]);
      block.append(buffer, end);
    }
    block += '\n';
    if (block.size() >= kBlockBytes) {
      if (std::fwrite(block.data(), 1, block.size(), out) != block.size()) return;
      block.clear();
    }
  }
  std::fwrite(block.data(), 1, block.size(), out);
}

void WriteCsv(const std::string& path, const std::vector<CsvColumn>& columns) {
  WriteFileAtomically(path, RenderCsv(columns));
}

}  // namespace gyrodrift::io
