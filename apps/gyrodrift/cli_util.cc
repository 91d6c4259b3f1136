#include "cli_util.h"

#include <sys/stat.h>
#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <regex>

#include "gyrodrift/common/check.h"
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

std::string ColumnName(const io::CsvTable& table, const std::string& spec) {
  return table.header()[static_cast<size_t>(table.ResolveColumn(spec))];
}

double ParseDuration(const std::string& text) {
  static const std::regex kPattern(
      R"(^\s*([0-9]+(\.[0-9]*)?|\.[0-9]+)([eE][+-]?[0-9]+)?\s*(s|min|h)?\s*$)");
  std::smatch m;
  if (std::regex_match(text, m, kPattern)) {
    const std::string number = m[1].str() + m[3].str();
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
    const std::string unit = m[4].str();
    const double seconds = unit == "h" ? value * 3600.0 : unit == "min" ? value * 60.0 : value;
    if (ec == std::errc() && seconds > 0.0 && std::isfinite(seconds)) return seconds;
  }
  ThrowOption("--duration", text, "a positive duration such as 30s, 10min, 8h or plain seconds");
}

}  // namespace gyrodrift::cli
