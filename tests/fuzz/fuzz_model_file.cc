// libFuzzer harness: the model-file loader on any bytes. A file either loads or throws a
// gyrodrift::Error naming the problem; a file that loads renders back to a file that loads. The
// checksum would reject almost every mutation before the fields are read, so the harness also
// reseals each input (recomputes its checksum) to reach the field checks.
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/model_file.h"

namespace {

void Load(const std::string& text) {
  try {
    const gyrodrift::io::LoadedModel m = gyrodrift::io::ParseModelFile(text, "fuzz.json");
    const std::string again = gyrodrift::io::RenderModelFile(m.model, m.info);
    (void)gyrodrift::io::ParseModelFile(again, "again.json");
  } catch (const gyrodrift::Error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  Load(text);
  nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_object()) {
    j.erase("checksum");
    const std::string body = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    char hex[17];
    std::snprintf(hex, sizeof(hex), "%016llx",
                  static_cast<unsigned long long>(gyrodrift::io::Fnv1a64(body)));
    j["checksum"] = std::string("fnv1a64:") + hex;
    Load(j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
  }
  return 0;
}
