#include "cli_util.h"

#include <sys/stat.h>
#include <charconv>
#include <cstdint>
#include <unistd.h>

#include "gyrodrift/common/version.h"

namespace gyrodrift::cli {

const CLI::Validator kInputFile(
    [](std::string& path) -> std::string {
      struct stat st {};
      if (::stat(path.c_str(), &st) != 0) return path + ": no such file";
      if (!S_ISREG(st.st_mode)) return path + ": not a regular file";
      return {};
    },
    "FILE");

const CLI::Validator kSeed(
    [](std::string& text) -> std::string {
      std::uint64_t value = 0;
      const char* end = text.data() + text.size();
      const auto [ptr, ec] = std::from_chars(text.data(), end, value);
      const bool ok = !text.empty() && ec == std::errc() && ptr == end;
      return ok ? std::string() : text + ": must be an integer in [0, 2^64)";
    },
    "SEED");

std::string SidecarPath(const std::string& output_path) { return output_path + ".json"; }

nlohmann::json SidecarHeader(const std::string& command) {
  return {{"tool", "gyrodrift"}, {"version", kVersion}, {"command", command}};
}

bool IsTerminal() { return ::isatty(STDERR_FILENO) != 0; }

}  // namespace gyrodrift::cli
