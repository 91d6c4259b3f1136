// A gyro log as every command reads it: a CSV table whose time_s column, when it has one, gives
// the sample rate and must increase. One home for the rules the CLI, the study and the fleet
// calibration share.
#pragma once

#include <string>

#include "gyrodrift/io/csv.h"

namespace gyrodrift::io {

// Reads a gyro log (CsvTable::Read) and, when it has a numeric time_s column, requires it to
// increase strictly: a time stamp that repeats or goes backwards is a DataError naming its row
// (the log was merged, sorted wrongly or its clock jumped; every model and the Allan analysis
// would otherwise take the samples as equally spaced, silently). Gaps and jitter stay a note
// (NonUniformTimeNote).
CsvTable ReadLog(const std::string& path);

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
