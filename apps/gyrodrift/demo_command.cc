// gyrodrift demo: the whole study in one command. Without files: simulate a navigation-grade FOG
// through two thermal-chamber programmes, decompose and group its output, fit MS-ELM and every
// baseline in predict mode (paper and causal protocols) and compensate mode (trained on run A,
// tested on run B), compare the Allan deviation before and after compensation, and write data,
// models, tables and one self-contained HTML report to a folder. With --input: the same study on
// a user's log (scored against the measured output; compensate mode by chronological split).
#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"
#include "gyrodrift/io/report.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/gyro_noise.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "progress.h"

namespace gyrodrift::cli {
namespace {

namespace sim = gyrodrift::simulation;
namespace dec = gyrodrift::decomposition;
namespace sel = gyrodrift::selection;

struct DemoArgs {
  std::string output = "gyrodrift-demo";
  std::string input, target, temperature;
  double rate_hz = 1.0;
  CLI::Option* rate_option = nullptr;
  std::string units = "dph";
  // Advanced: the size of the study. Defaults keep the full demo under 3 minutes on 2 cores.
  std::string duration = "8h";
  int ensemble = 20;
  int realisations = 20;
  int window = 128;
  std::string methods = "all";
  std::uint64_t seed = 1;
  int threads = 0;
  bool quiet = false;
};

constexpr double kMinDurationS = 2 * 3600.0;

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// -o must name a folder that exists or can be created. Found out before the study, which takes
// half a minute or more, rather than when the files are written.
void CheckOutputFolder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path existing = fs::absolute(fs::path(dir), ec);
  if (ec) throw IoError(dir + ": not a usable output folder (" + ec.message() + ")");
  while (existing.has_relative_path() && !fs::exists(existing, ec)) {
    existing = existing.parent_path();
  }
  if (!fs::is_directory(existing, ec)) {
    throw IoError(dir + ": cannot create the output folder (" + existing.string() +
                  " is not a folder)");
  }
  if (::access(existing.c_str(), W_OK) != 0) {
    throw IoError(dir + ": cannot create the output folder (" + existing.string() + ": " +
                  std::strerror(errno) + ")");
  }
}

// NaN marks a cell with no value (no simulator setting for the minimum ADEV, a noise fit that
// failed): a dash reads as "not applicable" where "nan" reads as a computation gone wrong.
std::string Fmt(double v, int digits = 4) {
  if (std::isnan(v)) return "-";
  return fmt::format("{:.{}g}", v, digits);
}

double Rms(const Eigen::Ref<const Eigen::VectorXd>& v) {
  return v.size() ? std::sqrt(v.squaredNorm() / static_cast<double>(v.size())) : 0.0;
}

// A table kept three ways: full precision for CSV, rounded for the console and the report.
struct Table {
  std::string title, caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> csv, shown;
  struct Cell {
    std::string text;
    double value = std::numeric_limits<double>::quiet_NaN();
    bool numeric = false;
    int digits = 4;
    Cell(std::string t) : text(std::move(t)) {}  // NOLINT: cells read naturally
    Cell(const char* t) : text(t) {}             // NOLINT
    Cell(double v, int d = 4) : value(v), numeric(true), digits(d) {}  // NOLINT
  };
  void Add(const std::vector<Cell>& cells) {
    std::vector<std::string> c, s;
    for (const auto& cell : cells) {
      c.push_back(cell.numeric ? io::FormatDouble(cell.value) : cell.text);
      s.push_back(cell.numeric ? Fmt(cell.value, cell.digits) : cell.text);
    }
    csv.push_back(std::move(c));
    shown.push_back(std::move(s));
  }
  std::string Csv() const {
    std::string out;
    for (size_t i = 0; i < header.size(); ++i) out += (i ? "," : "") + header[i];
    out += '\n';
    for (const auto& row : csv) {
      for (size_t i = 0; i < row.size(); ++i) out += (i ? "," : "") + row[i];
      out += '\n';
    }
    return out;
  }
  std::string Text() const {
    std::vector<size_t> width(header.size());
    for (size_t i = 0; i < header.size(); ++i) width[i] = header[i].size();
    for (const auto& row : shown) {
      for (size_t i = 0; i < row.size(); ++i) width[i] = std::max(width[i], row[i].size());
    }
    auto line = [&](const std::vector<std::string>& cells) {
      std::string out = " ";
      for (size_t i = 0; i < cells.size(); ++i) {
        out += i < 2 ? fmt::format(" {:<{}}", cells[i], width[i])
                     : fmt::format(" {:>{}}", cells[i], width[i]);
      }
      return out + "\n";
    };
    std::string out = title + "\n" + line(header);
    for (const auto& row : shown) out += line(row);
    return out;
  }
  io::ReportTable Report() const { return {title, caption, header, shown}; }
};

// Everything the study produced, for the files and the report.
struct Study {
  bool simulated = false;
  std::string source;            // "simulation" or the input file
  std::string target_name;       // the analysed column
  std::string unit;              // of the target
  std::string temperature_name;  // the temperature column (what a saved model reads)
  double rate_hz = 1.0;
  std::string rate_how;
  std::string time_note;  // a non-uniform time_s column (user logs), empty otherwise
  // Run A (or the user's log) and, for a simulation, run B.
  sim::SimulationResult a, b;
  Eigen::VectorXd y, temperature, truth;  // analysed record (truth empty for a user's log)
  Eigen::VectorXd time_h;
  // Decomposition and grouping of y.
  dec::Decomposition decomposition;
  sel::SelectionResult selection;
  // Predict mode.
  drift::EvaluationResult predict;
  // Compensate mode: run B (simulation) or chronological split (user's log).
  drift::EvaluationResult compensate_split;  // user's log only
  struct CompensateRow {
    drift::Method method;
    std::string protocol;
    drift::Metrics metrics;
    double share_removed = 0.0;
    double train_s = 0.0, estimate_s = 0.0;
    Eigen::VectorXd estimate;  // on the test record
    std::string summary;
  };
  std::vector<CompensateRow> compensate;
  Eigen::VectorXd comp_reference, comp_time_h, comp_raw;  // test record: reference, x, raw output
  std::vector<std::pair<std::string, std::string>> model_files;  // (file name, JSON)
  // Allan.
  allan::AllanResult allan_raw, allan_comp, allan_best, allan_noise;
  std::optional<allan::NoiseTerms> terms_raw, terms_comp, terms_best, terms_noise;
  std::string terms_note;
  std::string compensated_by, best_by;  // MS-ELM, and the lowest-RMSE method if another
  Table predict_table, compensate_table, terms_table, settings_table, timing_table;
  std::vector<std::pair<std::string, double>> stage_s;
};

// Evaluate reports the share of its trials done; the trials differ in cost by orders of magnitude
// (a causal MS-ELM trial decomposes one window per test sample), so the bar maps the trial index
// to a share of the expected cost instead. Weights: measured shares of the default demo.
std::function<void(double, const std::string&)> TrialProgress(
    ProgressBar& bar, const std::vector<drift::Method>& methods, drift::Mode mode,
    const std::string& prefix) {
  const std::vector<drift::Protocol> protocols{drift::Protocol::kPaper, drift::Protocol::kCausal};
  std::vector<double> cumulative{0.0};
  for (drift::Method m : methods) {
    for (drift::Protocol p : protocols) {
      double w = 0.0;
      if (drift::UsesDecomposition(m)) {
        w = p == drift::Protocol::kCausal && mode == drift::Mode::kPredict ? 10.0 : 1.5;
      } else if (p == drift::Protocol::kPaper) {
        w = 0.5;  // the causal row of a single model is a copy
      }
      cumulative.push_back(cumulative.back() + w);
    }
  }
  return [&bar, cumulative, prefix](double fraction, const std::string& label) {
    const double trials = static_cast<double>(cumulative.size() - 1);
    const size_t i =
        std::min(cumulative.size() - 1, static_cast<size_t>(std::lround(fraction * trials)));
    bar.Update(cumulative[i] / cumulative.back(), prefix + label);
  };
}

drift::DriftOptions BaseOptions(const DemoArgs& a, double rate_hz) {
  drift::DriftOptions o;
  o.decomposition.ensemble_size = a.ensemble;
  o.selection.monte_carlo.realisations = a.realisations;
  o.features.rate_hz = rate_hz;
  o.seed = a.seed;
  o.threads = a.threads;
  // The simulator's truth is zero in equilibrium at 20 degC and its turn-on bias is drawn anew for
  // each run: the simulated study references the estimate there (its convention, docs/drift.md
  // 1.3). A user's log keeps the fitted intercept, the library default.
  if (a.input.empty()) o.reference_c = 20.0;
  return o;
}

// ---- study steps -------------------------------------------------------------------------------

void DecomposeStep(const DemoArgs& a, Study& s) {
  const drift::DriftOptions o = BaseOptions(a, s.rate_hz);
  dec::DecompositionOptions dopt = o.decomposition;
  dopt.seed = a.seed;
  dopt.threads = a.threads;
  sel::SelectionOptions sopt = o.selection;
  sopt.threads = a.threads;
  sel::GroupedDecomposition grouped = sel::DecomposeAndSelect(s.y, dopt, sopt);
  if (!grouped.selection) {
    throw DataError(s.target_name +
                    " has fewer than 3 extrema: there is nothing to decompose or to model");
  }
  s.decomposition = std::move(grouped.decomposition);
  s.selection = std::move(*grouped.selection);
}

void FillPredictTable(Study& s) {
  Table& t = s.predict_table;
  t.title = "Predict mode: one-step-ahead prediction on the last 30 % of " +
            std::string(s.simulated ? "run A" : "the record");
  t.caption = std::string("Scored against ") +
              (s.simulated ? "the true drift (drift_dph)" : "the measured output") +
              ". paper = decompose the whole record, then split (sees the future); causal = only "
              "past samples reach a prediction (trailing-window decomposition). Single models are "
              "the same computation under both.";
  t.header = {"method", "protocol", "rmse", "mae", "max_abs", "train_s", "predict_s"};
  for (const auto& r : s.predict.rows) {
    t.Add({std::string(drift::ToString(r.method)),
           std::string(drift::ToString(r.protocol)),
           r.rmse,
           r.mae,
           r.max_abs,
           {r.train_s, 3},
           {r.predict_s, 3}});
  }
}

void FillCompensateTable(Study& s) {
  Table& t = s.compensate_table;
  t.title = s.simulated ? "Compensate mode: trained on run A (chamber), tested on run B (chamber-b)"
                        : "Compensate mode: chronological split (train first 70 %, test last 30 %)";
  t.caption =
      std::string("Drift estimated from temperature only; error = ") +
      (s.simulated ? "true drift of run B - estimate; removed = 1 - RMS(error) / RMS(true drift)"
                   : "measured output - estimate on the test block; removed = 1 - RMS(error) / "
                     "RMS(output - its mean), the share of the output's variation explained") +
      " (negative: the estimate adds more error than it removes). " +
      (s.simulated ? "The model is fitted on run A alone and sees only run B's temperature: causal "
                     "by construction."
                   : "paper = the whole record decomposed before the split; causal = the "
                     "training block alone.");
  t.header = {"method", "protocol", "rmse", "mae", "max_abs", "removed_%", "train_s", "estimate_s"};
  for (const auto& r : s.compensate) {
    t.Add({std::string(drift::ToString(r.method)),
           r.protocol,
           r.metrics.rmse,
           r.metrics.mae,
           r.metrics.max_abs,
           {100.0 * r.share_removed, 4},
           {r.train_s, 3},
           {r.estimate_s, 3}});
  }
}

void CompensateSimulated(const DemoArgs& a, const std::vector<drift::Method>& methods, Study& s,
                         ProgressBar& bar) {
  drift::DriftOptions base = BaseOptions(a, s.rate_hz);
  base.mode = drift::Mode::kCompensate;
  s.comp_reference = s.b.drift_dph;
  s.comp_raw = s.b.rate_dph;
  s.comp_time_h = s.b.time_s / 3600.0;
  const double reference_rms = Rms(s.comp_reference);
  for (size_t i = 0; i < methods.size(); ++i) {
    bar.Update(static_cast<double>(i) / static_cast<double>(methods.size()),
               "compensate: " + std::string(drift::ToString(methods[i])));
    drift::DriftOptions o = base;
    o.method = methods[i];
    Study::CompensateRow row{methods[i], "train A test B", {}, 0.0, 0.0, 0.0, {}, {}};
    auto start = std::chrono::steady_clock::now();
    const drift::DriftModel model = drift::FitDriftModel(s.a.rate_dph, s.a.temperature_c, o);
    row.train_s = Seconds(start);
    start = std::chrono::steady_clock::now();
    row.estimate = drift::EstimateDrift(model, s.b.temperature_c);
    row.estimate_s = Seconds(start);
    row.metrics = drift::ComputeMetrics(s.comp_reference - row.estimate);
    row.share_removed = 1.0 - row.metrics.rmse / reference_rms;
    row.summary = model.Summary();
    io::ModelFileInfo info{"rate_dph", "temperature_c", "simulation run A (chamber)", ""};
    s.model_files.push_back(
        {"models/" + std::string(drift::ToString(methods[i])) + "_compensate.json",
         io::RenderModelFile(model, info)});
    s.compensate.push_back(std::move(row));
  }
}

void CompensateSplit(const DemoArgs& a, const std::vector<drift::Method>& methods, Study& s,
                     ProgressBar& bar) {
  drift::DriftOptions base = BaseOptions(a, s.rate_hz);
  base.mode = drift::Mode::kCompensate;
  drift::EvaluationOptions e;
  e.methods = methods;
  e.causal.window = a.window;
  e.causal.threads = a.threads;
  e.causal.ensemble_size = a.ensemble;
  e.progress = TrialProgress(bar, methods, drift::Mode::kCompensate, "compensate: ");
  s.compensate_split = drift::Evaluate(s.y, s.temperature, Eigen::VectorXd(), base, e);
  const Eigen::Index split = s.compensate_split.split_index;
  s.comp_reference = s.compensate_split.reference;
  s.comp_raw = s.y.tail(s.y.size() - split);
  s.comp_time_h = s.time_h.tail(s.y.size() - split);
  // The measured output carries the sensor's constant bias, which any model removes; the share is
  // taken of the output's variation about its mean instead.
  const double reference_rms = Rms(s.comp_reference.array() - s.comp_reference.mean());
  for (const auto& r : s.compensate_split.rows) {
    Study::CompensateRow row{r.method,   std::string(drift::ToString(r.protocol)),
                             {},         0.0,
                             r.train_s,  r.predict_s,
                             r.estimate, r.model_summary};
    row.metrics = drift::ComputeMetrics(s.comp_reference - r.estimate);
    row.share_removed = 1.0 - row.metrics.rmse / reference_rms;
    s.compensate.push_back(std::move(row));
  }
  // Models for the files: fitted on the whole record (what a user would deploy).
  for (drift::Method m : methods) {
    drift::DriftOptions o = base;
    o.method = m;
    const drift::DriftModel model = drift::FitDriftModel(s.y, s.temperature, o);
    // gyrodrift compensate reads the temperature from the column named here.
    io::ModelFileInfo info{s.target_name, s.temperature_name, s.source, ""};
    s.model_files.push_back({"models/" + std::string(drift::ToString(m)) + "_compensate.json",
                             io::RenderModelFile(model, info)});
  }
}

void AllanStep(const DemoArgs& a, Study& s) {
  // The compensated output: MS-ELM if it ran (causal row for a split), else the first method.
  const Study::CompensateRow* best = nullptr;
  for (const auto& r : s.compensate) {
    if (r.method == drift::Method::kMsElm && (r.protocol != "paper")) best = &r;
  }
  if (!best && !s.compensate.empty()) best = &s.compensate.front();
  s.compensated_by =
      best ? std::string(drift::ToString(best->method)) + " (" + best->protocol + ")" : "";
  const Study::CompensateRow* lowest = nullptr;
  for (const auto& r : s.compensate) {
    if (r.protocol != "paper" && (!lowest || r.metrics.rmse < lowest->metrics.rmse)) lowest = &r;
  }
  // Another method only when it is clearly better (linear sub-models of MS-ELM and EMD-ELM can sum
  // to the same estimate).
  if (lowest == best || (best && lowest && lowest->metrics.rmse > 0.99 * best->metrics.rmse))
    lowest = nullptr;
  if (lowest)
    s.best_by = std::string(drift::ToString(lowest->method)) + " (" + lowest->protocol + ")";
  allan::AllanOptions o;
  o.rate_hz = s.rate_hz;
  o.units = allan::RateUnitFromString(a.units);
  o.threads = a.threads;
  s.allan_raw = allan::Compute(s.comp_raw, o);
  if (best) s.allan_comp = allan::Compute(Eigen::VectorXd(s.comp_raw - best->estimate), o);
  if (lowest) s.allan_best = allan::Compute(Eigen::VectorXd(s.comp_raw - lowest->estimate), o);
  if (s.simulated) s.allan_noise = allan::Compute(s.b.noise_dph, o);
  // The noise terms are in deg/h; a curve too short to fit is reported, not fatal.
  auto fit = [&](const allan::AllanResult& r, std::optional<allan::NoiseTerms>& out) {
    if (r.points.empty()) return;
    try {
      allan::AllanResult converted = r;
      const double to_dph = allan::ToDegPerHour(o.units);
      for (auto& p : converted.points) {
        p.dev *= to_dph;
        p.dev_lo *= to_dph;
        p.dev_hi *= to_dph;
      }
      converted.options.units = allan::RateUnit::kDegPerHour;
      out = allan::IdentifyNoise(converted);
    } catch (const Error& e) {
      s.terms_note += std::string(e.what()) + "; ";
    }
  };
  fit(s.allan_raw, s.terms_raw);
  fit(s.allan_comp, s.terms_comp);
  fit(s.allan_best, s.terms_best);
  if (s.simulated) fit(s.allan_noise, s.terms_noise);

  Table& t = s.terms_table;
  t.title = "IEEE 952 noise terms of " + std::string(s.simulated ? "run B" : "the test block") +
            ": raw vs compensated";
  t.caption =
      "Fitted to the overlapping Allan deviation (octave grid, 68.3 % bands); - = not identified: "
      "the term carries < 10 % of the model variance at every tau. Units: Q urad, N deg/sqrt(h), "
      "B deg/h, K deg/h/sqrt(h), R deg/h/h.";
  t.header = {"term", "unit", "raw", "compensated: " + s.compensated_by};
  if (!s.best_by.empty()) t.header.push_back("compensated: " + s.best_by);
  if (s.simulated) {
    t.header.push_back("noise only (truth)");
    t.header.push_back("simulator setting");
  }
  const sim::NoiseParameters np = sim::PresetParameters(sim::Preset::kNavigation).noise;
  struct Row {
    std::string name, unit;
    const allan::NoiseTerm allan::NoiseTerms::*term;
    double setting;
  };
  const Row rows[] = {
      {"Q quantization", "urad", &allan::NoiseTerms::q_urad, np.quantization_urad},
      {"N angle random walk", "deg/sqrt(h)", &allan::NoiseTerms::n_dpsh, np.arw_dpsh},
      {"B bias instability", "deg/h", &allan::NoiseTerms::b_dph, np.bias_instability_dph},
      {"K rate random walk", "deg/h/sqrt(h)", &allan::NoiseTerms::k_dphpsh, np.rrw_dphpsh},
      {"R rate ramp", "deg/h/h", &allan::NoiseTerms::r_dphph, np.rate_ramp_dphph},
  };
  auto value = [](const std::optional<allan::NoiseTerms>& n,
                  const allan::NoiseTerm allan::NoiseTerms::*m) {
    // A term the fit could not identify (it matters nowhere in the fitted range) is a dash, as
    // `gyrodrift allan` prints "not identified": its 0 is not a measurement.
    return n && ((*n).*m).identified ? ((*n).*m).value : std::numeric_limits<double>::quiet_NaN();
  };
  for (const Row& r : rows) {
    std::vector<Table::Cell> cells{r.name, r.unit, value(s.terms_raw, r.term),
                                   value(s.terms_comp, r.term)};
    if (!s.best_by.empty()) cells.emplace_back(value(s.terms_best, r.term));
    if (s.simulated) {
      cells.emplace_back(value(s.terms_noise, r.term));
      cells.emplace_back(r.setting);
    }
    t.Add(cells);
  }
  auto min_dev = [](const std::optional<allan::NoiseTerms>& n) {
    return n ? n->min_dev_dph : std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<Table::Cell> cells{"minimum ADEV", "deg/h", min_dev(s.terms_raw),
                                 min_dev(s.terms_comp)};
  if (!s.best_by.empty()) cells.emplace_back(min_dev(s.terms_best));
  if (s.simulated) {
    cells.emplace_back(min_dev(s.terms_noise));
    cells.emplace_back(std::numeric_limits<double>::quiet_NaN());
  }
  t.Add(cells);
}

// ---- files -------------------------------------------------------------------------------------

std::string SimCsv(const sim::SimulationResult& r) {
  return io::RenderCsv({{"time_s", r.time_s},
                        {"rate_dph", r.rate_dph},
                        {"temperature_c", r.temperature_c},
                        {"drift_dph", r.drift_dph},
                        {"shupe_dph", r.shupe_dph},
                        {"stress_dph", r.stress_dph},
                        {"bias_dph", r.bias_dph},
                        {"noise_dph", r.noise_dph},
                        {"chamber_c", r.chamber_c},
                        {"case_c", r.case_c},
                        {"coil_mean_c", r.coil_mean_c}});
}

std::string GroupOf(const sel::SelectionResult& s, int k) {
  for (const auto& g : s.groups) {
    if (std::find(g.imfs.begin(), g.imfs.end(), k) != g.imfs.end())
      return std::string(sel::ToString(g.kind));
  }
  return "drift";  // beyond the listed IMFs: with the residue
}

std::string AllanCsv(const Study& s) {
  std::vector<io::CsvColumn> c;
  auto add = [&](const std::string& name, const allan::AllanResult& r) {
    if (r.points.empty()) return;
    Eigen::VectorXd dev(r.points.size()), lo(r.points.size()), hi(r.points.size());
    for (size_t i = 0; i < r.points.size(); ++i) {
      dev[i] = r.points[i].dev;
      lo[i] = r.points[i].dev_lo;
      hi[i] = r.points[i].dev_hi;
    }
    if (c.empty()) c.push_back({"tau_s", r.tau_s()});
    c.push_back({name + "_adev", dev});
    c.push_back({name + "_lo", lo});
    c.push_back({name + "_hi", hi});
  };
  add("raw", s.allan_raw);
  add("compensated", s.allan_comp);
  if (!s.best_by.empty()) add("compensated_best", s.allan_best);
  if (s.simulated) add("noise_truth", s.allan_noise);
  return io::RenderCsv(c);
}

// ---- report ------------------------------------------------------------------------------------

io::ReportSeries Series(std::string name, Eigen::VectorXd v, bool dashed = false) {
  io::ReportSeries s;
  s.name = std::move(name);
  s.values = std::move(v);
  s.dashed = dashed;
  return s;
}

io::ReportSeries Reference(std::string name, Eigen::VectorXd v) {
  io::ReportSeries s = Series(std::move(name), std::move(v));
  s.emphasis = true;
  return s;
}

// A user's measured output is as noisy as the predictions: drawn thick and black on top it hides
// them, so it goes first (underneath) in light grey.
io::ReportSeries Measured(std::string name, Eigen::VectorXd v) {
  io::ReportSeries s = Series(std::move(name), std::move(v));
  s.color = "#aaaaaa";
  return s;
}

// The paper and causal rows of a single model are one computation (it never decomposes): a figure
// draws one of them.
bool DuplicateRow(drift::Method method, const std::string& protocol) {
  return !drift::UsesDecomposition(method) && protocol == drift::ToString(drift::Protocol::kCausal);
}

// Trailing mean over w samples (the first w - 1 use what exists): shows the slow structure of a
// residual that sample-to-sample noise hides.
Eigen::VectorXd TrailingMean(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Index w) {
  Eigen::VectorXd out(v.size());
  double sum = 0.0;
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    sum += v[i];
    if (i >= w) sum -= v[i - w];
    out[i] = sum / static_cast<double>(std::min<Eigen::Index>(i + 1, w));
  }
  return out;
}

void AllanFigure(io::HtmlReport& report, const Study& s) {
  if (s.allan_raw.points.empty()) return;
  io::ReportFigure f;
  f.title = "Allan deviation before and after compensation (" +
            std::string(s.simulated ? "run B" : "test block") + ")";
  f.x_label = "tau (s)";
  f.y_label = "overlapping ADEV (" + s.unit + ")";
  f.log_x = f.log_y = true;
  f.draw_points = true;
  f.height_px = 420;
  f.x = s.allan_raw.tau_s();
  auto add = [&](const std::string& name, const allan::AllanResult& r, const char* colour) {
    if (r.points.size() != s.allan_raw.points.size()) return;
    io::ReportSeries series = Series(name, r.dev());
    series.color = colour;
    series.lower.resize(f.x.size());
    series.upper.resize(f.x.size());
    for (size_t i = 0; i < r.points.size(); ++i) {
      series.lower[static_cast<Eigen::Index>(i)] = r.points[i].dev_lo;
      series.upper[static_cast<Eigen::Index>(i)] = r.points[i].dev_hi;
    }
    f.series.push_back(std::move(series));
  };
  // A curve and its fitted model share a colour.
  constexpr const char* kRaw = "#c0392b";
  constexpr const char* kMsElm = "#1f5fbf";
  constexpr const char* kBest = "#1e9e4a";
  add("raw output", s.allan_raw, kRaw);
  add("compensated: " + s.compensated_by, s.allan_comp, kMsElm);
  if (!s.best_by.empty()) add("compensated: " + s.best_by, s.allan_best, kBest);
  if (s.simulated) add("noise only (truth)", s.allan_noise, "#7f7f7f");
  const double from_dph =
      1.0 / allan::ToDegPerHour(allan::RateUnitFromString(s.unit == "rad/s"   ? "rads"
                                                          : s.unit == "deg/s" ? "dps"
                                                                              : "dph"));
  auto model = [&](const std::string& name, const std::optional<allan::NoiseTerms>& t,
                   const char* colour) {
    if (!t) return;
    Eigen::VectorXd v(f.x.size());
    for (Eigen::Index i = 0; i < f.x.size(); ++i) v[i] = t->ModelDevDph(f.x[i]) * from_dph;
    f.series.push_back(Series(name, v, true));
    f.series.back().color = colour;
  };
  model("IEEE 952 fit, raw", s.terms_raw, kRaw);
  model("IEEE 952 fit, compensated: " + s.compensated_by, s.terms_comp, kMsElm);
  if (!s.best_by.empty()) model("IEEE 952 fit, compensated: " + s.best_by, s.terms_best, kBest);
  if (s.simulated) {
    const sim::NoiseParameters np = sim::PresetParameters(sim::Preset::kNavigation).noise;
    Eigen::VectorXd v(f.x.size());
    for (Eigen::Index i = 0; i < f.x.size(); ++i) {
      v[i] = std::sqrt(sim::NoiseAllanVariance(np, 1.0 / s.rate_hz,
                                               s.allan_raw.points[static_cast<size_t>(i)].m));
    }
    f.series.push_back(Series("simulator noise model (exact)", v, true));
    f.series.back().color = "#000000";
  }
  f.caption =
      std::string(
          "Log-log; shaded: 68.3 % chi-square confidence bands; dashed: the fitted IEEE 952 "
          "models (table below)") +
      (s.simulated ? " and the exact Allan deviation of the simulated noise" : "") +
      ". The raw curve rises at long tau because the thermal drift dominates there; after "
      "compensation it should come down" +
      (s.simulated
           ? std::string(" towards the noise-only curve. Where the compensated curve stays above "
                         "it, the residual drift is what remains.")
           : std::string(". There is no noise-only curve for a measured log: a compensated curve "
                         "at or above the raw one at long tau means the model removed nothing "
                         "there, or added error."));
  report.AddFigure(f);
}

std::string RenderReport(const Study& s, const io::DygraphsAssets& assets) {
  io::HtmlReport report(s.simulated ? "gyrodrift demo: thermal drift of a simulated navigation FOG"
                                    : "gyrodrift demo: " + s.source);
  const double split_h = s.predict.split_index < s.time_h.size() ? s.time_h[s.predict.split_index]
                                                                 : s.time_h[s.time_h.size() - 1];
  const double end_h = s.time_h[s.time_h.size() - 1];
  report.AddParagraph(
      s.simulated
          ? "A navigation-grade fibre optic gyro (1 km coil, quadrupole winding) is simulated at " +
                Fmt(s.rate_hz) +
                " Hz through two thermal-chamber programmes: run A ('chamber') to train and "
                "evaluate, run B ('chamber-b', another thermal history) to test compensation. The "
                "simulator "
                "keeps the true drift apart from the noise, so every model is scored against the "
                "truth."
          : "The log " + s.source + " (column " + s.target_name + ", " + Fmt(s.rate_hz) +
                " Hz, rate " + s.rate_how +
                ") analysed like the simulated demo. There is no truth column: "
                "models are scored against the measured output, and compensation is tested by a "
                "chronological split.");
  report.AddParagraph(
      "Method: BEEMDAN decomposes the output into intrinsic mode functions (IMFs); the "
      "PDF-similarity "
      "criterion groups them into noise, mixed and drift sub-series; MS-ELM fits one extreme "
      "learning "
      "machine per sub-series and sums them (Chen & Cui, Signal Processing 128, 2016). Baselines: "
      "a "
      "single ELM, EMD-ELM (one ELM per IMF), polynomial regression, SVR and a BP network.");

  report.AddHeading(s.simulated ? "1. The simulated runs" : "1. The record");
  {
    io::ReportFigure f;
    f.title = s.simulated ? "Run A: gyro output and true thermal drift" : "Gyro output";
    f.x_label = "time (h)";
    f.y_label = s.target_name + " (" + s.unit + ")";
    f.x = s.time_h;
    f.series.push_back(Series("output", s.y));
    if (s.simulated) f.series.push_back(Reference("true drift", s.truth));
    f.shades.push_back({split_h, end_h, "predict-mode test block (last 30 %)"});
    f.caption =
        s.simulated
            ? "The output is the drift plus white and bias-instability noise. The drift follows "
              "the temperature ramps (Shupe effect: the rate of temperature change inside the "
              "coil) "
              "and the temperature level (stress and electronics bias). Zoom into a ramp to see "
              "the "
              "noise riding on it."
            : "The analysed column. Shaded: the last 30 %, where every model is tested.";
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    f.title = s.simulated ? "Run A: temperatures" : "Temperature channel";
    f.x_label = "time (h)";
    // A user's temperature column may be in any unit (raw counts, for one): its name, not a unit.
    f.y_label = s.simulated ? "temperature (degC)" : s.temperature_name;
    f.x = s.time_h;
    if (s.simulated) {
      f.series.push_back(Series("chamber", s.a.chamber_c));
      f.series.push_back(Series("case sensor (model input)", s.a.temperature_c));
      f.series.push_back(Series("coil mean (truth)", s.a.coil_mean_c));
    } else {
      f.series.push_back(Series("temperature", s.temperature));
    }
    f.caption =
        s.simulated
            ? "The chamber programme, the case sensor a user logs (the only temperature the "
              "models see) and the true mean coil temperature, which lags the case by minutes."
            : "The temperature column the compensate-mode models use.";
    report.AddFigure(f);
  }
  if (s.simulated) {
    io::ReportFigure f;
    f.title = "Run B: gyro output, true drift and temperature (test run for compensation)";
    f.x_label = "time (h)";
    f.y_label = "deg/h";
    f.y2_label = "case sensor (degC)";
    f.x = s.b.time_s / 3600.0;
    f.series.push_back(Series("output", s.b.rate_dph));
    f.series.push_back(Reference("true drift", s.b.drift_dph));
    io::ReportSeries t = Series("case sensor (right axis)", s.b.temperature_c);
    t.right_axis = true;
    f.series.push_back(t);
    f.caption =
        "Run B uses a different programme (slower ramps, other levels), so a compensation "
        "model trained on run A meets a thermal history it has not seen.";
    report.AddFigure(f);
  }

  report.AddHeading("2. BEEMDAN decomposition and mode selection");
  report.AddParagraph(s.decomposition.report.Summary() + ". " + s.selection.Summary() + ".");
  const int k_count = s.decomposition.num_imfs();
  {
    io::ReportFigure f;
    f.title =
        "Selection curves: distance of each IMF's PDF to the signal's (D_k) and to a Gaussian "
        "(G_k)";
    f.x_label = "IMF index k";
    f.y_label = "L2 distance between densities";
    f.draw_points = true;
    f.integer_x = true;
    f.x.resize(k_count);
    for (int k = 0; k < k_count; ++k) f.x[k] = k + 1;
    auto vec = [&](const std::vector<double>& v) {
      Eigen::VectorXd out(k_count);
      for (int k = 0; k < k_count; ++k) {
        out[k] = k < static_cast<int>(v.size()) ? v[static_cast<size_t>(k)]
                                                : std::numeric_limits<double>::quiet_NaN();
      }
      return out;
    };
    f.series.push_back(Series("D_k: PDF(IMF k) vs PDF(signal)", vec(s.selection.pdf_distance)));
    f.y2_label = "G_k (right axis)";
    f.series.push_back(
        Series("G_k: standardised IMF k vs N(0,1) (right axis)", vec(s.selection.self_distance)));
    f.series.push_back(
        Series("white-noise 99 % level of G_k (right axis)", vec(s.selection.noise_level), true));
    f.series[1].right_axis = f.series[2].right_axis = true;
    for (const auto& g : s.selection.groups) {
      if (g.imfs.empty()) continue;
      f.shades.push_back(
          {g.imfs.front() - 0.45, g.imfs.back() + 0.45, std::string(sel::ToString(g.kind))});
    }
    f.caption =
        "Shaded: the chosen groups. Noise = the leading IMFs whose G_k stays under the white-noise "
        "level (k_N = " +
        std::to_string(s.selection.k_noise) +
        "); k* = argmax D_k = " + std::to_string(s.selection.k_star) +
        " ends the mixed group; the rest plus the residue is the drift group. Look for the peak of "
        "D_k: below it the IMFs look like noise, above it like the signal.";
    // The rule above in general; the edge case this record met (no mixed group, say) in particular.
    if (!s.selection.note.empty()) f.caption += " Here: " + s.selection.note + ".";
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    f.title = "IMF energies against the white-noise energy model";
    f.x_label = "IMF index k";
    f.y_label = "log2 energy";
    f.draw_points = true;
    f.integer_x = true;
    f.x.resize(k_count);
    Eigen::VectorXd e(k_count), band(k_count);
    for (int k = 0; k < k_count; ++k) {
      f.x[k] = k + 1;
      e[k] = k < static_cast<int>(s.selection.log2_energy.size())
                 ? s.selection.log2_energy[static_cast<size_t>(k)]
                 : NAN;
      band[k] = k < static_cast<int>(s.selection.energy_band_log2_upper.size())
                    ? s.selection.energy_band_log2_upper[static_cast<size_t>(k)]
                    : NAN;
    }
    f.series.push_back(Series("log2 energy of IMF k", e));
    f.series.push_back(Series("99 % white-noise band, upper", band, true));
    int above = 0;
    for (int k = 0; k < k_count; ++k) above += e[k] > band[k];  // NaN compares false
    f.caption =
        "White noise gives IMF energies that halve with each k (Flandrin et al. 2004). IMFs above "
        "the dashed band carry more than noise: that is where the thermal drift lives." +
        std::string(above == 0
                        ? " Here no IMF rises above the band: by energy alone, every IMF could be "
                          "noise, and the drift hides in the slowest ones and the residue."
                        : "");
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    f.title = "The grouped sub-series (noise + mixed + drift = output)";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = s.time_h;
    for (const auto& g : s.selection.groups) {
      f.series.push_back(Series(std::string(sel::ToString(g.kind)), g.series));
      // A user's log carries its sensor bias in the drift group, which would flatten the other
      // groups to a line on a shared axis.
      if (!s.simulated && g.kind == sel::GroupKind::kDrift) f.series.back().right_axis = true;
    }
    if (!s.simulated) f.y2_label = "drift group (" + s.unit + ", right axis)";
    if (s.simulated) {
      // Thick and dashed: a thin line of its own would vanish in the noise group's band.
      f.series.push_back(Reference("true drift", s.truth));
      f.series.back().dashed = true;
    }
    const sel::ModeGroup* drift_group = s.selection.Group(sel::GroupKind::kDrift);
    const bool residue_only = drift_group && drift_group->imfs.empty();
    f.caption =
        s.simulated
            ? "The drift group should follow the true drift (thick dashed); the noise group "
              "should look like the white noise. MS-ELM fits one ELM to each."
            : "MS-ELM fits one ELM to each of these series and sums the outputs. The drift "
              "group is on the right axis (it carries the sensor's bias).";
    if (residue_only) {
      f.caption +=
          " Here the drift group is the residue alone: whatever slow structure the residue misses "
          "(compare the last IMFs below with the temperature) is in the " +
          std::string(s.selection.Group(sel::GroupKind::kMixed) ? "mixed" : "noise") + " group.";
    }
    report.AddFigure(f);
  }
  for (int k = 0; k < k_count; ++k) {
    io::ReportFigure f;
    f.title = "IMF " + std::to_string(k + 1) + " (" + GroupOf(s.selection, k + 1) + " group)";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = s.time_h;
    f.height_px = 150;
    f.series.push_back(Series("imf" + std::to_string(k + 1), s.decomposition.imfs.col(k)));
    const std::string group = GroupOf(s.selection, k + 1);
    f.caption =
        group == "noise"
            ? "Noise group: should look like noise of steady amplitude, with no trace of the "
              "temperature programme."
        : group == "mixed"
            ? "Mixed group: noise with slower structure in it; look for swings that line "
              "up with the temperature changes."
            : "Drift group: slow structure that should follow the temperature history.";
    // Only a series longer than the plotted rows is decimated (io::DecimateMinMax).
    const Eigen::Index n = s.time_h.size();
    if (n > f.max_points) {
      f.caption += " Plotted as the min and max of each run of " +
                   Fmt(static_cast<double>(n) / (f.max_points / 2), 3) + " samples.";
    }
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    f.title = "Residue";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = s.time_h;
    f.height_px = 150;
    f.series.push_back(Series("residue", s.decomposition.residue));
    f.caption = "The slow trend left after the last IMF (part of the drift group).";
    report.AddFigure(f);
  }

  report.AddHeading("3. Predict mode (the paper's task)");
  report.AddTable(s.predict_table.Report());
  const Eigen::Index split = s.predict.split_index;
  const Eigen::VectorXd test_h = s.time_h.tail(s.time_h.size() - split);
  {
    io::ReportFigure f;
    f.title = "Predict mode: one-step-ahead predictions on the test block";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = test_h;
    // MS-ELM under both protocols and the best single model; every row is in predict_estimates.csv.
    if (!s.simulated) f.series.push_back(Measured("measured output", s.predict.reference));
    const drift::EvaluationRow* best = nullptr;
    for (const auto& r : s.predict.rows) {
      if (r.method == drift::Method::kMsElm) {
        f.series.push_back(
            Series("ms-elm " + std::string(drift::ToString(r.protocol)), r.estimate));
      } else if (!drift::UsesDecomposition(r.method) && (!best || r.rmse < best->rmse)) {
        best = &r;
      }
    }
    if (best)
      f.series.push_back(Series(std::string(drift::ToString(best->method)) + " (best single model)",
                                best->estimate));
    if (s.simulated) f.series.push_back(Reference("true drift", s.predict.reference));
    f.caption =
        "Each model predicts the next output sample from the previous ones (MS-ELM under both "
        "protocols and the best single model; every method is in predict_estimates.csv). Under the "
        "paper protocol the sub-series were decomposed with the future in view. Predictions of a "
        "noisy output are noisy: zoom into a few minutes to compare them with the " +
        std::string(s.simulated ? "thick black true drift." : "grey measured output they predict.");
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    const Eigen::Index w =
        std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::lround(300.0 * s.rate_hz)), 1,
                                 std::max<Eigen::Index>(1, test_h.size() / 20));
    f.title = "Predict mode: residuals (reference - prediction), trailing mean over " +
              std::to_string(w) + " samples";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = test_h;
    for (const auto& r : s.predict.rows) {
      if (!drift::UsesDecomposition(r.method) && r.protocol == drift::Protocol::kCausal) continue;
      std::string name = std::string(drift::ToString(r.method));
      if (drift::UsesDecomposition(r.method))
        name += " " + std::string(drift::ToString(r.protocol));
      f.series.push_back(Series(name, TrailingMean(s.predict.reference - r.estimate, w)));
    }
    f.caption =
        "Averaged over " + Fmt(static_cast<double>(w) / s.rate_hz) +
        " s so that the sample-to-sample noise drops out: what remains is drift the model "
        "missed or a bias it added. Near zero is good; single models are one curve (the same "
        "under both protocols).";
    report.AddFigure(f);
  }

  report.AddHeading(s.simulated ? "4. Compensate mode: trained on run A, tested on run B"
                                : "4. Compensate mode: chronological split");
  report.AddTable(s.compensate_table.Report());
  {
    io::ReportFigure f;
    f.title = s.simulated
                  ? "Compensate mode: drift estimated from temperature on run B vs the true drift"
                  : "Compensate mode: drift estimated from temperature vs the measured output";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = s.comp_time_h;
    if (!s.simulated) f.series.push_back(Measured("measured output", s.comp_reference));
    for (const auto& r : s.compensate) {
      if (!s.simulated && DuplicateRow(r.method, r.protocol)) continue;
      const bool both = !s.simulated && drift::UsesDecomposition(r.method);
      f.series.push_back(Series(
          std::string(drift::ToString(r.method)) + (both ? " " + r.protocol : ""), r.estimate));
    }
    if (s.simulated) f.series.push_back(Reference("true drift (run B)", s.comp_reference));
    f.caption =
        s.simulated
            ? "Only the temperature channel reaches these models, as on a navigation computer. A "
              "good model tracks the thick black true drift through ramps it was not trained on."
            : "Only the temperature channel reaches these models, as on a navigation computer. A "
              "good model runs through the middle of the grey measured output over the test "
              "block, which it never saw. Single models are drawn once (the same under both "
              "protocols).";
    report.AddFigure(f);
  }
  {
    io::ReportFigure f;
    f.title = "Compensate mode: residual drift (reference - estimate)";
    f.x_label = "time (h)";
    f.y_label = s.unit;
    f.x = s.comp_time_h;
    for (const auto& r : s.compensate) {
      if (!s.simulated && DuplicateRow(r.method, r.protocol)) continue;
      const bool both = !s.simulated && drift::UsesDecomposition(r.method);
      f.series.push_back(
          Series(std::string(drift::ToString(r.method)) + (both ? " " + r.protocol : ""),
                 s.comp_reference - r.estimate));
    }
    f.caption =
        s.simulated
            ? "What is left after compensation. Flat near zero is good; spikes at the ramps are "
              "the Shupe part the temperature history did not explain."
            : "The measured output minus the estimate, noise included. A band centred on zero "
              "is good; a trend or a step is drift the temperature history did not explain, or "
              "a bias the model added.";
    report.AddFigure(f);
  }

  report.AddHeading("5. Allan deviation");
  AllanFigure(report, s);
  report.AddTable(s.terms_table.Report());
  if (!s.terms_note.empty()) report.AddParagraph("Noise fit notes: " + s.terms_note);

  report.AddHeading("6. Settings and timing");
  report.AddTable(s.settings_table.Report());
  report.AddTable(s.timing_table.Report());
  report.AddParagraph(
      "Everything plotted here is in the CSV files beside this report at full precision; the "
      "fitted compensation models are in models/*.json (gyrodrift compensate "
      "models/ms-elm_compensate.json LOG.csv -o OUT.csv; LOG.csv needs the columns " +
      s.target_name + " and " + s.temperature_name + ").");
  return report.Render(assets);
}

