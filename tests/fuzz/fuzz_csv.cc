// libFuzzer harness: the CSV reader on any bytes, with the delimiter detected and with one named
// (chosen by the input's length). Every input either parses or throws a gyrodrift::Error; a
// parsed table's columns either load or throw one. Anything else (a crash, a
// sanitizer finding, another exception) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  using gyrodrift::io::Delimiter;
  const Delimiter named[] = {Delimiter::kComma, Delimiter::kTab, Delimiter::kSemicolon};
  for (const Delimiter delimiter : {Delimiter::kAuto, named[size % 3]}) {
    try {
      const gyrodrift::io::CsvTable table =
          gyrodrift::io::CsvTable::Parse(text, "fuzz.csv", delimiter);
      for (int c = 0; c < static_cast<int>(table.header().size()); ++c) {
        try {
          (void)table.Column(c);
        } catch (const gyrodrift::Error&) {
        }
      }
      try {
        (void)table.Column("time_s");
      } catch (const gyrodrift::Error&) {
      }
    } catch (const gyrodrift::Error&) {
    }
  }
  return 0;
}
