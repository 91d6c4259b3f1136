// A command killed by SIGKILL (the OOM killer, a closed laptop lid, `kill -9`) leaves every
// output path holding the complete previous file or the complete new one (or nothing, where
// there was none), never a partial file. A SIGKILL cannot be caught, so temporaries of the
// killed run (<target>.gyrodrift-tmp.<pid>, <target>.gyrodrift-bak.<pid>) may be left beside the
// outputs; they never carry an output's name, and the next run of the command removes them
// (io::WriteFilesAtomically).
//
// Each command runs once to completion (the reference: its duration and its complete outputs),
// then is started again over a "previous version" of every output and killed at fixed times, at
// fractions of the reference duration and the moment its first temporary file appears (the write
// phase); after every kill each output is checked. Finally a rerun must succeed over the
// leftovers and leave no temporary behind.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "gyrodrift/html/report.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

extern char** environ;

namespace gyrodrift {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Under the sanitizers (make test-sanitize) every run is several times slower; smaller inputs
// keep the test's time similar.
bool Sanitized() { return std::getenv("GYRODRIFT_SANITIZE") != nullptr; }

// stderr goes to `err_path` (or nowhere).
pid_t Spawn(const std::vector<std::string>& args, const std::string& err_path = "/dev/null") {
  std::vector<std::string> argv_storage = {GYRODRIFT_CLI};
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0644);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  EXPECT_EQ(rc, 0) << "posix_spawn " << argv[0];
  return rc == 0 ? pid : -1;
}

// Exit status as a shell gives it: the code, or 128 + the signal.
int Wait(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

bool Exited(pid_t pid, int* code) {
  int status = 0;
  if (::waitpid(pid, &status, WNOHANG) != pid) return false;
  *code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return true;
}

// Every regular file below `root`, by path relative to it.
std::map<std::string, std::string> Snapshot(const std::string& root) {
  std::map<std::string, std::string> files;
  std::error_code ec;
  if (!fs::exists(root, ec)) return files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (e.is_regular_file()) {
      files[fs::relative(e.path(), root).string()] = io::ReadTextFile(e.path().string());
    }
  }
  return files;
}

bool IsTemporaryName(const std::string& name) {
  static const std::regex pattern(R"(.*\.gyrodrift-(tmp|bak)\.[0-9]+$)");
  return std::regex_match(name, pattern);
}

bool AnyTemporary(const std::string& root) {
  std::error_code ec;
  for (fs::recursive_directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    if (IsTemporaryName(it->path().filename().string())) return true;
  }
  return false;
}

// A complete version of an output whose numbers vary from run to run.
bool CompleteLike(const std::string& contents, const std::string& reference) {
  if (contents.empty() || contents.back() != '\n') return false;
  if (reference.front() == '{') return nlohmann::json::accept(contents);
  std::istringstream a(contents), b(reference);
  std::string la, lb;
  while (std::getline(b, lb)) {
    if (!std::getline(a, la)) return false;
    if (std::count(la.begin(), la.end(), ',') != std::count(lb.begin(), lb.end(), ',')) return false;
  }
  return !std::getline(a, la);
}

struct KillCase {
  std::string name;
  std::vector<std::string> args;  // the command line after the command's name
  std::string output_root;        // every output lies below it (a folder the test owns)
  // Outputs whose bytes change from run to run (they report wall-clock timings): a complete one
  // has the reference's lines, each with its number of commas (JSON: parses as a whole).
  std::set<std::string> timed;
};

