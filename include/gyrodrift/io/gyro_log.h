// A gyro log as every command reads it: a CSV table whose time_s column, when it has one, gives
// the sample rate and must increase. One home for the rules the CLI, the study and the fleet
// calibration share.
#pragma once

#include <string>
#include <string_view>

#include "gyrodrift/io/csv.h"

namespace gyrodrift::io {

// What to do with gaps in time_s: a step longer than 1.5 median steps (samples missing).
//   error:       refuse the log, naming the first gap's row, its length and the choices;
//   interpolate: insert round(step / median) - 1 rows across each gap, every column linear
//                between its neighbours (the models and the Allan analysis then see a uniform
//                record; the note says how many samples were made up).
enum class GapPolicy { kError, kInterpolate };
std::string_view ToString(GapPolicy policy);
GapPolicy GapPolicyFromString(std::string_view text);  // UsageError naming the choices

// Reads a gyro log (CsvTable::Read) and, when it has a numeric time_s column, requires it to
// increase strictly: a time stamp that repeats or goes backwards is a DataError naming its row
// (the log was merged, sorted wrongly or its clock jumped; every model and the Allan analysis
// would otherwise take the samples as equally spaced, silently). Gaps are handled by `gaps`;
// when rows were interpolated, *gap_note (if given) says how many, else it is cleared. Shorter
// irregular steps stay a note (NonUniformTimeNote).
CsvTable ReadLog(const std::string& path, GapPolicy gaps = GapPolicy::kError,
                 std::string* gap_note = nullptr);

// The sample rate of a log: `given` when > 0 (*how = "given"); else 1 / (median step of a time_s
// column) (*how = "time_s"); else 1 Hz (*how = "default"). Throws DataError naming time_s when
// its median step is not positive or gives a rate outside [1e-9, 1e6] Hz.
double ResolveSampleRate(const CsvTable& table, double given, std::string* how);

// "" for a log without time_s or with a uniform one (read by ReadLog, so time_s increases);
// otherwise a one-line note that the time axis has gaps or jitter (steps more than half the
// median step away from it: how many, the largest and its row), since every model and the Allan
// analysis assume uniform sampling.
std::string NonUniformTimeNote(const CsvTable& table);

}  // namespace gyrodrift::io
