// Whole-file reads and atomic writes (io/files.h): a write or a set of writes lands completely or
// not at all; every failure (a refusal up front, a writer that throws, a failed open or rename)
// leaves the earlier files as they were and no temporary or backup beside them; temporaries of
// writers that were killed are swept by the next write of the same target.
// (Refusing an output that is one of a command's inputs is the CLI's check, apps/gyrodrift/
// cli_util.cc, covered by tests/cli/data_safety_test.cc, not this file's.)
#include "gyrodrift/io/files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "support/test_support.h"

namespace gyrodrift::io {
namespace {

namespace fs = std::filesystem;

// The names in `dir` (not recursive).
std::set<std::string> Entries(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// The message of the IoError `call` throws, or "" when it throws none.
template <typename F>
std::string IoMessage(F&& call) {
  try {
    call();
  } catch (const IoError& e) {
    return e.what();
  }
  return "";
}

TEST(ReadTextFile, ReturnsTheBytesAsWritten) {
  const std::string dir = test::TempDir("files_read");
  // Binary-safe: NUL bytes, CR LF and no final newline come back unchanged.
  const std::string bytes = std::string("a\0b\r\nc", 6) + std::string(70000, 'x');
  WriteFileAtomically(dir + "/f.bin", bytes);
  EXPECT_EQ(ReadTextFile(dir + "/f.bin"), bytes);
  WriteFileAtomically(dir + "/empty", "");
  EXPECT_EQ(ReadTextFile(dir + "/empty"), "");
}

TEST(ReadTextFile, AMissingFileIsAnIoErrorNamingThePath) {
  const std::string path = test::TempDir("files_missing") + "/none.csv";
  const std::string message = IoMessage([&] { ReadTextFile(path); });
  EXPECT_EQ(message.rfind(path + ": cannot open for reading (", 0), 0u) << message;
}

TEST(ReadTextFile, ADirectoryIsAnIoErrorNamingThePath) {
  const std::string dir = test::TempDir("files_directory");
  EXPECT_EQ(IoMessage([&] { ReadTextFile(dir); }), dir + ": is a directory, not a file");
}

TEST(WriteFileAtomically, CreatesAndReplacesWithoutLeavingATemporary) {
  const std::string dir = test::TempDir("files_single");
  WriteFileAtomically(dir + "/out.csv", "first\n");
  EXPECT_EQ(ReadTextFile(dir + "/out.csv"), "first\n");
  WriteFileAtomically(dir + "/out.csv", "second, longer\n");
  EXPECT_EQ(ReadTextFile(dir + "/out.csv"), "second, longer\n");
  // A shorter replacement is not the old file's tail overwritten in place.
  WriteFileAtomically(dir + "/out.csv", "3");
  EXPECT_EQ(ReadTextFile(dir + "/out.csv"), "3");
  EXPECT_EQ(Entries(dir), std::set<std::string>{"out.csv"});
}

TEST(WriteFileAtomically, AMissingFolderIsRefusedNotCreated) {
  // The writer creates no folders: that is its callers' decision (RunFleet, WriteStudyFiles).
  const std::string dir = test::TempDir("files_no_folder");
  const std::string path = dir + "/missing/out.csv";
  const std::string message = IoMessage([&] { WriteFileAtomically(path, "x"); });
  EXPECT_EQ(message.rfind(path + ": cannot open for writing (", 0), 0u) << message;
  EXPECT_TRUE(Entries(dir).empty());
}

TEST(WriteFilesAtomically, FailedSetLeavesNothingBehind) {
  const std::string dir = test::TempDir("atomic_set");
  EXPECT_THROW(WriteFilesAtomically({{dir + "/ok.txt", "x"}, {dir + "/missing/dir/f.txt", "y"}}),
               IoError);
  EXPECT_FALSE(test::FileExists(dir + "/ok.txt"));
  // A directory among the targets or a target named twice: refused before anything is written,
  // and existing files keep their contents.
  WriteFileAtomically(dir + "/old.txt", "old");
  std::filesystem::create_directory(dir + "/sub");
  EXPECT_THROW(WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/sub", "z"}}), IoError);
  EXPECT_THROW(WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/./old.txt", "z"}}),
               IoError);
  EXPECT_EQ(ReadTextFile(dir + "/old.txt"), "old");
  // A set that succeeds replaces existing files and leaves no temporary or backup behind.
  WriteFilesAtomically({{dir + "/old.txt", "new"}, {dir + "/other.txt", "o"}});
  EXPECT_EQ(ReadTextFile(dir + "/old.txt"), "new");
  int entries = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 3);  // old.txt, other.txt, sub
}

TEST(WriteFilesAtomically, RefusalsNameThePath) {
  const std::string dir = test::TempDir("files_refusals");
  fs::create_directory(dir + "/sub");
  EXPECT_EQ(IoMessage([&] {
              WriteFilesAtomically({{dir + "/sub", "z"}});
            }),
            dir + "/sub: is a directory, cannot write a file there");
  // Named twice however spelled: "a/../x" is "x".
  EXPECT_EQ(IoMessage([&] {
              WriteFilesAtomically({{dir + "/x.csv", "1"}, {dir + "/sub/../x.csv", "2"}});
            }),
            dir + "/sub/../x.csv: named twice among the files of one output set");
  // An empty name (`-o ''`) is named as such, before any temporary is written.
  EXPECT_EQ(IoMessage([&] { WriteFileAtomically("", "z"); }),
            "the name of a file to write is empty");
  EXPECT_EQ(Entries(dir), std::set<std::string>{"sub"});
  EXPECT_TRUE(Entries(dir + "/sub").empty());
}

TEST(WriteStreamedFilesAtomically, AWriterThatThrowsChangesNothing) {
  const std::string dir = test::TempDir("files_streamed_throw");
  WriteFileAtomically(dir + "/a.csv", "old a");
  // The second file's writer fails after the first file's temporary is complete: neither target
  // is created or changed, and neither temporary stays.
  const auto attempt = [&] {
    WriteStreamedFilesAtomically(
        {{dir + "/a.csv", [](std::FILE* out) { std::fputs("new a", out); }},
         {dir + "/b.csv", [](std::FILE* out) {
            std::fputs("half of b", out);
            throw std::runtime_error("cancelled");
          }}});
  };
  EXPECT_THROW(attempt(), std::runtime_error);
  EXPECT_EQ(ReadTextFile(dir + "/a.csv"), "old a");
  EXPECT_EQ(Entries(dir), std::set<std::string>{"a.csv"});
}

TEST(WriteStreamedFilesAtomically, AFailedWriteOnTheStreamIsCaught) {
  const std::string dir = test::TempDir("files_stream_error");
  WriteFileAtomically(dir + "/a.csv", "old a");
  // A writer that does not throw but whose stream fails (here: writing to a read-only stream
  // sets its error flag) must not have its truncated output committed.
  const std::string message = IoMessage([&] {
    WriteStreamedFilesAtomically({{dir + "/a.csv", [](std::FILE* out) {
                                     std::fputs("new", out);
                                     std::fflush(out);
                                     std::fgetc(out);  // read on a write-only stream: an error
                                   }}});
  });
  EXPECT_EQ(message, dir + "/a.csv: write failed (disk full?)");
  EXPECT_EQ(ReadTextFile(dir + "/a.csv"), "old a");
  EXPECT_EQ(Entries(dir), std::set<std::string>{"a.csv"});
}

TEST(WriteStreamedFilesAtomically, AFailedRenameRemovesTheTemporary) {
  // The target turns into a folder while its contents are written (after the up-front check):
  // the rename fails, the error names the target and no temporary stays.
  const std::string dir = test::TempDir("files_rename");
  const std::string target = dir + "/out.csv";
  const std::string message = IoMessage([&] {
    WriteStreamedFilesAtomically({{target, [&](std::FILE* out) {
                                     std::fputs("data", out);
                                     fs::create_directory(target);
                                     WriteFileAtomically(target + "/inside", "x");
                                   }}});
  });
  EXPECT_EQ(message.rfind(target + ": cannot rename the temporary file into place (", 0), 0u)
      << message;
  EXPECT_EQ(Entries(dir), std::set<std::string>{"out.csv"});
  EXPECT_TRUE(fs::is_directory(target));
}

TEST(WriteStreamedFilesAtomically, ASetWhoseBackupFailsChangesNothing) {
  // Same race for a set: the existing a.csv is kept as a backup before any rename, and a target
  // that became a folder cannot be; the set is abandoned before a.csv is replaced.
  const std::string dir = test::TempDir("files_backup");
  WriteFileAtomically(dir + "/a.csv", "old a");
  const std::string b = dir + "/b.csv";
  EXPECT_THROW(WriteStreamedFilesAtomically(
                   {{dir + "/a.csv", [](std::FILE* out) { std::fputs("new a", out); }},
                    {b,
                     [&](std::FILE* out) {
                       std::fputs("b", out);
                       fs::create_directory(b);
                       WriteFileAtomically(b + "/inside", "x");
                     }}}),
               IoError);
  EXPECT_EQ(ReadTextFile(dir + "/a.csv"), "old a");
  EXPECT_EQ(Entries(dir), (std::set<std::string>{"a.csv", "b.csv"}));
}

TEST(WriteStreamedFilesAtomically, RelativePathsWriteIntoTheWorkingFolder) {
  // A bare file name has an empty parent path: the sweep of stale temporaries must look in ".".
  const std::string dir = test::TempDir("files_relative");
  const fs::path previous = fs::current_path();
  fs::current_path(dir);
  EXPECT_NO_THROW(WriteFileAtomically("plain.txt", "here"));
  fs::current_path(previous);
  EXPECT_EQ(ReadTextFile(dir + "/plain.txt"), "here");
  EXPECT_EQ(Entries(dir), std::set<std::string>{"plain.txt"});
}

// The rename that places a file would replace whatever sits at its name: a link is followed (its
// file replaced, the link kept); a pipe, a device or a link to nothing is refused before any
// work, by the output check as by the write.
TEST(Files, TargetsThatAreNotRegularFilesAreFollowedOrRefused) {
  namespace fs = std::filesystem;
  const std::string dir = test::TempDir("atomic_special");
  fs::create_directories(dir + "/runs");
  WriteFileAtomically(dir + "/runs/r1.csv", "old");
  fs::create_symlink("runs/r1.csv", dir + "/latest.csv");
  WriteFileAtomically(dir + "/latest.csv", "new");
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir + "/latest.csv")));
  EXPECT_EQ(ReadTextFile(dir + "/runs/r1.csv"), "new");
  EXPECT_EQ(Entries(dir), (std::set<std::string>{"latest.csv", "runs"}));

