// libFuzzer harness: the calibration manifest parser (fleet/manifest.h) on any text. A manifest
// parses or throws a gyrodrift::Error naming its line; nothing else may happen. The logs it names
// do not exist, so a well-formed manifest ends at the file check: what is fuzzed is TOML, the key
// checks, the types and ranges.
#include <cstddef>
#include <cstdint>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/fleet/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)gyrodrift::fleet::ParseManifest(text, "/nonexistent/fuzz.toml");
  } catch (const gyrodrift::Error&) {
  }
  return 0;
}
