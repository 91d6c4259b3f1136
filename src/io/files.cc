#include "gyrodrift/io/files.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
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
  namespace fs = std::filesystem;
  // Refuse what would fail half-way through the renames: a target named twice, or a directory.
  std::set<fs::path> targets;
  for (const auto& [path, contents] : files) {
    std::error_code ec;
    const fs::path key = fs::weakly_canonical(fs::path(path), ec);
    if (!targets.insert(ec ? fs::path(path) : key).second) {
      throw IoError(path + ": named twice among the files of one output set");
    }
    if (fs::is_directory(fs::path(path), ec)) {
      throw IoError(path + ": is a directory, cannot write a file there");
    }
  }
  const std::string suffix = "." + std::to_string(::getpid());
  std::vector<std::string> temps;
  auto remove_temps = [&] {
    for (const auto& t : temps) std::remove(t.c_str());
  };
  for (const auto& [path, contents] : files) {
    const std::string temp = path + ".tmp" + suffix;
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
  // Existing targets are moved aside first, so a failed rename can put every earlier one back:
  // the set appears complete or the targets are as they were.
  std::vector<std::string> backups(files.size());
  size_t placed = 0;
  auto roll_back = [&] {
    for (size_t j = 0; j < files.size(); ++j) {
      const std::string& target = files[j].first;
      if (j < placed) std::remove(target.c_str());
      if (!backups[j].empty()) std::rename(backups[j].c_str(), target.c_str());
    }
    remove_temps();
  };
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string& target = files[i].first;
    std::error_code ec;
    if (fs::exists(fs::symlink_status(target, ec))) {
      const std::string backup = target + ".bak" + suffix;
      if (std::rename(target.c_str(), backup.c_str()) != 0) {
        const std::string reason = std::strerror(errno);
        roll_back();
        throw IoError(target + ": cannot replace the existing file (" + reason + ")");
      }
      backups[i] = backup;
    }
    if (std::rename(temps[i].c_str(), target.c_str()) != 0) {
      const std::string reason = std::strerror(errno);
      roll_back();
      throw IoError(target + ": cannot rename the temporary file into place (" + reason + ")");
    }
    ++placed;
  }
  for (const auto& b : backups) {
    if (!b.empty()) std::remove(b.c_str());
  }
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFilesAtomically({{path, contents}});
}

}  // namespace gyrodrift::io