  ASSERT_EQ(::mkfifo((dir + "/pipe.csv").c_str(), 0644), 0);
  fs::create_symlink("runs/none.csv", dir + "/dangling.csv");
  for (const auto& [name, message] : std::vector<std::pair<std::string, std::string>>{
           {"/pipe.csv", "is not a regular file (a device, a pipe or a socket)"},
           {"/dangling.csv", "is a symbolic link to nothing"}}) {
    try {
      RequireOutputsAreNotInputs({}, {dir + name});
      ADD_FAILURE() << name << " was accepted";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find(dir + name + ": " + message), std::string::npos)
          << e.what();
    }
    EXPECT_THROW(WriteFileAtomically(dir + name, "x"), IoError) << name;
  }
  EXPECT_TRUE(fs::is_fifo(dir + "/pipe.csv"));
  EXPECT_THROW(RequireOutputsAreNotInputs({}, {"/dev/null"}), IoError);
}

TEST(Files, OneFileNamedTwiceIsRefused) {
  const std::string dir = test::TempDir("distinct_files");
  WriteFileAtomically(dir + "/a.csv", "a");
  WriteFileAtomically(dir + "/b.csv", "a");
  EXPECT_NO_THROW(RequireDistinctFiles({dir + "/a.csv", dir + "/b.csv", dir + "/none.csv"}, "logs",
                                       "give it once"));
  try {
    RequireDistinctFiles({dir + "/a.csv", dir + "/./a.csv"}, "logs", "give it once");
    ADD_FAILURE() << "one file named twice was accepted";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()),
              "logs " + dir + "/a.csv and " + dir + "/./a.csv are one file: give it once");
  }
}

