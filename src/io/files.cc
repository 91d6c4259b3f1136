#include "gyrodrift/io/files.h"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>

#include "gyrodrift/common/error.h"

namespace gyrodrift::io {

namespace {

// The temporary is created in the folder of the file written (a link's target's): one that is
// missing or not writable would fail the write after the work.
void RequireWritableFolder(const std::string& path, const std::filesystem::path& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path folder = file.parent_path().empty() ? fs::path(".") : file.parent_path();
  if (!fs::is_directory(folder, ec)) {
    throw IoError(path + ": cannot open for writing (no folder " + folder.string() + ")");
  }
  if (::access(folder.c_str(), W_OK) != 0) {
    throw IoError(path + ": cannot open for writing (" + std::strerror(errno) + ")");
  }
}

// Refuses a target that exists and is not a regular file or a link to one: a device (/dev/null),
// a pipe or a socket would be replaced by the rename that places the file, and a link that leads
// nowhere would be replaced rather than followed. Also refuses one whose folder
// RequireWritableFolder refuses.
void RequireFileTarget(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (ec || !fs::exists(link)) {
    RequireWritableFolder(path, path);
    return;
  }
  const fs::file_status target = fs::status(path, ec);
  if (fs::is_symlink(link) && (ec || !fs::exists(target))) {
    throw IoError(path + ": is a symbolic link to nothing: name the file to write");
  }
  if (fs::is_directory(target)) throw IoError(path + ": is a directory, cannot write a file there");
  if (!fs::is_regular_file(target)) {
    throw IoError(path +
                  ": is not a regular file (a device, a pipe or a socket): gyrodrift writes a "
                  "whole file and renames it into place; name a file");
  }
  const fs::path resolved = fs::canonical(path, ec);  // a link's target's folder
  RequireWritableFolder(path, ec ? fs::path(path) : resolved);
}

// The inputs this process has checked its outputs against: the clean-up of stale temporaries
// never removes one of them, whatever its name.
struct CheckedInputs {
  std::mutex mutex;
  std::vector<std::string> paths;  // guarded by mutex
};

CheckedInputs& Inputs() {
  static CheckedInputs* inputs = new CheckedInputs;  // never destroyed: writers run to the end
  return *inputs;
}

bool IsCheckedInput(const std::filesystem::path& path) {
  const std::lock_guard<std::mutex> lock(Inputs().mutex);
  for (const std::string& in : Inputs().paths) {
    std::error_code ec;
    if (std::filesystem::equivalent(in, path, ec) && !ec) return true;
  }
  return false;
}

}  // namespace

void RequireOutputsAreNotInputs(const std::vector<std::string>& inputs,
                                const std::vector<std::string>& outputs) {
  namespace fs = std::filesystem;
  for (const std::string& out : outputs) {
    if (!out.empty()) RequireFileTarget(out);
  }
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (in.empty() || !fs::exists(in, ec)) continue;
    {
      const std::string path = fs::absolute(in, ec).string();
      const std::lock_guard<std::mutex> lock(Inputs().mutex);
      auto& paths = Inputs().paths;
      if (std::find(paths.begin(), paths.end(), path) == paths.end()) paths.push_back(path);
    }
    for (const std::string& out : outputs) {
      if (out.empty() || !fs::exists(out, ec)) continue;
      if (fs::equivalent(in, out, ec) && !ec) {
        throw UsageError("output " + out + " is the input " + in +
                         ": gyrodrift never overwrites its input (choose another output path)");
      }
    }
  }
}

void RequireDistinctFiles(const std::vector<std::string>& paths, const std::string& what,
                          const std::string& why) {
  namespace fs = std::filesystem;
  for (size_t i = 0; i < paths.size(); ++i) {
    for (size_t j = 0; j < i; ++j) {
      std::error_code ec;
      if (fs::equivalent(paths[j], paths[i], ec) && !ec) {
        throw UsageError(what + " " + paths[j] + " and " + paths[i] + " are one file: " + why);
      }
    }
  }
}

