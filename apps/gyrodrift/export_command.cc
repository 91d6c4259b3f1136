// gyrodrift export: compensate-mode models as a C99 header for firmware, their coefficients as
// plain JSON, or PX4's thermal-compensation parameters (firmware/export.h does the work).
#include <fmt/core.h>

#include <memory>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/firmware/export.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::cli {
namespace {

struct ExportArgs {
  std::vector<std::string> models;
  std::string output;
  std::string format = "c";
  std::string prefix = "gyro_comp";
  bool single_precision = false;
  std::vector<std::uint32_t> device_ids;
  bool quiet = false;
};

void Run(const ExportArgs& a) {
  RequireOutputsAreNotInputs(a.models, {a.output});
  const firmware::ExportOptions options{.format = firmware::ExportFormatFromString(a.format),
                                        .single_precision = a.single_precision,
                                        .prefix = a.prefix,
                                        .device_ids = a.device_ids};
  const firmware::ExportResult exported = firmware::ExportModelFiles(a.models, options);
  const std::vector<io::LoadedModel>& axes = exported.axes;
  io::WriteFileAtomically(a.output, exported.text);
  if (a.quiet) return;
  // A model the calibration run could not identify says so wherever it is used (as compensate
  // does); nearly collinear regressors also amplify the header's rounding (docs/firmware.md).
  std::string warnings;
  for (const io::LoadedModel& axis : axes) {
    const std::string whose = axes.size() == 1 ? "" : axis.info.target_column + ": ";
    for (const auto& sub : axis.model.sub_models) {
      if (!sub.thermal) continue;
      for (const std::string& w : sub.thermal->report.warnings) {
        warnings += "warning: " + whose + "the model's calibration run (" + sub.name + "): " + w +
                    "\n";
      }
    }
  }
  if (options.format == firmware::ExportFormat::kPx4Params) {
    std::string forms;
    for (const firmware::Px4AxisForm& f : exported.px4_forms) {
      forms += fmt::format("  {}: {}\n", f.label, f.form.Summary());
    }
    fmt::print("px4: {} gyro{}, the autopilot form of each axis (fitted with the model):\n{}{}"
               "wrote {}\n",
               a.device_ids.size(), a.device_ids.size() == 1 ? "" : "s", forms, warnings,
               a.output);
    return;
  }
  fmt::print("{}\n{}: {}{}\n{}wrote {}\n", axes[0].model.Summary(), firmware::ToString(options.format),
             firmware::SummariseExport(axes).Line(),
             options.format == firmware::ExportFormat::kC
                 ? fmt::format(", {}, prefix {}", a.single_precision ? "float" : "double", a.prefix)
                 : std::string(),
             warnings, a.output);
}

const RegisterCommand kRegister("export", 75, [](CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Write a compensate-mode model as a C99 header for firmware, or its coefficients.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift fit cal.csv --target rate_dph --temperature temperature_c --mode compensate \\\n"
      "      -o model.json\n"
      "  gyrodrift export model.json --format c -o gyro_comp.h\n"
      "  gyrodrift export model.json --format json-coefficients -o coefficients.json\n"
      "  gyrodrift export imu0.json imu1.json --format px4 --device-id 2490378,2621450 -o tc.params\n"
      "gyro_comp.h is dependency-free C99 (no allocation, no libm): a state struct,\n"
      "gyro_comp_init(&s, t) once with the first temperature(s), gyro_comp_step(&s, t, drift)\n"
      "at every sample at the calibration's sample rate; drift[] is what 'gyrodrift compensate'\n"
      "writes as drift_est. Exports models fitted with --method thermal, ms-elm or emd-elm in\n"
      "compensate mode without --nonlinear; others are refused. px4 writes the parameters of\n"
      "PX4's thermal compensation (TC_G*) from the cubic in temperature fitted beside each\n"
      "axis' model, and says how much of the full model's removal it keeps. See docs/firmware.md.");
  cmd->add_option("model", args->models,
                  "model file(s) written by 'gyrodrift fit --mode compensate' (their axes in "
                  "order; for px4 one file per gyro, its axes x, y, z)")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "file to write (C header or JSON)")->required();
  BindSetting(
      cmd->add_option("--format,-f", args->format, "c|json-coefficients|px4")->capture_default_str(),
      {"format"});
  BindSetting(
      cmd->add_option("--prefix", args->prefix,
                      "C: prefix of every identifier (a C identifier, at most 32 characters)")
          ->capture_default_str(),
      {"prefix"});
  BindSetting(
      cmd->add_flag("--float", args->single_precision,
                    "C: float arithmetic instead of double (FPUs without double precision)"),
      {"single_precision"});
  BindSetting(AddListOption(cmd, "--device-id", &args->device_ids,
                            "px4: each gyro's DEVID, comma-separated, one per model file "
                            "(convert --list shows sensor_gyro's device_id)"),
              {"device_ids"});
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
