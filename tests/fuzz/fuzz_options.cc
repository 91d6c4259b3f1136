// libFuzzer harness: the CLI's option parsers on any text: durations, tau lists, method lists,
// temperature column lists, gap policies and delimiters, and the drift settings' one mapping
// (drift::MakeDriftOptions) with the text split at '|' into its string settings. Each accepts or
// throws a gyrodrift::Error (a usage error naming the option); nothing else may happen.
#include <cstddef>
#include <cstdint>
#include <string>

#include "cli_util.h"
#include "drift_cli.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/fit_settings.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/gyro_log.h"
#include "gyrodrift/tasks/allan_task.h"
#include "gyrodrift/tasks/evaluate_task.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace cli = gyrodrift::cli;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)cli::ParseDuration(text);
  } catch (const gyrodrift::Error&) {
  }
  try {
    // The tau list as `gyrodrift allan --taus` and Python's allan read it (the task layer).
    (void)gyrodrift::tasks::AllanSettings{.rate_hz = 1.0, .taus = text}.Options();
  } catch (const gyrodrift::Error&) {
  }
  for (auto mode : {gyrodrift::drift::Mode::kPredict, gyrodrift::drift::Mode::kCompensate}) {
    try {
      (void)gyrodrift::tasks::ParseMethods(text, mode, "--methods");
    } catch (const gyrodrift::Error&) {
    }
  }
  try {
    static const gyrodrift::io::CsvTable table = gyrodrift::io::CsvTable::Parse(
        "time_s,temperature_c,board_c\n0,20,21\n1,20.5,21.2\n", "log");
    (void)cli::ReadColumns(table, text, "--temperature");
  } catch (const gyrodrift::Error&) {
  }
  try {
    (void)gyrodrift::io::GapPolicyFromString(text);
  } catch (const gyrodrift::Error&) {
  }
  try {
    (void)gyrodrift::io::DelimiterFromString(text);
  } catch (const gyrodrift::Error&) {
  }
  try {
    // "mode|method|decomposition|lags|hidden|thermal_features|hysteresis", missing parts empty.
    std::string part[7];
    for (size_t i = 0, k = 0; i < text.size() && k < 7; ++i) {
      if (text[i] == '|') {
        ++k;
      } else {
        part[k] += text[i];
      }
    }
    gyrodrift::drift::FitSettings s{.mode = part[0],
                                    .method = part[1],
                                    .decomposition = part[2],
                                    .lags = part[3],
                                    .hidden = part[4],
                                    .thermal_features = part[5],
                                    .hysteresis = part[6],
                                    .has_temperature = !part[6].empty()};
    (void)gyrodrift::drift::MakeDriftOptions(s);
  } catch (const gyrodrift::Error&) {
  }
  return 0;
}
