// gyrodrift decompose: the EMD family on one column of a CSV file.
#include <fmt/core.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/tasks/decompose_task.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

namespace dec = gyrodrift::decomposition;

struct DecomposeArgs {
  std::string input;
  std::string column;
  std::string output;
  tasks::DecomposeSettings settings;  // the defaults are the library's
  std::string noise_file;
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

void Run(const DecomposeArgs& a) {
  RequireOutputsAreNotInputs({a.input, a.noise_file}, {a.output, SidecarPath(a.output)});
  const tasks::DecomposeSettings& settings = a.settings;
  settings.Validate();  // option errors before any file is read
  const dec::Method method = settings.Options().method;

  // Only the column (and time_s) is read, and the table is dropped once the column is out.
  a.log.RequireOneRecord("decompose", "a decomposition runs across the gaps");
  std::string notes, name;
  const Eigen::VectorXd x = [&] {
    io::CsvTable table = ReadLog(a.input, a.log, &notes, nullptr, {a.column});
    name = "column '" + ColumnName(table, a.column) + "'";
    Eigen::VectorXd column = table.TakeColumn(a.column);
    tasks::RequireDecomposable(column, name);  // before a noise file is read
    return column;
  }();
  Eigen::MatrixXd noise;  // --noise-file: one realisation per column
  const std::string noise_name = "--noise-file = " + a.noise_file;
  if (!a.noise_file.empty()) {
    tasks::RequireNoiseTaken(settings, noise_name);
    const io::CsvTable table = io::CsvTable::Read(a.noise_file);
    noise.resize(table.rows(), static_cast<Eigen::Index>(table.header().size()));
    for (int c = 0; c < static_cast<int>(table.header().size()); ++c)
      noise.col(c) = table.Column(c);
  }
  dec::Decomposition d;
  {
    ProgressBar progress({1.0}, IsTerminal() && !a.quiet && method != dec::Method::kEmd);
    progress.BeginStage(0, std::string(dec::ToString(method)));
    d = tasks::RunDecompose(
        x, settings, noise,
        [&progress](double fraction, std::string_view) { progress.Update(fraction); }, noise_name,
        name);
  }

  // Streamed from the decomposition itself: the text of 1e7 samples is gigabytes.
  std::vector<io::CsvColumnView> columns;
  for (int k = 0; k < d.num_imfs(); ++k) {
    columns.push_back({"imf" + std::to_string(k + 1), d.imfs.col(k).data(), d.imfs.rows()});
  }
  columns.push_back({"residue", d.residue.data(), d.residue.size()});
  nlohmann::json sidecar = SidecarHeader("decompose");
  sidecar["options"] = tasks::DecomposeOptionsRecord(settings, noise.cols());
  sidecar["options"]["input"] = a.input;
  sidecar["options"]["column"] = a.column;
  sidecar["options"]["noise_file"] = a.noise_file;
  sidecar["samples"] = x.size();
  sidecar["report"] = tasks::DecomposeReportRecord(d);
  const std::string sidecar_text = sidecar.dump(2) + "\n";
  io::WriteStreamedFilesAtomically(
      {{a.output, [&](std::FILE* out) { io::WriteCsvTo(out, columns); }},
       {SidecarPath(a.output),
        [&](std::FILE* out) { std::fwrite(sidecar_text.data(), 1, sidecar_text.size(), out); }}});
  if (!a.quiet)
    fmt::print("{}{}\nwrote {} and {}\n", notes, d.report.Summary(), a.output,
               SidecarPath(a.output));
}

constexpr const char* kFooter =
    "Example:\n"
    "  gyrodrift simulate --duration 2h -o fog.csv\n"
    "  gyrodrift decompose fog.csv --column rate_dph --method beemdan --seed 7 -o imfs.csv\n"
    "writes imfs.csv (imf1..imfK,residue; one row per input sample) and imfs.csv.json (every\n"
    "option, the seed and the report: sifts per IMF, noise-assisted stages and why they ended).\n"
    "Defaults follow Rilling & Flandrin's emd.m (stop 0.05/0.5/0.05, 2000 sifts) and\n"
    "Colominas et al. 2014 (eps 0.2); libeemd's rule is --stop snumber (S = 4, 50 sifts).";

const RegisterCommand kRegister("decompose", 20, [](CLI::App& app) {
  auto args = std::make_shared<DecomposeArgs>();
  CLI::App* cmd = app.add_subcommand(
      "decompose", "Split a signal into IMFs + residue (EMD, EEMD, CEEMDAN, ICEEMDAN, BEEMDAN).");
  cmd->footer(kFooter);
  cmd->add_option("input", args->input, "CSV file with a header row")
      ->required()
      ->check(kInputFile);
  cmd->add_option("--column,-c", args->column, "column name or 1-based index")->required();
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(
      cmd->add_option("--method,-m", args->settings.method, "emd|eemd|ceemdan|iceemdan|beemdan")
          ->capture_default_str(),
      {"method"});
  BindSetting(
      cmd->add_option("--stop", args->settings.stop, "sifting stop rule: rilling|snumber|fixed|sd")
          ->capture_default_str(),
      {"stop"});
  BindSetting(cmd->add_option("--max-sifts", args->settings.max_sifts,
                              "sift cap per IMF (0 = rule default: 2000 rilling/sd, 50 snumber)")
                  ->capture_default_str(),
              {"max_sifts"});
  BindSetting(cmd->add_option("--s-number", args->settings.s_number, "S of the S-number rule")
                  ->capture_default_str(),
              {"s_number"});
  BindSetting(
      cmd->add_option("--fixed-sifts", args->settings.fixed_sifts, "sifts per IMF for --stop fixed")
          ->capture_default_str(),
      {"fixed_sifts"});
  BindSetting(cmd->add_option("--sd", args->settings.sd, "Cauchy SD threshold for --stop sd")
                  ->capture_default_str(),
              {"sd"});
  BindSetting(cmd->add_option("--max-imfs", args->settings.max_imfs,
                              "IMF cap (0 = until the residue is monotone)")
                  ->capture_default_str(),
              {"max_imfs"});
  BindSetting(cmd->add_option("--ensemble,-I", args->settings.ensemble,
                              "ensemble size (noise-assisted methods)")
                  ->capture_default_str(),
              {"ensemble"});
  BindSetting(cmd->add_option("--noise", args->settings.noise,
                              "noise strength eps (relative to the signal's std)")
                  ->capture_default_str(),
              {"noise"});
  cmd->add_option("--seed", args->settings.seed, "seed; realisation i uses stream (seed, i)")
      ->check(kSeed)
      ->capture_default_str();
  BindSetting(
      cmd->add_option("--threads,-j", args->settings.threads, "worker threads (0 = all cores)")
          ->capture_default_str(),
      {"threads"});
  BindSetting(cmd->add_option("--noise-scaling", args->settings.noise_scaling,
                              "ICEEMDAN/BEEMDAN noise scaling: colominas2014|constant-snr")
                  ->capture_default_str(),
              {"noise_scaling"});
  BindSetting(
      cmd->add_option("--bound", args->settings.bound,
                      "BEEMDAN noise bound: ensemble (band of the ensemble's white-noise modes) | "
                      "energy (Flandrin et al.'s band) | stages | full (= ICEEMDAN)")
          ->capture_default_str(),
      {"bound"});
  BindSetting(
      cmd->add_option("--band", args->settings.band, "BEEMDAN band confidence: 0.95 or 0.99")
          ->capture_default_str(),
      {"band"});
  BindSetting(cmd->add_option("--noise-stages", args->settings.noise_stages,
                              "BEEMDAN stages with --bound stages")
                  ->capture_default_str(),
              {"noise_stages"});
  cmd->add_option("--noise-file", args->noise_file,
                  "CSV of white-noise realisations (one per column) to use instead of drawing")
      ->check(kInputFile);
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
