// gyrodrift export: a compensate-mode model as a C99 header for firmware, or its coefficients as
// plain JSON (io/firmware_export.h does the work).
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
  std::string model;
  std::string output;
  std::string format = "c";
  std::string prefix = "gyro_comp";
  bool single_precision = false;
  bool quiet = false;
};

void Run(const ExportArgs& a) {
  RequireOutputsAreNotInputs({a.model}, {a.output});
  const firmware::ExportOptions options{.format = firmware::ExportFormatFromString(a.format),
                                  .single_precision = a.single_precision,
                                  .prefix = a.prefix};
  options.Validate();
  // One axis per model file for now; the library takes one model per gyro axis.
  const std::vector<io::LoadedModel> axes = io::ReadModelFileAxes(a.model);
  const std::string text = firmware::RenderExport(axes, options);
  io::WriteFileAtomically(a.output, text);
  if (a.quiet) return;
  // A model the calibration run could not identify says so wherever it is used (as compensate
  // does); nearly collinear regressors also amplify the header's rounding (docs/firmware.md).
  std::string warnings;
  for (const auto& sub : axes[0].model.sub_models) {
    if (!sub.thermal) continue;
    for (const std::string& w : sub.thermal->report.warnings) {
      warnings += "warning: the model's calibration run (" + sub.name + "): " + w + "\n";
    }
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
      "gyro_comp.h is dependency-free C99 (no allocation, no libm): a state struct,\n"
      "gyro_comp_init(&s, t) once with the first temperature(s), gyro_comp_step(&s, t, drift)\n"
      "at every sample at the calibration's sample rate; drift[] is what 'gyrodrift compensate'\n"
      "writes as drift_est. Exports models fitted with --method thermal, ms-elm or emd-elm in\n"
      "compensate mode without --nonlinear; others are refused. See docs/firmware.md.");
  cmd->add_option("model", args->model, "model file written by 'gyrodrift fit --mode compensate'")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "file to write (C header or JSON)")->required();
  BindSetting(
      cmd->add_option("--format,-f", args->format, "c|json-coefficients")->capture_default_str(),
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
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