// ---- the command -------------------------------------------------------------------------------

void Run(const DemoArgs& a) {
  RequireInputsOutsideFolder({a.input}, a.output);
  const auto wall_start = std::chrono::steady_clock::now();
  // Options first: every mistake is reported before any work.
  const bool user = !a.input.empty();
  if (!user && (!a.target.empty() || !a.temperature.empty() || a.rate_option->count() > 0)) {
    throw UsageError("--target, --temperature and --rate-hz need --input FILE.csv");
  }
  if (user && a.target.empty())
    throw UsageError("--input needs --target COL (the gyro output column)");
  if (user && a.temperature.empty()) {
    throw UsageError(
        "--input needs --temperature COL (compensate mode models drift from temperature)");
  }
  if (a.ensemble < 1 || a.ensemble > 10000)
    ThrowOption("--ensemble", std::to_string(a.ensemble), "an integer in [1, 10000]");
  if (a.window < 16 || a.window > 1000000)
    ThrowOption("--window", std::to_string(a.window), "an integer in [16, 1000000]");
  if (a.threads < 0) ThrowOption("--threads", std::to_string(a.threads), "an integer >= 0");
  // The library would name these "realisations" and "units"; the user typed the options.
  if (a.realisations < 20 || a.realisations > 100000) {
    ThrowOption("--realisations", std::to_string(a.realisations), "an integer in [20, 100000]");
  }
  try {
    (void)allan::RateUnitFromString(a.units);
  } catch (const UsageError&) {
    ThrowOption("--units", a.units, "one of dph, dps, rads");
  }
  const std::vector<drift::Method> methods = ParseMethods(a.methods, drift::Mode::kCompensate);
  const double duration_s = ParseDuration(a.duration);
  // Run A must show the model a ramp and a dwell at a new level: the chamber programme ramps from
  // 30 to 70 min. On shorter runs the level and rate responses cannot be told apart, and every
  // compensation model extrapolates wildly on run B (docs/demo.md).
  if (duration_s < kMinDurationS) {
    ThrowOption("--duration", a.duration, "at least 2h (run A needs a ramp and a dwell)");
  }
  if (user && a.rate_option->count() > 0) RequireInRange("--rate-hz", a.rate_hz, 1e-6, 1e6);
  {
    drift::DriftOptions probe = BaseOptions(a, 1.0);
    probe.Validate();
  }
  // The report needs dygraphs and the files need their folder; find out now, not after the work.
  const io::DygraphsAssets assets = io::LoadDygraphs();
  CheckOutputFolder(a.output);

  Study s;
  s.simulated = !user;
  // Stage weights: seconds the stages took in the measured runs (docs/demo.md).
  ProgressBar bar(user ? std::vector<double>{0.1, 0.5, 12, 5, 0.1, 1}
                       : std::vector<double>{0.2, 5, 68, 22, 0.1, 3},
                  !a.quiet);
  auto say = [&](const std::string& text) {
    if (!a.quiet) bar.Print(text);
  };
  auto stage_done = [&](const std::string& name, std::chrono::steady_clock::time_point t0) {
    s.stage_s.push_back({name, Seconds(t0)});
  };

  // 1. Data.
  bar.BeginStage(0, user ? "reading " + a.input : "simulating runs A and B");
  auto t0 = std::chrono::steady_clock::now();
  if (!user) {
    const sim::FogParameters fog = sim::PresetParameters(sim::Preset::kNavigation);
    sim::SimulationOptions so;
    so.duration_s = duration_s;
    so.rate_hz = 1.0;
    so.seed = a.seed;
    s.a = sim::Simulate(sim::BuiltinProgramme("chamber"), fog, so);
    so.seed = a.seed + 1;
    s.b = sim::Simulate(sim::BuiltinProgramme("chamber-b"), fog, so);
    s.source = "simulation";
    s.target_name = "rate_dph";
    s.unit = "deg/h";
    s.temperature_name = "temperature_c";
    s.rate_hz = so.rate_hz;
    s.rate_how = "simulated";
    s.y = s.a.rate_dph;
    s.temperature = s.a.temperature_c;
    s.truth = s.a.drift_dph;
    s.time_h = s.a.time_s / 3600.0;
    say(fmt::format("1. simulated run A: {}\n   simulated run B: {}\n", s.a.Summary(),
                    s.b.Summary()));
  } else {
    const io::CsvTable table = ReadLog(a.input);
    s.y = table.Column(a.target);
    s.temperature = table.Column(a.temperature);
    s.source = a.input;
    s.target_name = table.header()[static_cast<size_t>(table.ResolveColumn(a.target))];
    s.unit = a.units == "dph" ? "deg/h" : a.units == "dps" ? "deg/s" : "rad/s";
    s.temperature_name = table.header()[static_cast<size_t>(table.ResolveColumn(a.temperature))];
    std::string how;
    s.rate_hz = ResolveSampleRate(table, a.rate_option->count() > 0 ? a.rate_hz : 0.0, &how);
    s.rate_how = how == "given"    ? "given by --rate-hz"
                 : how == "time_s" ? "from the median step of time_s"
                                   : "assumed 1 Hz (no --rate-hz, no time_s column)";
    s.time_note = NonUniformTimeNote(table);
    if (s.y.size() < 64) {
      throw DataError(a.input + ": " + std::to_string(s.y.size()) +
                      " samples; the study needs at least 64 (a 70/30 split with 32 training and "
                      "16 test samples, "
                      "and room for the decomposition)");
    }
    s.time_h = Eigen::VectorXd::LinSpaced(s.y.size(), 0.0, static_cast<double>(s.y.size() - 1)) /
               (3600.0 * s.rate_hz);
    say(fmt::format("1. read {}: {} samples of {} at {} Hz ({})\n", a.input, s.y.size(),
                    s.target_name, Fmt(s.rate_hz), s.rate_how));
    if (!s.time_note.empty()) say("   " + s.time_note + "\n");
  }
  stage_done(user ? "read" : "simulate A and B", t0);

  // 2. Decomposition and selection (for display; the models decompose their own training data).
  bar.BeginStage(1, "BEEMDAN decomposition and mode selection");
  t0 = std::chrono::steady_clock::now();
  DecomposeStep(a, s);
  stage_done("decompose + select", t0);
  say(fmt::format("2. {}\n   {}\n", s.decomposition.report.Summary(), s.selection.Summary()));

  // 3. Predict mode, both protocols.
  bar.BeginStage(2, "predict mode");
  t0 = std::chrono::steady_clock::now();
  {
    drift::DriftOptions o = BaseOptions(a, s.rate_hz);
    o.mode = drift::Mode::kPredict;
    drift::EvaluationOptions e;
    e.methods.clear();
    for (drift::Method m : methods) {
      if (drift::SupportsMode(m, drift::Mode::kPredict)) e.methods.push_back(m);
    }
    e.causal.window = a.window;
    e.causal.threads = a.threads;
    e.causal.ensemble_size = a.ensemble;
    e.progress = TrialProgress(bar, e.methods, drift::Mode::kPredict, "predict: ");
    s.predict = drift::Evaluate(s.y, s.temperature, s.truth, o, e);
  }
  stage_done("predict mode (both protocols)", t0);
  FillPredictTable(s);
  say("3. " + s.predict_table.Text());

  // 4. Compensate mode.
  bar.BeginStage(3, "compensate mode");
  t0 = std::chrono::steady_clock::now();
  if (s.simulated) {
    CompensateSimulated(a, methods, s, bar);
  } else {
    CompensateSplit(a, methods, s, bar);
  }
  stage_done("compensate mode", t0);
  FillCompensateTable(s);
  say("4. " + s.compensate_table.Text());

  // 5. Allan deviation.
  bar.BeginStage(4, "Allan deviation");
  t0 = std::chrono::steady_clock::now();
  AllanStep(a, s);
  stage_done("Allan deviation + noise fits", t0);
  say("5. " + s.terms_table.Text());

  // 6. Files.
  bar.BeginStage(5, "writing " + a.output);
  t0 = std::chrono::steady_clock::now();
  Table& settings = s.settings_table;
  settings.title = "Settings of this run";
  settings.header = {"setting", "value"};
  const drift::DriftOptions base = BaseOptions(a, s.rate_hz);
  settings.Add(
      {"source", s.simulated
                     ? "simulation: navigation preset, programmes chamber (A) and chamber-b (B)"
                     : s.source});
  if (s.simulated) {
    settings.Add({"duration, rate", Fmt(duration_s / 3600.0) + " h per run at 1 Hz (" +
                                        std::to_string(s.a.samples) + " samples)"});
  } else {
    // The rate sets every time axis and the thermal time constants: say where it came from.
    settings.Add({"columns", "output " + s.target_name + " (" + s.unit + "), temperature " +
                                 s.temperature_name});
    settings.Add({"samples, rate", std::to_string(s.y.size()) + " samples at " + Fmt(s.rate_hz) +
                                       " Hz (" + s.rate_how + "), " +
                                       Fmt(s.time_h[s.time_h.size() - 1]) + " h"});
  }
  settings.Add({"seed", std::to_string(a.seed) +
                            (s.simulated ? " (run A), " + std::to_string(a.seed + 1) + " (run B)"
                                         : " (decomposition and learners)")});
  settings.Add(
      {"decomposition", "BEEMDAN, ensemble " + std::to_string(a.ensemble) +
                            " (also in each causal window), noise 0.2, energy-band bound"});
  settings.Add({"selection", "PDF similarity (L2), Monte-Carlo level from " +
                                 std::to_string(a.realisations) + " white-noise realisations"});
  settings.Add(
      {"learner", "ELM sigmoid, hidden units <= " + std::to_string(base.learner.elm.hidden_units) +
                      " and ridge by leave-one-out; SVR/BP/poly library defaults"});
  settings.Add({"predict mode", std::to_string(base.features.lags) +
                                    " lags, split 70/30, causal window " +
                                    std::to_string(a.window) + " samples"});
  settings.Add(
      {"compensate mode",
       std::string("thermal models identified from the calibration run") +
           ", estimate referenced to " +
           (std::isnan(base.reference_c) ? std::string("the fitted intercept (user log)")
                                         : "equilibrium at " + Fmt(base.reference_c) + " degC")});
  settings.Add({"threads", a.threads == 0 ? "all cores" : std::to_string(a.threads)});
  Table& timing = s.timing_table;
  timing.title = "Wall time of each stage";
  timing.header = {"stage", "seconds"};
  for (const auto& [name, sec] : s.stage_s) timing.Add({name, {sec, 3}});
  timing.Add({"total until the report (files written after)", {Seconds(wall_start), 3}});

  std::vector<std::pair<std::string, std::string>> files;
  const std::string dir = a.output;
  auto path = [&](const std::string& name) { return (std::filesystem::path(dir) / name).string(); };
  if (s.simulated) {
    files.push_back({path("run_a.csv"), SimCsv(s.a)});
    files.push_back({path("run_b.csv"), SimCsv(s.b)});
  }
  {
    std::vector<io::CsvColumn> c{{"time_s", s.time_h * 3600.0}};
    for (int k = 0; k < s.decomposition.num_imfs(); ++k)
      c.push_back({"imf" + std::to_string(k + 1), s.decomposition.imfs.col(k)});
    c.push_back({"residue", s.decomposition.residue});
    for (const auto& g : s.selection.groups)
      c.push_back({"group_" + std::string(sel::ToString(g.kind)), g.series});
    files.push_back({path("imfs.csv"), io::RenderCsv(c)});
    Table sc;
    sc.header = {"k",           "group",       "pdf_distance",   "self_distance",
                 "noise_level", "log2_energy", "band_log2_upper"};
    auto at = [](const std::vector<double>& v, int k) {
      return k < static_cast<int>(v.size()) ? v[static_cast<size_t>(k)]
                                            : std::numeric_limits<double>::quiet_NaN();
    };
    for (int k = 0; k < s.decomposition.num_imfs(); ++k) {
      sc.Add({std::to_string(k + 1), GroupOf(s.selection, k + 1), at(s.selection.pdf_distance, k),
              at(s.selection.self_distance, k), at(s.selection.noise_level, k),
              at(s.selection.log2_energy, k), at(s.selection.energy_band_log2_upper, k)});
    }
    files.push_back({path("selection.csv"), sc.Csv()});
  }
  files.push_back({path("predict_table.csv"), s.predict_table.Csv()});
  files.push_back({path("compensate_table.csv"), s.compensate_table.Csv()});
  files.push_back({path("noise_terms.csv"), s.terms_table.Csv()});
  {
    const Eigen::Index split = s.predict.split_index;
    std::vector<io::CsvColumn> c{{"time_s", s.time_h.tail(s.y.size() - split) * 3600.0},
                                 {s.simulated ? "drift_dph" : "reference", s.predict.reference}};
    for (const auto& r : s.predict.rows) {
      c.push_back(
          {std::string(drift::ToString(r.method)) + "_" + std::string(drift::ToString(r.protocol)),
           r.estimate});
    }
    files.push_back({path("predict_estimates.csv"), io::RenderCsv(c)});
  }
  {
    std::vector<io::CsvColumn> c{{"time_s", s.comp_time_h * 3600.0},
                                 {"output", s.comp_raw},
                                 {s.simulated ? "drift_dph" : "reference", s.comp_reference}};
    for (const auto& r : s.compensate) {
      c.push_back({std::string(drift::ToString(r.method)) + (s.simulated ? "" : "_" + r.protocol) +
                       "_estimate",
                   r.estimate});
    }
    files.push_back({path("compensate_estimates.csv"), io::RenderCsv(c)});
  }
  files.push_back({path("allan.csv"), AllanCsv(s)});
  for (const auto& [name, json] : s.model_files) files.push_back({path(name), json});

  const std::string html = RenderReport(s, assets);
  files.push_back({path("report.html"), html});
  nlohmann::json sidecar = SidecarHeader("demo");
  sidecar["options"] = {{"output", a.output},     {"input", a.input},
                        {"target", a.target},     {"temperature", a.temperature},
                        {"rate_hz", s.rate_hz},   {"rate_source", s.rate_how},
                        {"units", a.units},       {"duration_s", s.simulated ? duration_s : 0.0},
                        {"ensemble", a.ensemble}, {"realisations", a.realisations},
                        {"window", a.window},     {"methods", a.methods},
                        {"seed", a.seed},         {"threads", a.threads}};
  sidecar["drift_options"] = io::DriftOptionsToJson(base);
  sidecar["decomposition"] = s.decomposition.report.Summary();
  sidecar["selection"] = s.selection.Summary();
  sidecar["stages_s"] = nlohmann::json::object();
  for (const auto& [name, sec] : s.stage_s) sidecar["stages_s"][name] = sec;
  sidecar["compensated_by"] = s.compensated_by;
  const std::string sidecar_text = sidecar.dump(2) + "\n";
  files.push_back({path("demo.json"), sidecar_text});

  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(dir) / "models", ec);
  if (ec) throw IoError(dir + ": cannot create the output folder (" + ec.message() + ")");
  io::WriteFilesAtomically(files);
  bar.Finish();
  if (!a.quiet) {
    fmt::print("6. wrote {} files to {} (report: {}, {:.1f} MB) in {:.1f} s of wall time\n",
               files.size(), dir, path("report.html"), static_cast<double>(html.size()) / 1e6,
               Seconds(wall_start));
  }
}