class KillSafety : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = test::TempDir("cli_kill_safety"); }

  // Writes a recognisable complete previous version of every reference output, by plain
  // streams (io::WriteFilesAtomically would already clear the leftovers under test).
  static void WritePreviousVersions(const KillCase& c,
                                    const std::map<std::string, std::string>& reference) {
    for (const auto& [relative, contents] : reference) {
      const fs::path path = fs::path(c.output_root) / relative;
      fs::create_directories(path.parent_path());
      std::ofstream(path, std::ios::binary | std::ios::trunc) << "previous " << relative << "\n";
    }
  }

  // Each output is its previous version, or a complete new one; anything else in the output
  // folders is a temporary of our naming pattern (and is counted).
  static void CheckOutputs(const KillCase& c, const std::map<std::string, std::string>& reference,
                           const std::string& when, int* temporaries) {
    for (const auto& [relative, contents] : Snapshot(c.output_root)) {
      const std::string label = c.name + " killed " + when + ": " + relative;
      if (reference.count(relative) == 0) {
        EXPECT_TRUE(IsTemporaryName(relative)) << label << " is neither an output nor a temporary";
        ++*temporaries;
        continue;
      }
      if (contents == "previous " + relative + "\n") continue;
      if (c.timed.count(relative)) {
        EXPECT_TRUE(CompleteLike(contents, reference.at(relative))) << label << " is partial";
      } else {
        EXPECT_EQ(contents.size(), reference.at(relative).size()) << label;
        EXPECT_TRUE(contents == reference.at(relative)) << label << " is a partial or foreign file";
      }
    }
  }

  static void Run(const KillCase& c) {
    // Reference: a complete run into an empty folder.
    std::vector<std::string> args = {c.name};
    args.insert(args.end(), c.args.begin(), c.args.end());
    fs::remove_all(c.output_root);
    fs::create_directories(c.output_root);
    const std::string err_path = c.output_root + ".stderr";
    const auto start = Clock::now();
    const pid_t ref = Spawn(args, err_path);
    ASSERT_GT(ref, 0);
    const int ref_code = Wait(ref);
    const double ref_ms =
        std::chrono::duration<double, std::milli>(Clock::now() - start).count();
    ASSERT_EQ(ref_code, 0) << c.name << " reference run: " << io::ReadTextFile(err_path);
    const std::map<std::string, std::string> reference = Snapshot(c.output_root);
    ASSERT_FALSE(reference.empty()) << c.name;
    ASSERT_FALSE(AnyTemporary(c.output_root)) << c.name;

    // Kill points: fixed early times, fractions of the reference run, and the write phase
    // (-1: the moment a temporary appears; -2: 2 ms later, into the renames).
    std::vector<double> kill_ms = {5, 50, 200, 0.5 * ref_ms, 0.9 * ref_ms, -1, -2};
    int temporaries = 0, killed = 0, caught_writing = 0;
    for (const double at : kill_ms) {
      WritePreviousVersions(c, reference);
      const pid_t pid = Spawn(args);
      ASSERT_GT(pid, 0);
      const auto t0 = Clock::now();
      int code = -1;
      bool done = false;
      if (at >= 0) {
        while (!(done = Exited(pid, &code)) &&
               std::chrono::duration<double, std::milli>(Clock::now() - t0).count() < at) {
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        }
      } else {
        // Ten times the reference duration bounds the wait if the temporary is never seen.
        while (!(done = Exited(pid, &code)) && !AnyTemporary(c.output_root) &&
               std::chrono::duration<double, std::milli>(Clock::now() - t0).count() <
                   10 * ref_ms + 1000) {
        }
        if (!done) {
          ++caught_writing;
          if (at == -2) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
      }
      if (!done) {
        ::kill(pid, SIGKILL);
        code = Wait(pid);
      }
      if (code == 128 + SIGKILL) ++killed;
      const std::string when =
          at >= 0 ? "after " + std::to_string(static_cast<int>(at)) + " ms"
                  : (at == -1 ? "as its first temporary appeared" : "2 ms into its write");
      EXPECT_TRUE(code == 0 || code == 128 + SIGKILL) << c.name << " " << when << ": " << code;
      CheckOutputs(c, reference, when, &temporaries);
    }
    EXPECT_GE(killed, 3) << c.name << ": too few runs were killed before they ended";
    // Rerun over whatever the kills left: it succeeds, writes the complete outputs and removes
    // the temporaries of the killed runs.
    const int rerun = Wait(Spawn(args, err_path));
    EXPECT_EQ(rerun, 0) << c.name << " rerun: " << io::ReadTextFile(err_path);
    for (const auto& [relative, contents] : Snapshot(c.output_root)) {
      EXPECT_FALSE(IsTemporaryName(relative)) << c.name << ": rerun left " << relative;
      if (reference.count(relative) && !c.timed.count(relative)) {
        EXPECT_TRUE(contents == reference.at(relative)) << c.name << " rerun: " << relative;
      }
    }
    std::printf("%s: reference %.0f ms, %d of %zu runs killed (%d in the write phase), "
                "%d temporaries left by kills\n",
                c.name.c_str(), ref_ms, killed, kill_ms.size(), caught_writing, temporaries);
  }

  std::string dir_;
};

TEST_F(KillSafety, Decompose) {
  // Large enough that writing its CSV takes a while (the write phase is then caught).
  const std::string log = dir_ + "/log.csv";
  io::WriteFileAtomically(log, test::ThermalLogCsv(Sanitized() ? 20000 : 60000, 1));
  Run({"decompose",
       {log, "-c", "rate_dph", "--method", "emd", "-q", "-o", dir_ + "/out/imfs.csv"},
       dir_ + "/out",
       {}});
}