TEST(Files, StaleTemporariesOfKilledWritersAreRemovedByTheNextWrite) {
  const std::string dir = test::TempDir("atomic_stale");
  // A pid that no longer runs: a child that has exited and been reaped.
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ASSERT_GT(child, 0);
  ::waitpid(child, nullptr, 0);
  const std::string dead = std::to_string(child);
  const std::string alive = std::to_string(::getppid());
  const std::vector<std::string> stale = {"x.csv.gyrodrift-tmp." + dead,
                                          "x.csv.gyrodrift-bak." + dead};
  const std::vector<std::string> kept = {
      "x.csv.gyrodrift-tmp." + alive,  // a writer that still runs
      "y.csv.gyrodrift-tmp." + dead,   // another target's: that write cleans it
      "x.csv.gyrodrift-tmp.12ab",      // not our naming pattern
      "x.csv.tmp." + dead,             // a user's file, whatever its digits
      "x.csv.bak.20261127",            // a user's dated backup
      "x.csv.old"};
  for (const auto& name : stale) WriteFileAtomically(dir + "/" + name, "partial");
  for (const auto& name : kept) WriteFileAtomically(dir + "/" + name, "other");
  WriteFileAtomically(dir + "/x.csv", "complete");
  EXPECT_EQ(ReadTextFile(dir + "/x.csv"), "complete");
  for (const auto& name : stale) EXPECT_FALSE(test::FileExists(dir + "/" + name)) << name;
  for (const auto& name : kept) EXPECT_EQ(ReadTextFile(dir + "/" + name), "other") << name;
  // A user's input named like a dead writer's temporary is checked as an input, then kept.
  const std::string input = dir + "/x.csv.gyrodrift-tmp." + dead;
  WriteFileAtomically(input, "the user's log");
  RequireOutputsAreNotInputs({input}, {dir + "/x.csv"});
  WriteFileAtomically(dir + "/x.csv", "again");
  EXPECT_EQ(ReadTextFile(input), "the user's log");
}

