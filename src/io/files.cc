#include "gyrodrift/io/files.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "gyrodrift/common/error.h"

namespace gyrodrift::io {

std::string ReadTextFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path + ": cannot open for reading (" + std::strerror(errno) + ")");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw IoError(path + ": read failed");
  return buffer.str();
}

void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<std::string> temps;
  auto remove_temps = [&] {
    for (const auto& t : temps) std::remove(t.c_str());
  };
  for (const auto& [path, contents] : files) {
    const std::string temp = path + ".tmp." + std::to_string(::getpid());
    std::FILE* f = std::fopen(temp.c_str(), "wb");
    if (!f) {
      const std::string reason = std::strerror(errno);
      remove_temps();
      throw IoError(path + ": cannot open for writing (" + reason + ")");
    }
    temps.push_back(temp);
    const bool ok = std::fwrite(contents.data(), 1, contents.size(), f) == contents.size();
    if (std::fclose(f) != 0 || !ok) {
      remove_temps();
      throw IoError(path + ": write failed (disk full?)");
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), files[i].first.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      remove_temps();
      throw IoError(files[i].first + ": cannot rename the temporary file into place (" + reason +
                    ")");
    }
  }
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFilesAtomically({{path, contents}});
}

}  // namespace gyrodrift::io
