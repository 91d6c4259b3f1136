// gyrodrift allan: Allan-family deviation of one CSV column, with confidence intervals and the
// IEEE 952 noise terms.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::cli {
namespace {

namespace al = gyrodrift::allan;

struct AllanArgs {
  std::string input;
  std::string column;
  std::string output;
  double rate_hz = 0.0;
  std::string type = "rate";
  std::string dev = "oadev";
  std::string taus = "octave";
  std::string units = "dph";
  double confidence = 0.683;
  int threads = 0;
  double fit_tau_min_s = 0.0;
  double fit_tau_max_s = INFINITY;
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

nlohmann::json TermJson(const al::NoiseTerm& t, const char* unit) {
  return {{"unit", unit},
          {"identified", t.identified},
          {"value", t.value},
          {"sigma", t.sigma},
          {"tau_lo_s", t.tau_lo_s},
          {"tau_hi_s", t.tau_hi_s},
          {"slope_reading", t.slope_reading},
          {"slope_tau_s", t.slope_tau_s},
          {"evidence_chi2", t.evidence_chi2}};
}

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
  return s;
}

void Run(const AllanArgs& a) {
  RequireOutputsAreNotInputs({a.input}, {a.output, SidecarPath(a.output)});
  // Beyond this range the averages under- or overflow (1e308 Hz gave all-zero deviations).
  RequireInRange("--rate-hz", a.rate_hz, 1e-9, 1e9);
  al::AllanOptions o;
  o.rate_hz = a.rate_hz;
  o.data_type = al::DataTypeFromString(a.type);
  o.deviation = al::DeviationFromString(a.dev);
  o.units = al::RateUnitFromString(a.units);
  o.confidence = a.confidence;
  ParseTaus(a.taus, &o);
  for (double tau : o.tau_list_s) {
    // Averages span whole samples: a tau between two is not silently moved to the nearer one.
    const double m = tau * a.rate_hz;
    // Absolute in samples (a relative test would let half a sample through at large factors),
    // loose enough for decimal taus such as 0.1 s at 10 Hz.
    if (m < 1.0 - 1e-9 || std::abs(m - std::round(m)) > 1e-6 + 1e-12 * m) {
      ThrowOption("--taus", fmt::format("{:g}", tau),
                  fmt::format("a whole number of sample periods at {:g} Hz (nearest: {:g} s)",
                              a.rate_hz, std::max(1.0, std::round(m)) / a.rate_hz));
    }
  }
  o.Validate();
  const Execution execution{.threads = a.threads};
  execution.Validate();
  const al::NoiseFitOptions fit_options{.tau_min_s = a.fit_tau_min_s, .tau_max_s = a.fit_tau_max_s};
  fit_options.Validate();  // every option error before any file is read

  // Only the analysed column and time_s are read; the column is moved out of the table, and
  // time_s is dropped with the table before the analysis, which builds the phase in the column's
  // storage: at 1e8 samples each is 800 MB (docs/errors.md, Memory). The note on the time axis is
  // worked out while time_s is there, and printed at the end.
  std::string notes, time_note;
  // A log with gaps (--gaps split or carry) is analysed on its time grid with the gaps as
  // missing samples (allan::ComputeWithGaps): carry marks the rows it made up, and split's records
  // are joined with one missing sample between them, so no cluster pair spans a break.
  std::vector<bool> logged;
  Eigen::VectorXd data = [&] {
    std::vector<Eigen::Index> starts;
    io::CsvTable table = ReadLog(a.input, a.log, &notes, &starts, {a.column}, &logged);
    if (!a.quiet) time_note = NonUniformTimeNote(table);
    Eigen::VectorXd column = table.TakeColumn(a.column);
    RequireVaryingSignal("column '" + ColumnName(table, a.column) + "'", column,
                         "its Allan deviation is zero at every tau (a logging fault?)");
    if (a.log.gaps == "carry" || starts.empty()) return column;
    Eigen::VectorXd joined(column.size() + static_cast<Eigen::Index>(starts.size()));
    logged.assign(static_cast<size_t>(joined.size()), true);
    Eigen::Index from = 0, to = 0;
    for (size_t r = 0; r <= starts.size(); ++r) {
      const Eigen::Index end = r < starts.size() ? starts[r] : column.size();
      joined.segment(to, end - from) = column.segment(from, end - from);
      to += end - from;
      if (r < starts.size()) {
        joined[to] = 0.0;  // never read: a break between records
        logged[static_cast<size_t>(to++)] = false;
      }
      from = end;
    }
    return joined;
  }();
  if (a.log.gaps == "interpolate") logged.clear();  // the made-up rows are analysed as data
  // Noise terms need an Allan-variance curve; for the other estimators fit an OADEV on the same
  // grid.
  const bool allan_curve = o.deviation == al::Deviation::kAdev ||
                           o.deviation == al::Deviation::kOadev ||
                           o.deviation == al::Deviation::kTotdev;
  // The record's last use hands it over: the phase is built in its storage (no second copy).
  auto compute = [&](const al::AllanOptions& options, bool last_use) {
    if (!logged.empty()) return al::ComputeWithGaps(data, logged, options, execution);
    return last_use ? al::Compute(std::move(data), options, execution)
                    : al::Compute(data, options, execution);
  };
  const al::AllanResult r = compute(o, allan_curve);
  std::string fit_source = al::ToString(o.deviation);
  std::optional<al::NoiseTerms> terms;
  std::string fit_error;
  try {
    if (allan_curve) {
      terms = al::IdentifyNoise(r, fit_options);
    } else {
      al::AllanOptions oa = o;
      oa.deviation = al::Deviation::kOadev;
      fit_source = "oadev";
      terms = al::IdentifyNoise(compute(oa, true), fit_options);
    }
  } catch (const DataError& e) {
    fit_error = e.what();  // too few points to fit: the deviations are still the result
  }

  std::vector<io::CsvColumn> columns(5);
  const char* names[] = {"tau_s", "dev", "dev_lo", "dev_hi", "n_terms"};
  for (int c = 0; c < 5; ++c) {
    columns[c].name = names[c];
    columns[c].values.resize(static_cast<Eigen::Index>(r.points.size()));
  }
  nlohmann::json points = nlohmann::json::array();
  for (size_t i = 0; i < r.points.size(); ++i) {
    const auto& p = r.points[i];
    const Eigen::Index k = static_cast<Eigen::Index>(i);
    columns[0].values[k] = p.tau_s;
    columns[1].values[k] = p.dev;
    columns[2].values[k] = p.dev_lo;
    columns[3].values[k] = p.dev_hi;
    columns[4].values[k] = static_cast<double>(p.n_terms);
    points.push_back({{"tau_s", p.tau_s},
                      {"m", p.m},
                      {"dev", p.dev},
                      {"dev_lo", p.dev_lo},
                      {"dev_hi", p.dev_hi},
                      {"n_terms", p.n_terms},
                      {"edf", p.edf},
                      {"alpha", p.alpha},
                      {"noise_type", al::NoiseTypeName(p.alpha)},
                      {"alpha_identified", p.alpha_identified}});
  }
  nlohmann::json sidecar = SidecarHeader("allan");
  sidecar["options"] = {
      {"input", a.input},
      {"column", a.column},
      {"rate_hz", o.rate_hz},
      {"tau0_s", o.tau0_s()},
      {"type", al::ToString(o.data_type)},
      {"dev", al::ToString(o.deviation)},
      {"taus", a.taus},
      {"tau_grid", al::ToString(o.grid)},
      {"tau_list_s", o.tau_list_s},
      {"units", al::ToString(o.units)},
      {"confidence", o.confidence},
      {"threads", a.threads},
      {"fit_tau_min_s", fit_options.tau_min_s},
      {"fit_tau_max_s", std::isfinite(fit_options.tau_max_s) ? nlohmann::json(fit_options.tau_max_s)
                                                             : nlohmann::json("inf")},
      {"seed", nullptr}};
  sidecar["samples"] = r.n_samples;
  sidecar["options"]["gaps"] = a.log.gaps;
  // The analysed grid: with gaps skipped, how many of its samples were logged.
  if (!logged.empty()) {
    sidecar["logged_samples"] = std::count(logged.begin(), logged.end(), true);
    sidecar["gaps_method"] =
        "overlapping estimator over the cluster pairs whose samples are all logged (made-up "
        "samples and record breaks skipped); EDF of a gap-free record with as many terms";
  }
  sidecar["summary"] = r.Summary();
  sidecar["dev_unit"] = al::ToString(o.units) + (o.deviation == al::Deviation::kTdev ? "*s" : "");
  sidecar["edf_method"] =
      "Greenhall & Riley 2003 (TOTDEV: NIST SP 1065 table 7); noise type per tau by lag-1 "
      "autocorrelation, carried forward below 30 points";
  sidecar["points"] = points;
  if (terms) {
    sidecar["noise_terms"] = {
        {"source_dev", fit_source},
        {"method",
         "IEEE 952 model fitted in log variance (weights from the EDF); terms removed steepest "
         "first (R, Q, K, N, B) while a nested chi-square test at the significance level, "
         "corrected for the correlated overlapping points, finds them unnecessary, or while they "
         "stay below 10 % of the model at every tau; uncertainties from the correlated points "
         "(docs/allan.md)"},
        {"critical_chi2", terms->critical_chi2},
        {"points_used", terms->points_used},
        {"tau_min_s", terms->tau_min_s},
        {"tau_max_s", terms->tau_max_s},
        {"chi2_per_dof", terms->chi2_per_dof},
        {"min_dev_dph", terms->min_dev_dph},
        {"min_dev_tau_s", terms->min_dev_tau_s},
        {"Q", TermJson(terms->q_urad, "urad")},
        {"Q_arcsec", terms->q_urad.value * 0.206264806247},
        {"N", TermJson(terms->n_dpsh, "deg/sqrt(h)")},
        {"B", TermJson(terms->b_dph, "deg/h")},
        {"K", TermJson(terms->k_dphpsh, "deg/h/sqrt(h)")},
        {"R", TermJson(terms->r_dphph, "deg/h/h")},
        {"summary", terms->Summary()}};
  } else {
    sidecar["noise_terms"] = {{"error", fit_error}};
  }
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (a.quiet) return;
  fmt::print("{}\n", r.Summary());
  if (terms) {
    fmt::print("{}", TermTable(*terms, fit_source));
  } else {
    fmt::print("noise terms not fitted: {}\n", fit_error);
  }
  if (!time_note.empty()) notes += time_note + "\n";
  fmt::print("{}", notes);
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
  BindSetting(cmd->add_option("--rate-hz", args->rate_hz, "sample rate in Hz (tau0 = 1 / rate)")
                  ->required(),
              {"rate_hz"});
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(cmd->add_option("--type", args->type, "rate (gyro output) | angle (integrated)")
                  ->capture_default_str(),
              {"type", "data_type"});
  BindSetting(cmd->add_option("--dev", args->dev, "oadev|adev|mdev|hdev|ohdev|tdev|totdev")
                  ->capture_default_str(),
              {"dev", "deviation"});
  BindSetting(
      cmd->add_option("--taus", args->taus, "all | octave | decade | comma-separated taus in s")
          ->capture_default_str(),
      {"taus", "tau_list_s"});
  BindSetting(
      cmd->add_option("--units", args->units, "rate unit: dph (deg/h) | dps (deg/s) | rads (rad/s)")
          ->capture_default_str(),
      {"units"});
  BindSetting(cmd->add_option("--confidence", args->confidence,
                              "two-sided confidence of the bounds, in (0,1)")
                  ->capture_default_str(),
              {"confidence"});
  BindSetting(cmd->add_option("--threads,-j", args->threads, "worker threads (0 = all cores)")
                  ->capture_default_str(),
              {"threads"});
  BindSetting(cmd->add_option("--fit-tau-min", args->fit_tau_min_s, "noise fit: smallest tau in s")
                  ->capture_default_str(),
              {"tau_min_s"});
  BindSetting(cmd->add_option("--fit-tau-max", args->fit_tau_max_s, "noise fit: largest tau in s"),
              {"tau_max_s"});
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
