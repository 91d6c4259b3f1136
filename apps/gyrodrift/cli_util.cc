#include "cli_util.h"

#include <sys/stat.h>
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

std::string SidecarPath(const std::string& output_path) { return output_path + ".json"; }

nlohmann::json SidecarHeader(const std::string& command) {
  return {{"tool", "gyrodrift"}, {"version", kVersion}, {"command", command}};
}

bool IsTerminal() { return ::isatty(STDERR_FILENO) != 0; }

}  // namespace gyrodrift::cli
