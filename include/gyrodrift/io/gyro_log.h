// A gyro log as every command reads it: a CSV table whose time_s column, when it has one, gives
// the sample rate and must increase. One home for the rules the CLI, the study and the fleet
// calibration share.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/ulog.h"

namespace gyrodrift::io {

// What to do with gaps in time_s: a step longer than 1.5 median steps (samples missing).
//   error:       refuse the log, naming the first gap's row, its length and the choices;
//   interpolate: insert round(step / median) - 1 rows across each gap, every column linear
//                between its neighbours (the models and the Allan analysis then see a uniform
//                record; the note says how many samples were made up);
//   split:       keep the rows as they are and cut the log into records at its gaps (the caller
//                gets where each record starts): a thermal model's lag states restart after a
//                gap instead of running across it, for a logger that stopped for a while. Only
//                where the caller can use records (record_starts given).
//   carry:       fill the gaps as interpolate does, and tell the caller which rows were logged
//                (*logged): a thermal model's lag states run across each gap on the interpolated
//                temperature, while fitting, scoring and reporting use the logged rows only (a
//                duty-cycled logger: 5 s of every 300 s). Only where the caller honours the mask
//                (logged given).
// Where rows were made up (interpolate or carry) and the caller passed `logged`, it receives the
// mask; a caller that shows the made-up rows marks them.
enum class GapPolicy { kError, kInterpolate, kSplit, kCarry };
std::string_view ToString(GapPolicy policy);
GapPolicy GapPolicyFromString(std::string_view text);  // UsageError naming the choices

// How a log is read.
struct LogOptions {
  GapPolicy gaps = GapPolicy::kError;
  Delimiter delimiter = Delimiter::kAuto;
  // How the caller's user spells the gaps setting, so that every message names it as typed:
  // "gaps" (a manifest key: gaps = 'split') or a flag such as "--gaps" (--gaps split).
  std::string gaps_name = "gaps";
  // A file without a header row (the names of its columns), lines to skip before the header or
  // the first row, and what to do with damaged rows: CsvReadOptions' names, skip_rows and
  // bad_lines. Skipped rows are listed in the note (ReadLog).
  std::vector<std::string> names = {};
  int skip_rows = CsvReadOptions{}.skip_rows;
  BadLines bad_lines = CsvReadOptions{}.bad_lines;
  // A PX4 ULog (a file that starts with ULog's magic bytes, whatever its name) is read as
  // `gyrodrift convert` writes it: the series of ulog.topic and ulog_instance as time_s,
  // <axis>_<units> and temperature_c; the CSV settings above do not apply to it.
  UlogConversion ulog = {};
  int ulog_instance = 0;  // [0, kMaxUlogInstance]
  bool operator==(const LogOptions&) const = default;
};

// `policy` spelt as the user sets it under options.gaps_name: "--gaps split" or "gaps = 'split'".
std::string SpellGaps(const LogOptions& options, GapPolicy policy);

// Share of made-up rows above which interpolate warns (the models would fit and score mostly on
// rows nobody logged) and suggests carry.
constexpr double kMostlyMadeUpShare = 0.5;

// Whether `path` starts with ULog's magic bytes (false for a file that cannot be opened).
bool IsUlogFile(const std::string& path);

// Reads a gyro log (CsvTable::Read, or a ULog's series as LogOptions says) and, when it has a numeric time_s column, requires it to
// increase strictly: a time stamp that repeats or goes backwards is a DataError naming its row
// (the log was merged, sorted wrongly or its clock jumped; every model and the Allan analysis
// would otherwise take the samples as equally spaced, silently). Gaps are handled by
// options.gaps; when rows were interpolated or the log was split, *gap_note (if given) says so,
// else it is cleared (with interpolate, when more than kMostlyMadeUpShare of the rows are made up,
// the note is a warning that suggests carry; damaged rows skipped under BadLines::kSkip, and a
// ULog's damage skipped, are on lines of their own). With kSplit, *record_starts receives the first row
// (0-based) of every record after the first (empty: no gap); kSplit without record_starts is a
// UsageError. *logged (if given) receives one flag per returned row, true where the row was
// logged, or stays empty when every row was; kCarry without logged is a UsageError. Shorter
// irregular steps stay a note (NonUniformTimeNote). `columns`: the columns the caller needs
// (CsvReadOptions::columns); empty = every column. With columns named, time_s is read as a time
// axis (CsvTable::time_axis: its steps, not its values; NonUniformTimeNote and ResolveSampleRate
// use it), and kept whole only when it repeats, goes backwards, has a bad cell, a gap or more
// than TimeAxis::kMaxDistinctSteps distinct steps.
CsvTable ReadLog(const std::string& path, const LogOptions& options = {},
                 std::string* gap_note = nullptr,
                 std::vector<Eigen::Index>* record_starts = nullptr,
                 const std::vector<std::string>& columns = {},
                 std::vector<bool>* logged = nullptr);

// The sample rate of a log: `given` when > 0 (*how = "given"); else 1 / the clock's step of a
// time_s column (*how = "time_s": the mean of its steps within 1 % of the median step, which
// epoch time stamps round; the median where the two agree to 1e-9); else 1 Hz (*how = "default").
// Throws DataError naming time_s when its median step is not positive or gives a rate outside
// [1e-9, 1e6] Hz.
double ResolveSampleRate(const CsvTable& table, double given, std::string* how);

// Logs fitted together as records of one calibration need one sample rate: throws DataError
// naming both logs when `rate_hz` (of `log`) differs from `first_hz` (of `first`) by more than 1 %.
void RequireSameSampleRate(const std::string& first, double first_hz, const std::string& log,
                           double rate_hz);

// "" for a log without time_s or with a uniform one (read by ReadLog, so time_s increases);
// otherwise a one-line note that the time axis has jitter (steps shorter than half the median
// step: how many, the shortest and its row), since every model and the Allan analysis assume
// uniform sampling. Gaps (steps of 1.5 median steps or more) are not counted: ReadLog refused,
// filled or split them.
std::string NonUniformTimeNote(const CsvTable& table);

}  // namespace gyrodrift::io
