// libFuzzer harness: the ULog reader on any bytes, every topic decoded. Every input either reads
// or throws a gyrodrift::Error, and a log that reads is whole: every decoded series holds one
// time stamp per sample and one value per sample and field, its fields and types pair up, and
// its first and last time stamps are those of its samples. Anything else (a crash, a sanitizer
// finding, another exception, a broken invariant) is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/ulog.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  gyrodrift::io::Ulog log;
  try {
    log = gyrodrift::io::ParseUlog(std::span<const std::uint8_t>(data, size), {"*"}, "fuzz.ulg");
  } catch (const gyrodrift::Error&) {
    return 0;
  }
  for (const gyrodrift::io::UlogSeries& s : log.series) {
    if (s.fields.size() != s.types.size() || !s.decoded) std::abort();
    if (s.timestamp_us.size() != s.samples || s.values.size() != s.samples * s.fields.size()) {
      std::abort();
    }
    if (s.samples > 0 && s.Field("timestamp") >= 0 &&
        (s.timestamp_us.front() != s.first_us || s.timestamp_us.back() != s.last_us)) {
      std::abort();
    }
  }
  (void)gyrodrift::io::DescribeUlog(log);
  return 0;
}
