// gyrodrift convert: a PX4 ULog's gyro series as CSV logs the other commands read.
#include <fmt/core.h>

#include <filesystem>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/ulog.h"

namespace gyrodrift::cli {
namespace {

struct ConvertArgs {
  std::string input;
  bool list = false;
  std::string instance = "0";
  std::string units = "dph";
  io::UlogConversion conversion;
  std::string output;
  bool quiet = false;
};

// OUT.csv for one instance; OUT_<i>.csv each with --instance all.
std::string InstancePath(const std::string& output, int instance, bool all) {
  if (!all) return output;
  const std::filesystem::path p(output);
  return (p.parent_path() / (p.stem().string() + "_" + std::to_string(instance) +
                             p.extension().string()))
      .string();
}

void Run(ConvertArgs& a) {
  a.conversion.units = allan::RateUnitFromString(a.units);
  if (a.list) {
    // The topic asked for is decoded, for its sensors' ids.
    const io::Ulog log = io::ReadUlog(a.input, {a.conversion.topic});
    fmt::print("{}", io::DescribeUlog(log));
    for (const std::string& w : log.warnings) fmt::print(stderr, "warning: {}\n", w);
    return;
  }
  if (a.output.empty()) throw UsageError("convert: -o/--output is required (or --list)");
  const bool all = a.instance == "all";
  int instance = 0;
  if (!all) {
    try {
      std::size_t used = 0;
      instance = std::stoi(a.instance, &used);
      if (used != a.instance.size() || instance < 0 || instance > io::kMaxUlogInstance)
        throw std::out_of_range("");
    } catch (const std::logic_error&) {
      throw OptionError("--instance", a.instance,
                        fmt::format("an integer in [0, {}] or all", io::kMaxUlogInstance));
    }
  }
  const io::Ulog log = io::ReadUlog(a.input, {a.conversion.topic});
  for (const std::string& w : log.warnings) fmt::print(stderr, "warning: {}\n", w);
  const std::vector<const io::UlogSeries*> chosen =
      io::SeriesWithSamples(log, a.input, a.conversion.topic, all ? -1 : instance);
  std::vector<std::pair<std::string, std::string>> files;
  std::vector<std::string> outputs;
  for (const io::UlogSeries* s : chosen) {
    outputs.push_back(InstancePath(a.output, s->instance, all));
    files.emplace_back(outputs.back(), io::RenderCsv(io::UlogColumns(*s, a.conversion)));
  }
  RequireOutputsAreNotInputs({a.input}, outputs);
  io::WriteFilesAtomically(files);
  if (a.quiet) return;
  for (size_t i = 0; i < chosen.size(); ++i) {
    const io::UlogSeries& s = *chosen[i];
    fmt::print("{} instance {}: {} samples over {:.1f} s -> {}\n", s.topic, s.instance, s.samples,
               1e-6 * static_cast<double>(s.last_us - s.first_us), outputs[i]);
  }
}

const RegisterCommand kRegister("convert", 9, [](CLI::App& app) {
  auto a = std::make_shared<ConvertArgs>();
  CLI::App* cmd = app.add_subcommand(
      "convert", "Convert a PX4 ULog's gyro series to CSV logs the other commands read.");
  cmd->add_option("input", a->input, "ULog file (.ulg)")->required()->check(kInputFile);
  cmd->add_flag("--list", a->list,
                "print the log's series (topic, instance, samples, duration, rate, fields) and the "
                "device_id of each instance of --topic, and stop");
  cmd->add_option("--topic", a->conversion.topic, "topic to convert")->capture_default_str();
  cmd->add_option("--instance", a->instance,
                  "multi-instance id, or all (one file per instance: OUT_<id>.csv)")
      ->capture_default_str();
  AddListOption(cmd, "--axes", &a->conversion.axes, "the rate fields, rad/s, comma-separated");
  cmd->add_option("--temperature-field", a->conversion.temperature,
                  "the temperature field, degC (empty: none)")
      ->capture_default_str();
  cmd->add_option("--units", a->units, "unit of the rate columns written: dph | dps | rads")
      ->check(CLI::IsMember({"dph", "dps", "rads"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", a->output, "CSV file to write (time_s, <axis>_<units>, temperature_c)");
  cmd->add_flag("-q,--quiet", a->quiet, "print nothing on success");
  cmd->footer(
      "Example:\n"
      "  gyrodrift convert flight.ulg --list\n"
      "  gyrodrift convert flight.ulg --topic sensor_gyro --instance all -o gyro.csv\n"
      "  gyrodrift fit gyro_0.csv -t x_dph,y_dph,z_dph -T temperature_c --mode compensate -o m.json\n"
      "Damaged or cut logs: what precedes the damage is read, with a warning naming the bytes "
      "skipped (docs/ulog.md).");
  cmd->callback([a] { Run(*a); });
});

}  // namespace
}  // namespace gyrodrift::cli