const RegisterCommand kRegister("demo", 5, [](CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo", "The whole study in one command: simulate, decompose, model, compensate, report.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift demo                       # simulated FOG, about 30 s on 2 cores -> "
      "./gyrodrift-demo/\n"
      "  gyrodrift demo -o /tmp/study\n"
      "  gyrodrift demo --input log.csv --target gyro_x --temperature temp --rate-hz 1\n"
      "Writes run_a.csv, run_b.csv (simulation), imfs.csv, selection.csv, predict_table.csv,\n"
      "compensate_table.csv, predict_estimates.csv, compensate_estimates.csv, allan.csv,\n"
      "noise_terms.csv, models/<method>_compensate.json, demo.json and report.html (open it in a\n"
      "browser; it works offline). The study's size options (--duration, --ensemble, --window,\n"
      "--realisations, --methods) trade fidelity for time; docs/demo.md lists the defaults' cost.");
  cmd->add_option("-o,--output", args->output, "output folder (created if needed)")
      ->capture_default_str();
  cmd->add_option("--input", args->input,
                  "a uniformly sampled CSV log of your own instead of the simulation")
      ->check(kInputFile);
  cmd->add_option("--target", args->target,
                  "with --input: the gyro output column (name or 1-based index)");
  cmd->add_option("--temperature", args->temperature, "with --input: the temperature column");
  args->rate_option =
      cmd->add_option("--rate-hz", args->rate_hz,
                      "with --input: sample rate, Hz (default: from a time_s column, else 1)");
  cmd->add_option("--units", args->units,
                  "unit of the --input target for the Allan noise terms: dph|dps|rads")
      ->capture_default_str();
  cmd->add_option("--seed", args->seed,
                  "seed of the simulation (run B uses seed + 1), decomposition and learners")
      ->capture_default_str()
      ->check(kSeed);
  cmd->add_option("--threads,-j", args->threads, "worker threads (0 = all cores)")
      ->capture_default_str();
  cmd->add_flag("--quiet,-q", args->quiet, "no progress bar and no tables on the terminal");
  cmd->add_option("--duration", args->duration,
                  "advanced: length of each simulated run, at least 2h (2h, 150min, 8h)")
      ->capture_default_str()
      ->group("Advanced");
  cmd->add_option("--ensemble", args->ensemble, "advanced: BEEMDAN ensemble size")
      ->capture_default_str()
      ->group("Advanced");
  cmd->add_option("--realisations", args->realisations,
                  "advanced: white-noise realisations of the selection's Monte-Carlo level (>= 20)")
      ->capture_default_str()
      ->group("Advanced");
  cmd->add_option("--window", args->window,
                  "advanced: trailing window of the causal protocol, samples")
      ->capture_default_str()
      ->group("Advanced");
  cmd->add_option("--methods", args->methods, "advanced: all, or a list such as ms-elm,elm,poly")
      ->capture_default_str()
      ->group("Advanced");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
