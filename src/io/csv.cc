#include "gyrodrift/io/csv.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::io {
namespace {

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

}  // namespace

std::string_view ToString(Delimiter delimiter) {
  switch (delimiter) {
    case Delimiter::kComma: return "comma";
    case Delimiter::kTab: return "tab";
    case Delimiter::kSemicolon: return "semicolon";
    case Delimiter::kAuto: break;
  }
  return "auto";
}

Delimiter DelimiterFromString(std::string_view text) {
  for (Delimiter d : {Delimiter::kAuto, Delimiter::kComma, Delimiter::kTab, Delimiter::kSemicolon}) {
    if (text == ToString(d)) return d;
  }
  throw OptionError("delimiter", "'" + std::string(text) + "'", "auto, comma, tab or semicolon");
}

CsvTable CsvTable::Read(const std::string& path, Delimiter delimiter) {
  return Parse(ReadTextFile(path), path, delimiter);
}

CsvTable CsvTable::Parse(const std::string& text, const std::string& source,
                         Delimiter given) {
  CsvTable table;
  table.source_ = source;
  std::string_view rest(text);
  if (rest.size() >= 3 && rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // BOM
  std::vector<std::string_view> cells;
  bool have_header = false;
  char delimiter = ',';
  Eigen::Index line_number = 0;
  while (!rest.empty()) {
    const size_t eol = rest.find('\n');
    const std::string_view line = rest.substr(0, eol);
    rest = eol == std::string_view::npos ? std::string_view() : rest.substr(eol + 1);
    ++line_number;
    if (IsSkippable(line)) continue;
    if (!have_header) {
      delimiter = given == Delimiter::kComma       ? ','
                  : given == Delimiter::kTab       ? '\t'
                  : given == Delimiter::kSemicolon ? ';'
                                                   : DetectDelimiter(line);
    }
    SplitLine(line, delimiter, cells);
    if (!have_header) {
      for (auto cell : cells) table.header_.emplace_back(Unquote(cell));
      for (size_t i = 0; i < table.header_.size(); ++i) {
        if (table.header_[i].empty()) {
          throw DataError(source + ": header column " + std::to_string(i + 1) + " has no name");
        }
        for (size_t j = 0; j < i; ++j) {
          // A column is chosen by name: two of one name would make the choice silent guesswork.
          if (table.header_[j] == table.header_[i]) {
            throw DataError(source + ": header names column '" + table.header_[i] + "' twice (" +
                            std::to_string(j + 1) + " and " + std::to_string(i + 1) + ")");
          }
        }
      }
      table.columns_.resize(table.header_.size());
      table.first_bad_.resize(table.header_.size());
      have_header = true;
      continue;
    }
    if (cells.size() != table.header_.size()) {
      throw DataError(source + ": line " + std::to_string(line_number) + " has " +
                      std::to_string(cells.size()) + " cells, the header has " +
                      std::to_string(table.header_.size()));
    }
    ++table.rows_;
    for (size_t c = 0; c < cells.size(); ++c) {
      double value;
      if (!ParseDouble(cells[c], value)) {
        value = std::numeric_limits<double>::quiet_NaN();
        if (table.first_bad_[c].row < 0) table.first_bad_[c] = {table.rows_, std::string(cells[c])};
      } else if (!std::isfinite(value) && table.first_bad_[c].row < 0) {
        table.first_bad_[c] = {table.rows_, std::string(cells[c])};
      }
      table.columns_[c].push_back(value);
    }
  }
  if (!have_header) throw DataError(source + ": empty file (no header row)");
  if (table.rows_ == 0) throw DataError(source + ": header but no data rows");
  return table;
}

bool CsvTable::HasColumn(const std::string& name) const {
  for (const auto& h : header_) {
    if (h == name) return true;
  }
  return false;
}

int CsvTable::ResolveColumn(const std::string& spec) const {
  for (size_t i = 0; i < header_.size(); ++i) {
    if (header_[i] == spec) return static_cast<int>(i);
  }
  int index = 0;
  auto [end, ec] = std::from_chars(spec.data(), spec.data() + spec.size(), index);
  if (ec == std::errc() && end == spec.data() + spec.size() && index >= 1 &&
      index <= static_cast<int>(header_.size())) {
    return index - 1;
  }
  std::string names;
  for (const auto& h : header_) names += (names.empty() ? "" : ", ") + h;
  throw UsageError("column '" + spec + "' not found in " + source_ + " (columns: " + names +
                   "; or a 1-based index up to " + std::to_string(header_.size()) + ")");
}

Eigen::VectorXd CsvTable::Column(const std::string& spec) const {
  return Column(ResolveColumn(spec));
}

Eigen::VectorXd CsvTable::Column(int index) const {
  const auto& bad = first_bad_.at(static_cast<size_t>(index));
  if (bad.row >= 0) {
    throw DataError(source_ + ": column '" + header_[static_cast<size_t>(index)] + "' data row " +
                    std::to_string(bad.row) + " is '" + bad.text +
                    "': every value must be a finite number");
  }
  const auto& values = columns_[static_cast<size_t>(index)];
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

CsvTable CsvTable::WithInterpolatedRows(
    const std::vector<std::pair<Eigen::Index, int>>& insert) const {
  CsvTable out = *this;
  size_t added = 0;
  for (const auto& [row, count] : insert) added += static_cast<size_t>(count);
  for (size_t c = 0; c < columns_.size(); ++c) {
    const std::vector<double>& in = columns_[c];
    std::vector<double>& v = out.columns_[c];
    v.clear();
    v.reserve(in.size() + added);
    size_t next = 0;
    for (size_t r = 0; r < in.size(); ++r) {
      v.push_back(in[r]);
      if (next < insert.size() && static_cast<size_t>(insert[next].first) == r && r + 1 < in.size()) {
        const int m = insert[next].second;
        for (int k = 1; k <= m; ++k) {
          const double f = static_cast<double>(k) / static_cast<double>(m + 1);
          v.push_back(in[r] + f * (in[r + 1] - in[r]));
        }
        ++next;
      }
    }
  }
  out.rows_ = static_cast<Eigen::Index>(out.columns_.empty() ? 0 : out.columns_[0].size());
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
