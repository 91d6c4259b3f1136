#include "gyrodrift/tasks/simulate_task.h"

#include <filesystem>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"

namespace gyrodrift::tasks {

simulation::TemperatureProgramme LoadProgramme(const std::string& profile,
                                               std::string_view setting) {
  for (const auto& name : simulation::BuiltinProgrammeNames()) {
    if (profile == name) return simulation::BuiltinProgramme(name);
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(profile, ec)) {
    throw UsageError(std::string(setting) + " = " + profile +
                     ": must be chamber, chamber-b, sine or an existing CSV file");
  }
  const io::CsvTable table = io::CsvTable::Read(profile);
  for (const char* column : {"time_s", "temperature_c"}) {
    if (!table.HasColumn(column)) {
      throw DataError(profile + ": no column '" + column +
                      "' (a profile CSV needs time_s and temperature_c)");
    }
  }
  return simulation::TemperatureProgramme::FromSamples(table.Column("time_s"),
                                                       table.Column("temperature_c"), profile);
}

}  // namespace gyrodrift::tasks