void RequireInputsOutsideFolder(const std::vector<std::string>& inputs, const std::string& folder) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (folder.empty() || !fs::exists(folder, ec)) return;
  const fs::path root = fs::canonical(folder, ec);
  if (ec) return;
  for (const std::string& in : inputs) {
    if (in.empty() || !fs::exists(in, ec)) continue;
    const fs::path file = fs::canonical(in, ec);
    if (ec) continue;
    for (fs::path p = file; !p.empty() && p != p.root_path(); p = p.parent_path()) {
      if (fs::equivalent(p, root, ec) && !ec) {
        throw UsageError("input " + in + " lies inside the output folder " + folder +
                         ": gyrodrift never overwrites its input (choose another folder)");
      }
    }
  }
}

void RequireNotDirectory(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, not a file");
}

std::string ReadTextFile(const std::string& path) {
  RequireNotDirectory(path);  // a directory opens as a stream, then fails to read
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path + ": cannot open for reading (" + std::strerror(errno) + ")");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw IoError(path + ": read failed");
  return buffer.str();
}

namespace {

// The marks of our temporaries and backups: "<target><mark><pid>". Distinct enough that no
// user's file (a dated "x.csv.bak.20261127") is taken for one of ours and removed.
constexpr const char* kTemporaryMark = ".gyrodrift-tmp.";
constexpr const char* kBackupMark = ".gyrodrift-bak.";

// "<name><mark><pid>" -> pid; 0 for anything else.
pid_t TemporaryOwner(const std::string& entry, const std::string& name) {
  for (const char* kind : {kTemporaryMark, kBackupMark}) {
    const std::string prefix = name + kind;
    if (entry.size() <= prefix.size() || entry.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string digits = entry.substr(prefix.size());
    if (digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos) return 0;
    return static_cast<pid_t>(std::stol(digits));
  }
  return 0;
}

// Removes the temporaries and backups of these targets left by writers that were killed (their
// process is gone), so that stale copies do not pile up beside the outputs. A temporary of a
// writer that still runs is left alone; so is anything not of our own naming pattern.
void RemoveStaleTemporaries(const std::vector<std::string>& targets) {
  namespace fs = std::filesystem;
  std::map<fs::path, std::set<std::string>> names_by_folder;
  for (const std::string& target : targets) {
    const fs::path p(target);
    names_by_folder[p.parent_path()].insert(p.filename().string());
  }
  std::vector<fs::path> stale;
  for (const auto& [folder, names] : names_by_folder) {
    std::error_code ec;
    fs::directory_iterator it(folder.empty() ? fs::path(".") : folder, ec), end;
    for (; !ec && it != end; it.increment(ec)) {
      const std::string entry = it->path().filename().string();
      pid_t owner = 0;
      for (const std::string& name : names) {
        if ((owner = TemporaryOwner(entry, name)) > 0) break;
      }
      if (owner <= 0 || owner == ::getpid()) continue;
      if (::kill(owner, 0) == 0 || errno != ESRCH) continue;  // alive, or not ours to judge
      if (IsCheckedInput(it->path())) continue;  // named like ours, but the user's input
      stale.push_back(it->path());
    }
  }
  for (const fs::path& path : stale) {
    std::error_code ignored;
    fs::remove(path, ignored);
  }
}

// The temporaries being written, for RemoveTemporariesForExit. A set is placed (its backups
// made, its renames, its backups removed) under the mutex, so an exit waits for it to be whole.
struct TemporaryRegistry {
  std::mutex mutex;
  std::multiset<std::string> paths;  // guarded by mutex
};

TemporaryRegistry& Registry() {
  static TemporaryRegistry* registry = new TemporaryRegistry;  // never destroyed: exits use it
  return *registry;
}

// A set's temporaries, registered from before each exists until the set is placed or failed.
class RegisteredTemporaries {
 public:
  RegisteredTemporaries() = default;
  RegisteredTemporaries(const RegisteredTemporaries&) = delete;
  RegisteredTemporaries& operator=(const RegisteredTemporaries&) = delete;
  ~RegisteredTemporaries() {
    TemporaryRegistry& r = Registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    for (const std::string& path : paths_) r.paths.erase(r.paths.find(path));
  }
  void Add(const std::string& path) {
    TemporaryRegistry& r = Registry();
    const std::lock_guard<std::mutex> lock(r.mutex);
    r.paths.insert(path);
    paths_.push_back(path);
  }

 private:
  std::vector<std::string> paths_;
};

// Removes each of `paths` that is not empty, ignoring failures (cleaning up after one).
void RemoveAll(const std::vector<std::string>& paths) {
  for (const auto& p : paths) {
    if (!p.empty()) std::remove(p.c_str());
  }
}

// Refuses what would fail half-way through the renames, or replace what is not a file: an
// empty name, a target named twice, a directory, a device, a pipe, a dangling link.
void CheckTargets(const std::vector<StreamedFile>& files) {
  namespace fs = std::filesystem;
  std::set<fs::path> targets;
  for (const auto& [path, write] : files) {
    if (path.empty()) throw IoError("the name of a file to write is empty");
    std::error_code ec;
    const fs::path key = fs::weakly_canonical(fs::path(path), ec);
    if (!targets.insert(ec ? fs::path(path) : key).second) {
      throw IoError(path + ": named twice among the files of one output set");
    }
    RequireFileTarget(path);
  }
}

// Where each file is written: its path, or a link's file where it lies (so the link stays a
// link: the rename would replace it). Messages keep naming the path as given.
std::vector<std::string> Targets(const std::vector<StreamedFile>& files) {
  namespace fs = std::filesystem;
  std::vector<std::string> targets;
  for (const StreamedFile& f : files) {
    std::error_code ec;
    targets.push_back(f.path);
    if (!fs::is_symlink(fs::symlink_status(f.path, ec))) continue;
    const fs::path file = fs::canonical(f.path, ec);
    if (!ec) targets.back() = file.string();
  }
  return targets;
}

// Each file written by its writer to its temporary "<path><kTemporaryMark><suffix>", in order; on a
// failure the temporaries written so far are removed before the error is thrown.
std::vector<std::string> WriteTemporaries(const std::vector<StreamedFile>& files,
                                          const std::vector<std::string>& targets,
                                          const std::string& suffix,
                                          RegisteredTemporaries& registered) {
  std::vector<std::string> temps;
  for (size_t i = 0; i < files.size(); ++i) {
    const auto& [path, write] = files[i];
    const std::string temp = targets[i] + kTemporaryMark + suffix;
    registered.Add(temp);  // before it exists: an exit from here on removes it
    std::FILE* f = std::fopen(temp.c_str(), "wb");
    if (!f) {
      const std::string reason = std::strerror(errno);
      RemoveAll(temps);
      throw IoError(path + ": cannot open for writing (" + reason + ")");
    }
    temps.push_back(temp);
    // A replaced file keeps its permissions (a private 0600 output stays private).
    struct stat existing;
    if (::stat(targets[i].c_str(), &existing) == 0) ::fchmod(::fileno(f), existing.st_mode & 07777);
    try {
      write(f);
    } catch (...) {
      std::fclose(f);
      RemoveAll(temps);
      throw;
    }
    const bool ok = std::ferror(f) == 0;
    if (std::fclose(f) != 0 || !ok) {
      RemoveAll(temps);
      throw IoError(path + ": write failed (disk full?)");
    }
  }
  return temps;
}

// For a set, each existing target hard-linked (or copied) to "<path><kBackupMark><suffix>", so that
// a failed later rename can rename every earlier backup back over its new file; "" where there is
// no target. On a failure the backups and `temps` are removed before the error is thrown.
std::vector<std::string> KeepBackups(const std::vector<StreamedFile>& files,
                                     const std::vector<std::string>& targets,
                                     const std::string& suffix,
                                     const std::vector<std::string>& temps) {
  namespace fs = std::filesystem;
  std::vector<std::string> backups(files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string& target = targets[i];
    std::error_code ec;
    if (!fs::exists(fs::symlink_status(target, ec))) continue;
    const std::string backup = target + kBackupMark + suffix;
    if (::link(target.c_str(), backup.c_str()) != 0) {
      fs::copy_file(target, backup, fs::copy_options::overwrite_existing, ec);
      if (ec) {
        RemoveAll(backups);
        RemoveAll(temps);
        throw IoError(files[i].path + ": cannot keep a copy of the existing file (" + ec.message() +
                      ")");
      }
    }
    backups[i] = backup;
  }
  return backups;
}

// Each temporary renamed over its target. When a rename fails, the targets placed before it are
// restored from their backups (or removed where there was none) and the error thrown.
void PlaceFiles(const std::vector<StreamedFile>& files, const std::vector<std::string>& targets,
                const std::vector<std::string>& temps, const std::vector<std::string>& backups) {
  for (size_t i = 0; i < files.size(); ++i) {
    if (std::rename(temps[i].c_str(), targets[i].c_str()) == 0) continue;
    const std::string reason = std::strerror(errno);
    std::string restore_failed;
    for (size_t j = 0; j < i; ++j) {
      const std::string& placed = targets[j];
      const bool ok = backups[j].empty() ? std::remove(placed.c_str()) == 0
                                         : std::rename(backups[j].c_str(), placed.c_str()) == 0;
      if (!ok) restore_failed += (restore_failed.empty() ? "" : ", ") + files[j].path;
    }
    RemoveAll(backups);
    RemoveAll(temps);
    throw IoError(files[i].path + ": cannot rename the temporary file into place (" + reason + ")" +
                  (restore_failed.empty()
                       ? ""
                       : "; could not restore the earlier state of " + restore_failed));
  }
}

}  // namespace

void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files) {
  std::vector<StreamedFile> streamed;
  streamed.reserve(files.size());
  for (const auto& [path, contents] : files) {
    streamed.push_back({path, [&contents = contents](std::FILE* out) {
                          std::fwrite(contents.data(), 1, contents.size(), out);
                        }});
  }
  WriteStreamedFilesAtomically(streamed);
}

