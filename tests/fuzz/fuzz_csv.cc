// libFuzzer harness: the CSV reader on any bytes, with the delimiter detected and with one named
// (chosen by the input's length). Every input either parses or throws a gyrodrift::Error; a
// parsed table's columns either load or throw one. The block reader (CsvTable::Read of a stream,
// in blocks of 1 to 13 bytes, so that lines, CRLF pairs and the byte-order mark cross block ends)
// must give what the whole-text parse gives: the same message if it throws, else the same header
// and rows and, for every column it kept (all, or time_s and the second one), the same values to
// the bit or the same message. Anything else (a crash, a sanitizer finding, another exception, a
// difference) is a finding. Read with time_s as a time axis (CsvReadOptions::time_axis), the
// axis must say of a time_s that loads what its values say: rows, finite, increasing, and the
// median, largest and shortest step to the bit.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/statistics.h"
#include "gyrodrift/io/csv.h"

namespace {

using gyrodrift::io::CsvReadOptions;
using gyrodrift::io::CsvTable;
using gyrodrift::io::Delimiter;

// A column's values, or the message that refused it.
struct Loaded {
  std::optional<Eigen::VectorXd> values;
  std::string error;
};

Loaded Load(const CsvTable& table, int c) {
  try {
    return {table.Column(c), ""};
  } catch (const gyrodrift::Error& e) {
    return {std::nullopt, e.what()};
  }
}

void Check(bool ok) {
  if (!ok) std::abort();  // libFuzzer reports the input as a crash
}

void CompareBlockReader(const std::string& text, Delimiter delimiter,
                        const std::optional<CsvTable>& whole, const std::string& whole_error) {
  CsvReadOptions options{.delimiter = delimiter, .block_bytes = 1 + text.size() % 13};
  if (text.size() % 2 == 1) options.columns = {"time_s", "2"};
  std::istringstream in(text);
  std::optional<CsvTable> blocks;
  std::string blocks_error;
  try {
    blocks = CsvTable::Read(in, "fuzz.csv", options);
  } catch (const gyrodrift::Error& e) {
    blocks_error = e.what();
  }
  Check(blocks.has_value() == whole.has_value());
  if (!whole) {
    Check(blocks_error == whole_error);
    return;
  }
  Check(blocks->header() == whole->header() && blocks->rows() == whole->rows());
  for (int c = 0; c < static_cast<int>(whole->header().size()); ++c) {
    if (!blocks->IsKept(c)) continue;
    const Loaded a = Load(*whole, c), b = Load(*blocks, c);
    Check(a.values.has_value() == b.values.has_value() && a.error == b.error);
    if (a.values) {
      Check(a.values->size() == b.values->size() &&
            std::memcmp(a.values->data(), b.values->data(),
                        sizeof(double) * static_cast<size_t>(a.values->size())) == 0);
    }
  }
}

// The time axis gathered while reading against the time_s column the whole-text parse loads.
void CompareTimeAxis(const std::string& text, Delimiter delimiter, const CsvTable& whole) {
  std::optional<Eigen::VectorXd> t;
  try {
    t = whole.Column("time_s");
  } catch (const gyrodrift::Error&) {
    return;
  }
  const CsvReadOptions options{.delimiter = delimiter, .columns = {"2"}, .time_axis = "time_s"};
  std::optional<CsvTable> read;
  try {
    std::istringstream in(text);
    read = CsvTable::Read(in, "fuzz.csv", options);
  } catch (const gyrodrift::Error&) {
    return;  // column "2" may not exist or load
  }
  const gyrodrift::io::TimeAxis* axis = read->time_axis();
  if (!axis) return;  // time_s is column 2, kept as values
  Check(axis->rows() == t->size() && axis->complete() == t->allFinite());
  if (!axis->complete()) return;
  const Eigen::Index n = t->size();
  const Eigen::VectorXd steps =
      n >= 2 ? Eigen::VectorXd(t->tail(n - 1) - t->head(n - 1)) : Eigen::VectorXd();
  Check(axis->increasing() == (n < 2 || steps.minCoeff() > 0.0));
  if (!axis->increasing() || n < 2) return;
  const double median = gyrodrift::MedianStep(*t), largest = axis->LargestStep();
  Check(axis->MedianStep() == median && largest == steps.maxCoeff());
  Eigen::Index first = 0;
  steps.minCoeff(&first);
  Check(axis->Shortest().value == steps.minCoeff() && axis->Shortest().first == first);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const Delimiter named[] = {Delimiter::kComma, Delimiter::kTab, Delimiter::kSemicolon};
  for (const Delimiter delimiter : {Delimiter::kAuto, named[size % 3]}) {
    std::optional<CsvTable> table;
    std::string error;
    try {
      table = CsvTable::Parse(text, "fuzz.csv", delimiter);
      for (int c = 0; c < static_cast<int>(table->header().size()); ++c) {
        try {
          (void)table->Column(c);
        } catch (const gyrodrift::Error&) {
        }
      }
      try {
        (void)table->Column("time_s");
      } catch (const gyrodrift::Error&) {
      }
    } catch (const gyrodrift::Error& e) {
      error = e.what();
    }
    CompareBlockReader(text, delimiter, table, error);
    if (table) CompareTimeAxis(text, delimiter, *table);
  }
  return 0;
}
