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
  // Each target is replaced by one atomic rename, so a reader sees the old file or the new one,
  // never none. For a set, existing targets are first hard-linked (or copied) to backups, so that
  // a failed later rename can rename every earlier backup back over its new file.
  const bool set = files.size() > 1;
  std::vector<std::string> backups(files.size());
  auto remove_backups = [&] {
    for (const auto& b : backups) {
      if (!b.empty()) std::remove(b.c_str());
    }
  };
  if (set) {
    for (size_t i = 0; i < files.size(); ++i) {
      const std::string& target = files[i].first;
      std::error_code ec;
      if (!fs::exists(fs::symlink_status(target, ec))) continue;
      const std::string backup = target + ".bak" + suffix;
      if (::link(target.c_str(), backup.c_str()) != 0) {
        fs::copy_file(target, backup, fs::copy_options::overwrite_existing, ec);
        if (ec) {
          remove_backups();
          remove_temps();
          throw IoError(target + ": cannot keep a copy of the existing file (" + ec.message() +
                        ")");
        }
      }
      backups[i] = backup;
    }
  }
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string& target = files[i].first;
    if (std::rename(temps[i].c_str(), target.c_str()) == 0) continue;
    const std::string reason = std::strerror(errno);
    std::string restore_failed;
    for (size_t j = 0; j < i; ++j) {
      const std::string& placed = files[j].first;
      const bool ok = backups[j].empty() ? std::remove(placed.c_str()) == 0
                                         : std::rename(backups[j].c_str(), placed.c_str()) == 0;
      if (!ok) restore_failed += (restore_failed.empty() ? "" : ", ") + placed;
    }
    remove_backups();
    remove_temps();
    throw IoError(target + ": cannot rename the temporary file into place (" + reason + ")" +
                  (restore_failed.empty()
                       ? ""
                       : "; could not restore the earlier state of " + restore_failed));
  }
  remove_backups();
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFilesAtomically({{path, contents}});
}

}  // namespace gyrodrift::io