// Ctrl-C, SIGTERM and SIGHUP are caught: the temporaries of the write under way go, the previous
// outputs stay, and the process ends by the signal.
TEST_F(KillSafety, InterruptedWriteLeavesNoTemporary) {
  const std::string log = dir_ + "/log.csv";
  io::WriteFileAtomically(log, test::ThermalLogCsv(Sanitized() ? 20000 : 60000, 1));
  const std::vector<std::string> args = {
      "decompose", log, "-c", "rate_dph", "--method", "emd", "-q", "-o", dir_ + "/out/imfs.csv"};
  int caught_writing = 0;
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    fs::create_directories(dir_ + "/out");
    for (const char* name : {"imfs.csv", "imfs.csv.json"}) {
      std::ofstream(dir_ + "/out/" + name, std::ios::trunc) << "previous\n";
    }
    const pid_t pid = Spawn(args);
    ASSERT_GT(pid, 0);
    int code = -1;
    bool done = false;
    const auto t0 = Clock::now();
    while (!(done = Exited(pid, &code)) && !AnyTemporary(dir_ + "/out") &&
           std::chrono::duration<double>(Clock::now() - t0).count() < 60.0) {
    }
    if (!done) {
      ++caught_writing;
      ::kill(pid, signal_number);
      code = Wait(pid);
      EXPECT_EQ(code, 128 + signal_number) << "signal " << signal_number;
    }
    EXPECT_FALSE(AnyTemporary(dir_ + "/out")) << "signal " << signal_number;
    for (const auto& [relative, contents] : Snapshot(dir_ + "/out")) {
      if (code != 0) {
        EXPECT_EQ(contents, "previous\n") << relative;
      }
    }
  }
  EXPECT_GE(caught_writing, 2) << "too few runs were still writing when signalled";
}

TEST_F(KillSafety, Fit) {
  const std::string log = dir_ + "/log.csv";
  // Long enough (about 0.5 s) for most kill points to strike before it ends.
  io::WriteFileAtomically(log, test::ThermalLogCsv(Sanitized() ? 40000 : 80000, 2));
  Run({"fit",
       {log, "-t", "rate_dph", "-T", "temperature_c", "--mode", "compensate", "-q", "-o",
        dir_ + "/out/model.json"},
       dir_ + "/out",
       {}});
}

TEST_F(KillSafety, Demo) {
  if (!fs::exists(std::string(html::kDygraphsDir) + "/dygraph.min.js")) {
    GTEST_SKIP() << "libjs-dygraphs not installed";
  }
  const std::string log = dir_ + "/log.csv";
  ASSERT_EQ(test::RunCli("simulate --duration 30min -q -o '" + log + "'").exit_code, 0);
  Run({"demo",
       {"--input", log, "--target", "rate_dph", "--temperature", "temperature_c", "--ensemble",
        "10", "--realisations", "20", "--window", "64", "--methods", "ms-elm,poly", "--threads",
        "1", "-q", "-o", dir_ + "/out"},
       dir_ + "/out",
       {"demo.json", "compensate_table.csv", "predict_table.csv", "report.html"}});
}

TEST_F(KillSafety, Calibrate) {
  fs::create_directories(dir_ + "/logs");
  for (const char* run : {"cal", "ver"}) {
    io::WriteFileAtomically(dir_ + "/logs/SN1_" + run + ".csv",
                            test::ThermalLogCsv(Sanitized() ? 12000 : 40000, run[0] == 'c' ? 3 : 4));
  }
  io::WriteFileAtomically(dir_ + "/fleet.toml",
                          "method = \"thermal\"\nrate_unit = \"dph\"\n"
                          "[[axis]]\ntarget = \"rate_dph\"\ntemperature = \"temperature_c\"\n"
                          "truth = \"drift_dph\"\n"
                          "[[unit]]\nserial = \"SN1\"\ncalibration = \"logs/SN1_cal.csv\"\n"
                          "verification = [\"logs/SN1_ver.csv\"]\n");
  Run({"calibrate",
       {dir_ + "/fleet.toml", "-o", dir_ + "/out", "--force", "--threads", "1", "-q"},
       dir_ + "/out",
       {"SN1/summary.json", "fleet.csv", "fleet.html"}});
}

}  // namespace
}  // namespace gyrodrift
