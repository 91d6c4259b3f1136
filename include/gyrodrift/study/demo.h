// The `demo` user operation, written once for every front end: the study's settings by name as a
// user gives them, their mapping onto StudyOptions, a user's log read into a StudyLog, the run,
// and the folder of files (the study's and demo.json, the record of how it was run).
// `gyrodrift demo` and the Python package's `demo` call RunDemo and nothing below it.
//
// Messages spell a setting as the caller's user types it: flags (--input, --target) when the log
// settings' gaps_name is a flag ("--gaps"), else keys (input, target), as tasks::SpeltAsFlags.
// Cost: the study's (study.h); reading and writing are a few per cent of it.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/study/study.h"

namespace gyrodrift::study {

namespace internal {
inline const StudyOptions kStudyDefaults{};
}  // namespace internal

struct DemoSettings {
  std::string output = "gyrodrift-demo";  // the folder written (created if needed)
  // A uniformly sampled log (CSV or ULog) to study instead of the simulation; "" = simulate.
  std::string input;
  std::string target, temperature;  // the log's output and temperature columns (input only)
  std::optional<double> rate_hz;    // the log's sample rate, Hz; unset: from time_s, else 1 Hz
  // allan::RateUnit name of the log's output (input only): dph | dps | rads.
  std::string units{allan::ToString(internal::kStudyDefaults.units)};
  double duration_s = internal::kStudyDefaults.duration_s;  // of each simulated run, s
  int ensemble = internal::kStudyDefaults.ensemble_size;
  int realisations = internal::kStudyDefaults.realisations;
  drift::CausalOptions causal = internal::kStudyDefaults.causal;  // the causal windows
  std::string methods = "all";  // "all" or a comma-separated list of compensate-mode methods
  std::uint64_t seed = internal::kStudyDefaults.seed;
  int threads = 0;     // [0, 1024]; 0 = every core
  io::LogOptions log;  // how the input is read (gaps, delimiter, ...)

  // The study's options, validated: OptionError naming the StudyOptions field (duration_s,
  // ensemble_size, ...) or the setting (units, methods, threads); UsageError for settings of a
  // log given without input, or input without target or temperature.
  StudyOptions Options() const;
};

// The user's log of settings.input as the study takes it (target, temperature, sample rate, the
// notes on its time axis). Throws what io::ReadLog throws, UsageError for gaps split or carry.
StudyLog ReadDemoLog(const DemoSettings& settings);

// What RunDemo did: the study's result and the files written under settings.output (names
// relative to it, report.html last but demo.json).
struct DemoRun {
  StudyResult result;
  std::vector<StudyFile> files;
  double seconds = 0.0;  // wall time of the whole run, reading and writing included
};

// Checks the settings, that the input lies outside the output folder and that the folder can be
// written, then runs the study (on the simulation or the log) and writes every file as one atomic
// set. `context` reports its stages; writing the files is reported as stage kStudyStages.
DemoRun RunDemo(const DemoSettings& settings, const StudyContext& context = {});

// The relative cost of RunDemo's stages 0..kStudyStages (the last: writing the files), for a
// progress bar: the seconds each took in the measured runs (docs/demo.md), of the simulated
// study or of a log's.
std::vector<double> DemoStageWeights(bool simulated);

// demo.json: the tool, "command": "demo", the study's record (StudyRecord) and the settings.
nlohmann::json DemoRecord(const DemoSettings& settings, const StudyResult& result);

}  // namespace gyrodrift::study
