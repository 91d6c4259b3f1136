#include "gyrodrift/study/table.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "gyrodrift/io/csv.h"

namespace gyrodrift::study {

std::string RoundedText(double value, int digits) {
  if (std::isnan(value)) return "-";
  return fmt::format("{:.{}g}", value, digits);
}

void Table::Add(const std::vector<Cell>& cells) {
  // A caller's bug, not the user's: a row of another width would be drawn past its columns.
  if (cells.size() != header.size()) {
    throw std::logic_error("table '" + title + "': a row of " + std::to_string(cells.size()) +
                           " cells under a header of " + std::to_string(header.size()));
  }
  std::vector<std::string> c, s;
  for (const auto& cell : cells) {
    c.push_back(cell.numeric ? io::FormatDouble(cell.value) : cell.text);
    s.push_back(cell.numeric ? RoundedText(cell.value, cell.digits) : cell.text);
  }
  csv.push_back(std::move(c));
  shown.push_back(std::move(s));
}

std::string Table::Csv() const {
  std::string out;
  for (size_t i = 0; i < header.size(); ++i) out += (i ? "," : "") + header[i];
  out += '\n';
  for (const auto& row : csv) {
    for (size_t i = 0; i < row.size(); ++i) out += (i ? "," : "") + row[i];
    out += '\n';
  }
  return out;
}

std::string Table::Text() const {
  std::vector<size_t> width(header.size());
  for (size_t i = 0; i < header.size(); ++i) width[i] = header[i].size();
  for (const auto& row : shown) {
    for (size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string out = " ";
    for (size_t i = 0; i < cells.size(); ++i) {
      out += i < 2 ? fmt::format(" {:<{}}", cells[i], width[i])
                   : fmt::format(" {:>{}}", cells[i], width[i]);
    }
    return out + "\n";
  };
  std::string out = title + "\n" + line(header);
  for (const auto& row : shown) out += line(row);
  return out;
}

html::ReportTable Table::Report() const { return {title, caption, header, shown, {}}; }

}  // namespace gyrodrift::study
