// The temperature programme of the `simulate` user operation, for every front end: a built-in
// programme by name, or a chamber programme recorded as a CSV file. `gyrodrift simulate --profile`
// and the Python package's simulate(profile=...) read it here.
#pragma once

#include <string>
#include <string_view>

#include "gyrodrift/simulation/temperature_programme.h"

namespace gyrodrift::tasks {

// The built-in programme `profile` (chamber, chamber-b, sine), else the CSV file of that path with
// columns time_s and temperature_c (TemperatureProgramme::FromSamples). UsageError naming
// `setting` (--profile, profile) for neither; DataError for a file without those columns or with
// bad samples; IoError for a file that cannot be read.
simulation::TemperatureProgramme LoadProgramme(const std::string& profile,
                                               std::string_view setting);

}  // namespace gyrodrift::tasks