// Checked before the work: an output in a folder that does not exist is refused up front (the
// write would fail after an hour of decomposition), and one beside the working folder is not.
TEST(RequireOutputsAreNotInputs, AnOutputWithoutItsFolderIsRefusedBeforeTheWork) {
  const std::string dir = test::TempDir("files_folder");
  try {
    RequireOutputsAreNotInputs({}, {dir + "/nodir/x.csv"});
    ADD_FAILURE() << "no refusal";
  } catch (const IoError& e) {
    EXPECT_EQ(std::string(e.what()),
              dir + "/nodir/x.csv: cannot open for writing (no folder " + dir + "/nodir)");
  }
  EXPECT_NO_THROW(RequireOutputsAreNotInputs({}, {dir + "/x.csv", "relative_output.csv"}));
}

TEST(WriteFileAtomically, AReplacedFileKeepsItsPermissions) {
  const std::string dir = test::TempDir("files_mode");
  WriteFileAtomically(dir + "/private.csv", "first\n");
  ::chmod((dir + "/private.csv").c_str(), 0600);
  WriteFileAtomically(dir + "/private.csv", "second\n");
  struct stat st;
  ASSERT_EQ(::stat((dir + "/private.csv").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
  EXPECT_EQ(ReadTextFile(dir + "/private.csv"), "second\n");
}

}  // namespace
}  // namespace gyrodrift::io