void RemoveTemporariesForExit() {
  TemporaryRegistry& r = Registry();
  r.mutex.lock();  // held to the end: no write starts or places a set after this
  for (const std::string& path : r.paths) ::unlink(path.c_str());
}

void WriteStreamedFilesAtomically(const std::vector<StreamedFile>& files) {
  CheckTargets(files);
  const std::vector<std::string> targets = Targets(files);
  const std::string suffix = std::to_string(::getpid());
  RemoveStaleTemporaries(targets);
  RegisteredTemporaries registered;
  const std::vector<std::string> temps = WriteTemporaries(files, targets, suffix, registered);
  // Each target is replaced by one atomic rename, so a reader sees the old file or the new one,
  // never none; a set keeps backups so that it is placed whole or not at all. An exit
  // (RemoveTemporariesForExit) waits until then, so the backups never outlive it.
  const std::lock_guard<std::mutex> placing(Registry().mutex);
  const std::vector<std::string> backups = files.size() > 1
                                               ? KeepBackups(files, targets, suffix, temps)
                                               : std::vector<std::string>(files.size());
  PlaceFiles(files, targets, temps, backups);
  RemoveAll(backups);
}

void WriteFileAtomically(const std::string& path, const std::string& contents) {
  WriteFilesAtomically({{path, contents}});
}

void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files,
                          const std::vector<std::string>& inputs) {
  std::vector<std::string> paths;
  for (const auto& file : files) paths.push_back(file.first);
  RequireOutputsAreNotInputs(inputs, paths);
  WriteFilesAtomically(files);
}

}  // namespace gyrodrift::io
