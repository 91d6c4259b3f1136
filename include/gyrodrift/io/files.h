// Whole-file reads and atomic writes.
//
// An output set (a CSV and its JSON sidecar, say) is committed with one AtomicWriteSet: every file
// is written to a temporary beside its target first, and only when all are written are they
// renamed into place, so a failure leaves no partial output.
//
// Temporaries are named <target>.gyrodrift-tmp.<pid> (and, while a set is renamed, backups
// <target>.gyrodrift-bak.<pid>), beside their targets. A process killed by SIGKILL (or a power
// cut) cannot remove them; they never carry a target's name, and the next write of the same
// target removes those whose process no longer runs (nothing else: a user's "x.csv.bak.1" stays;
// so do the "<target>.tmp.<pid>" temporaries of earlier gyrodrift versions: remove those by
// hand).
// A program that ends on SIGINT / SIGTERM calls RemoveTemporariesForExit first.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace gyrodrift::io {

// The user's files are never overwritten: throws UsageError naming both paths when an output
// (each output's sidecar included: pass both) is one of the inputs, however spelled (relative,
// "./", a symbolic or a hard link: the same file by device and inode). Inputs that do not exist
// or are empty strings are skipped. Also throws IoError for an output that exists and is not a
// regular file or a link to one (a directory, /dev/null, a pipe, a dangling link), or that does
// not exist in a folder that is missing or not writable, which the write would refuse after the
// work. Called before any work. The inputs are remembered for the
// process: no later write's clean-up of a killed writer's temporaries removes one of them, even
// one named like a temporary.
void RequireOutputsAreNotInputs(const std::vector<std::string>& inputs,
                                const std::vector<std::string>& outputs);

// Throws UsageError naming both when two of `paths` are one file however spelled (by device and
// inode: "./a.csv", a link): "`what` a.csv and ./a.csv are one file" and `why`. Paths that do not
// exist are skipped (reading them fails on its own).
void RequireDistinctFiles(const std::vector<std::string>& paths, const std::string& what,
                          const std::string& why);

// The same for an output folder: no input may lie inside it (or be it).
void RequireInputsOutsideFolder(const std::vector<std::string>& inputs, const std::string& folder);

// Throws IoError naming the path when it is a directory (which opens as a stream, then fails to
// read).
void RequireNotDirectory(const std::string& path);

// Throws IoError naming the path when the file cannot be read.
std::string ReadTextFile(const std::string& path);

// Writes each (path, contents) atomically as a set: every file is written to a temporary beside
// its target (a symbolic link's file, where it lies: the link stays), then renamed into place
// (one atomic replace per file: readers never find it missing); for a set, existing targets are
// first hard-linked (or copied) to backups that are renamed back if a later rename fails. Throws
// IoError naming the path that failed (also for a path named twice, or a target that is not a
// regular file: RequireOutputsAreNotInputs); then no target is created or changed (the message says
// so if a restore itself failed).
void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files);
void WriteFileAtomically(const std::string& path, const std::string& contents);
// The same after RequireOutputsAreNotInputs(inputs, the files' paths): for the writers of a folder
// (demo, calibrate), whose files are named at the end, where a link left in the folder could lead
// to an input.
void WriteFilesAtomically(const std::vector<std::pair<std::string, std::string>>& files,
                          const std::vector<std::string>& inputs);

// One file of an output set whose contents are streamed into the temporary file by `write`
// rather than held in memory (a decomposition of 1e7 samples renders to gigabytes of text).
// `write` may throw; a write error on the stream is caught after it returns.
struct StreamedFile {
  std::string path;
  std::function<void(std::FILE* out)> write;
};
// As above, with the same guarantees.
void WriteStreamedFilesAtomically(const std::vector<StreamedFile>& files);

// Removes the temporaries of the writes under way, after a set being placed is whole, and keeps
// any other write from starting or placing a set: for a thread that then ends the process (the
// CLI's signal thread, apps/gyrodrift/main.cc). Not for a signal handler (it takes a mutex).
void RemoveTemporariesForExit();

}  // namespace gyrodrift::io
