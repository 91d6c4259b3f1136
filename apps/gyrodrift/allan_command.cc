// gyrodrift allan: Allan-family deviation of one CSV column, with confidence intervals and the
// IEEE 952 noise terms.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <utility>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/tasks/allan_task.h"
#include "gyrodrift/tasks/task_log.h"

namespace gyrodrift::cli {
namespace {

namespace al = gyrodrift::allan;

struct AllanArgs {
  std::string input;
  std::string column;
  std::string output;
  tasks::AllanSettings settings;  // the defaults are the library's
  LogArgs log;                    // --gaps, --delimiter
  bool quiet = false;
  CLI::Option* rate_option = nullptr;  // not given: the rate is read from time_s
};

std::string Num(double v) { return std::isfinite(v) ? fmt::format("{:.4g}", v) : "-"; }

// Aligned noise-term table for the terminal.
std::string TermTable(const al::NoiseTerms& t, const std::string& source) {
  std::string s = fmt::format(
      "IEEE 952 noise terms ({} curve, fit in log variance, {} points {}..{} s, "
      "chi2/dof {}):\n",
      source, t.points_used, Num(t.tau_min_s), Num(t.tau_max_s), Num(t.chi2_per_dof));
  s += fmt::format("  {:<34} {:>24} {:>9}   {:>12} {:>12}\n", "term", "fitted", "evidence",
                   "slope method", "at tau [s]");
  struct Row {
    const char* name;
    const al::NoiseTerm* term;
  };
  const Row rows[] = {{"Q quantization [urad]", &t.q_urad},
                      {"N angle random walk [deg/sqrt(h)]", &t.n_dpsh},
                      {"B bias instability [deg/h]", &t.b_dph},
                      {"K rate random walk [deg/h/sqrt(h)]", &t.k_dphpsh},
                      {"R rate ramp [deg/h/h]", &t.r_dphph}};
  for (const auto& r : rows) {
    const std::string fitted = r.term->identified
                                   ? fmt::format("{:.4g} +- {:.2g}", r.term->value, r.term->sigma)
                                   : std::string("not identified");
    s += fmt::format("  {:<34} {:>24} {:>9}   {:>12} {:>12}\n", r.name, fitted,
                     Num(r.term->evidence_chi2), Num(r.term->slope_reading),
                     Num(r.term->slope_tau_s));
  }
  s += fmt::format(
      "  evidence: chi-square rise of the misfit without the term (the term is kept above {})\n",
      Num(t.critical_chi2));
  s += fmt::format("  curve minimum {} deg/h at tau {} s (B slope reading = minimum / 0.664)\n",
                   Num(t.min_dev_dph), Num(t.min_dev_tau_s));
  // The range flags cure a misfit over enough points; few points need a longer record.
  const bool misfit = t.chi2_per_dof > al::kMisfitNote && t.points_used > 5;
  if (!t.note.empty())
    s += "note: " + t.note + (misfit ? " (--fit-tau-min, --fit-tau-max)\n" : "\n");
  return s;
}

void Run(const AllanArgs& a) {
  RequireOutputsAreNotInputs({a.input}, {a.output, SidecarPath(a.output)});
  // Every option error before any file is read; without --rate-hz the rate, and what depends on
  // it (taus a whole number of samples), is checked once time_s gave it.
  const bool rate_given = a.rate_option->count() > 0;
  tasks::AllanSettings settings = a.settings;
  if (rate_given) settings.Validate();
  std::string rate_how = "given";

  // Only the analysed column is read as values (time_s as its steps, io::TimeAxis, unless they
  // show a gap or a fault); the column is moved out of the table before the analysis, which
  // builds the phase in the column's storage: at 1e8 samples it is 800 MB (docs/errors.md,
  // Memory). The note on the time axis is worked out while the table is there, printed at the
  // end.
  std::string notes, time_note, name;
  std::vector<bool> logged;
  Eigen::VectorXd data = [&] {
    std::vector<Eigen::Index> starts;
    io::CsvTable table = ReadLog(a.input, a.log, &notes, &starts, {a.column}, &logged);
    if (!a.quiet) time_note = NonUniformTimeNote(table);
    if (!rate_given) {
      settings.rate_hz = io::ResolveSampleRate(table, 0.0, &rate_how);
      if (rate_how != "time_s") {
        // A time_s column of one row gives no step either: that log is too short, not untimed.
        if (table.rows() < 2) {
          throw DataError(a.input + " has " + std::to_string(table.rows()) +
                          " data row: an Allan deviation needs at least 2 samples");
        }
        throw UsageError("--rate-hz is required: " + a.input +
                         " has no time_s column to read the sample rate from");
      }
      settings.Validate();
    }
    name = "column '" + ColumnName(table, a.column) + "'";
    Eigen::VectorXd column = table.TakeColumn(a.column);
    if (a.log.gaps == "carry" || starts.empty()) return column;
    return tasks::JoinRecords(column, starts, &logged);
  }();
  if (a.log.gaps == "interpolate") logged.clear();  // the made-up rows are analysed as data
  const tasks::AllanRun r = tasks::RunAllan(std::move(data), logged, settings, name);

  std::vector<io::CsvColumn> columns(5);
  const char* names[] = {"tau_s", "dev", "dev_lo", "dev_hi", "n_terms"};
  for (int c = 0; c < 5; ++c) {
    columns[c].name = names[c];
    columns[c].values.resize(static_cast<Eigen::Index>(r.curve.points.size()));
  }
  for (size_t i = 0; i < r.curve.points.size(); ++i) {
    const auto& p = r.curve.points[i];
    const Eigen::Index k = static_cast<Eigen::Index>(i);
    columns[0].values[k] = p.tau_s;
    columns[1].values[k] = p.dev;
    columns[2].values[k] = p.dev_lo;
    columns[3].values[k] = p.dev_hi;
    columns[4].values[k] = static_cast<double>(p.n_terms);
  }
  nlohmann::json sidecar = SidecarHeader("allan");
  sidecar.update(tasks::AllanRecord(r, settings, logged));
  sidecar["options"]["input"] = a.input;
  sidecar["options"]["column"] = a.column;
  sidecar["options"]["gaps"] = a.log.gaps;
  sidecar["options"]["rate_hz_from"] = rate_how;  // "given" (--rate-hz) or "time_s"
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (a.quiet) return;
  fmt::print("{}\n", r.curve.Summary());
  if (r.terms) {
    fmt::print("{}", TermTable(*r.terms, r.fit_source));
  } else {
    fmt::print("noise terms not fitted: {}\n", r.fit_error);
  }
  if (!time_note.empty()) notes += time_note + "\n";
  fmt::print("{}", notes);
  if (!rate_given) {
    fmt::print("sample rate: {} Hz ({})\n", settings.rate_hz,
               tasks::RateSourceText(rate_how, /*flags=*/true));
  }
  fmt::print("wrote {} and {}\n", a.output, SidecarPath(a.output));
}

const RegisterCommand kRegister("allan", 40, [](CLI::App& app) {
  auto args = std::make_shared<AllanArgs>();
  CLI::App* cmd = app.add_subcommand(
      "allan", "Allan-family deviations with confidence intervals and IEEE 952 noise terms.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift simulate --duration 8h -o fog.csv\n"
      "  gyrodrift allan fog.csv --column rate_dph --rate-hz 1 --taus octave -o adev.csv\n"
      "writes adev.csv (tau_s,dev,dev_lo,dev_hi,n_terms; 68.3 % bounds from the equivalent\n"
      "degrees of freedom of the identified noise type) and adev.csv.json (options, every point\n"
      "with its EDF and noise type, the fitted terms), and prints the noise-term table:\n"
      "Q [urad], N [deg/sqrt(h)], B [deg/h], K [deg/h/sqrt(h)], R [deg/h/h], fitted by weighted\n"
      "non-negative least squares on sigma^2 = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3\n"
      "+ R^2 tau^2/2, beside the IEEE 952 slope-method readings.\n"
      "Angle input (--type angle) is in degrees (radians with --units rads).\n"
      "  gyrodrift allan imu.csv -c 2 --rate-hz 100 --units dps --dev mdev --taus 0.1,1,10 -o "
      "m.csv");
  cmd->add_option("input", args->input, "CSV file with a header row")
      ->required()
      ->check(kInputFile);
  cmd->add_option("--column,-c", args->column, "column name or 1-based index")->required();
  args->rate_option = BindSetting(
      cmd->add_option(
          "--rate-hz", args->settings.rate_hz,
          "sample rate in Hz (tau0 = 1 / rate); not given: 1 / the mean step of the "
          "time_s column (its steps within 1 % of the median; a log without one needs it)"),
      {"rate_hz"});
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(
      cmd->add_option("--type", args->settings.type, "rate (gyro output) | angle (integrated)")
          ->capture_default_str(),
      {"type", "data_type"});
  BindSetting(cmd->add_option("--dev", args->settings.dev, "oadev|adev|mdev|hdev|ohdev|tdev|totdev")
                  ->capture_default_str(),
              {"dev", "deviation"});
  BindSetting(cmd->add_option("--taus", args->settings.taus,
                              "all | octave | decade | comma-separated taus in s")
                  ->capture_default_str(),
              {"taus", "tau_list_s"});
  BindSetting(cmd->add_option("--units", args->settings.units,
                              "rate unit: dph (deg/h) | dps (deg/s) | rads (rad/s)")
                  ->capture_default_str(),
              {"units"});
  BindSetting(cmd->add_option("--confidence", args->settings.confidence,
                              "two-sided confidence of the bounds, in (0, 1 - 1e-12]")
                  ->capture_default_str(),
              {"confidence"});
  BindSetting(
      cmd->add_option("--threads,-j", args->settings.threads, "worker threads (0 = all cores)")
          ->capture_default_str(),
      {"threads"});
  BindSetting(
      cmd->add_option("--fit-tau-min", args->settings.fit_tau_min_s, "noise fit: smallest tau in s")
          ->capture_default_str(),
      {"fit_tau_min"});
  BindSetting(
      cmd->add_option("--fit-tau-max", args->settings.fit_tau_max_s, "noise fit: largest tau in s"),
      {"fit_tau_max"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
