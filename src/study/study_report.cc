// The study's HTML report: the text, tables and figures of html::HtmlReport, each figure with a
// caption saying what to look at.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "gyrodrift/simulation/gyro_noise.h"
#include "gyrodrift/study/study_files.h"
#include "study_steps.h"

namespace gyrodrift::study {
namespace {

namespace sim = gyrodrift::simulation;
namespace sel = gyrodrift::selection;

html::ReportSeries Series(std::string name, Eigen::VectorXd v, bool dashed = false) {
  html::ReportSeries s;
  s.name = std::move(name);
  s.values = std::move(v);
  s.dashed = dashed;
  return s;
}

html::ReportSeries Reference(std::string name, Eigen::VectorXd v) {
  html::ReportSeries s = Series(std::move(name), std::move(v));
  s.emphasis = true;
  return s;
}

// A user's measured output is as noisy as the predictions: drawn thick and black on top it hides
// them, so it goes first (underneath) in light grey.
html::ReportSeries Measured(std::string name, Eigen::VectorXd v) {
  html::ReportSeries s = Series(std::move(name), std::move(v));
  s.color = "#aaaaaa";
  return s;
}

// A figure over time in hours: every figure's frame but its series and caption.
html::ReportFigure TimeFigure(std::string title, std::string y_label, Eigen::VectorXd x_h) {
  html::ReportFigure f;
  f.title = std::move(title);
  f.x_label = "time (h)";
  f.y_label = std::move(y_label);
  f.x = std::move(x_h);
  return f;
}

// The paper and causal rows of a single model are one computation (it never decomposes): a figure
// draws one of them.
bool DuplicateRow(drift::Method method, const std::string& protocol) {
  return !drift::UsesDecomposition(method) && protocol == drift::ToString(drift::Protocol::kCausal);
}

// A compensate row's curve: the method, and its protocol where a log's evaluation has two.
std::string CompensateRowName(const StudyResult& s, const StudyResult::CompensateRow& r) {
  const bool both = !s.simulated && drift::UsesDecomposition(r.method);
  return std::string(drift::ToString(r.method)) + (both ? " " + r.protocol : "");
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

void AllanFigure(html::HtmlReport& report, const StudyResult& s) {
  if (s.allan_raw.points.empty()) return;
  html::ReportFigure f;
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
    html::ReportSeries series = Series(name, r.dev());
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
  add("compensated: " + s.compensated_by, s.allan_compensated, kMsElm);
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
  model("IEEE 952 fit, compensated: " + s.compensated_by, s.terms_compensated, kMsElm);
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

// The opening: what was analysed and the method.
void AddIntroduction(html::HtmlReport& report, const StudyResult& s) {
  report.AddParagraph(
      s.simulated
          ? "A navigation-grade fibre optic gyro (1 km coil, quadrupole winding) is simulated at " +
                RoundedText(s.rate_hz) +
                " Hz through two thermal-chamber programmes: run A ('chamber') to train and "
                "evaluate, run B ('chamber-b', another thermal history) to test compensation. The "
                "simulator "
                "keeps the true drift apart from the noise, so every model is scored against the "
                "truth."
          : "The log " + s.source + " (column " + s.target_name + ", " + RoundedText(s.rate_hz) +
                " Hz, rate " + s.rate_source +
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
}

// Section 1's first figure: the analysed output (and the truth), its predict-mode test block
// shaded.
html::ReportFigure OutputFigure(const StudyResult& s) {
  const double split_h = s.predict.split_index < s.time_h.size() ? s.time_h[s.predict.split_index]
                                                                 : s.time_h[s.time_h.size() - 1];
  const double end_h = s.time_h[s.time_h.size() - 1];
  html::ReportFigure f =
      TimeFigure(s.simulated ? "Run A: gyro output and true thermal drift" : "Gyro output",
                 s.target_name + " (" + s.unit + ")", s.time_h);
  f.series.push_back(Series("output", s.output));
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
  return f;
}

html::ReportFigure TemperatureFigure(const StudyResult& s) {
  // A user's temperature column may be in any unit (raw counts, for one): its name, not a unit.
  html::ReportFigure f =
      TimeFigure(s.simulated ? "Run A: temperatures" : "Temperature channel",
                 s.simulated ? "temperature (degC)" : s.temperature_name, s.time_h);
  if (s.simulated) {
    f.series.push_back(Series("chamber", s.run_a.chamber_c));
    f.series.push_back(Series("case sensor (model input)", s.run_a.temperature_c));
    f.series.push_back(Series("coil mean (truth)", s.run_a.coil_mean_c));
  } else {
    f.series.push_back(Series("temperature", s.temperature));
  }
  f.caption =
      s.simulated
          ? "The chamber programme, the case sensor a user logs (the only temperature the "
            "models see) and the true mean coil temperature, which lags the case by minutes."
          : "The temperature column the compensate-mode models use.";
  return f;
}

// Simulated studies only.
html::ReportFigure RunBFigure(const StudyResult& s) {
  html::ReportFigure f =
      TimeFigure("Run B: gyro output, true drift and temperature (test run for compensation)",
                 "deg/h", s.run_b.time_s / 3600.0);
  f.y2_label = "case sensor (degC)";
  f.series.push_back(Series("output", s.run_b.rate_dph));
  f.series.push_back(Reference("true drift", s.run_b.drift_dph));
  html::ReportSeries t = Series("case sensor (right axis)", s.run_b.temperature_c);
  t.right_axis = true;
  f.series.push_back(t);
  f.caption =
      "Run B uses a different programme (slower ramps, other levels), so a compensation "
      "model trained on run A meets a thermal history it has not seen.";
  return f;
}

void AddRecordSection(html::HtmlReport& report, const StudyResult& s) {
  report.AddHeading(s.simulated ? "1. The simulated runs" : "1. The record");
  report.AddFigure(OutputFigure(s));
  report.AddFigure(TemperatureFigure(s));
  if (s.simulated) report.AddFigure(RunBFigure(s));
}

html::ReportFigure SelectionCurvesFigure(const StudyResult& s) {
  const int k_count = s.decomposition.num_imfs();
  html::ReportFigure f;
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
      Series("family-wise 99 % level of G_k (right axis)", vec(s.selection.noise_level), true));
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
  return f;
}

html::ReportFigure EnergyFigure(const StudyResult& s) {
  const int k_count = s.decomposition.num_imfs();
  html::ReportFigure f;
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
  return f;
}

html::ReportFigure GroupsFigure(const StudyResult& s) {
  html::ReportFigure f =
      TimeFigure("The grouped sub-series (noise + mixed + drift = output)", s.unit, s.time_h);
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
  f.caption = s.simulated
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
  return f;
}

// IMF k (0-based), captioned by its group.
html::ReportFigure ImfFigure(const StudyResult& s, int k) {
  const std::string group = internal::GroupOf(s.selection, k + 1);
  html::ReportFigure f =
      TimeFigure("IMF " + std::to_string(k + 1) + " (" + group + " group)", s.unit, s.time_h);
  f.height_px = 150;
  f.series.push_back(Series("imf" + std::to_string(k + 1), s.decomposition.imfs.col(k)));
  f.caption = group == "noise"
                  ? "Noise group: should look like noise of steady amplitude, with no trace of the "
                    "temperature programme."
              : group == "mixed"
                  ? "Mixed group: noise with slower structure in it; look for swings that line "
                    "up with the temperature changes."
                  : "Drift group: slow structure that should follow the temperature history.";
  // Only a series longer than the plotted rows is decimated (html::DecimateMinMax).
  const Eigen::Index n = s.time_h.size();
  if (n > f.max_points) {
    f.caption += " Plotted as the min and max of each run of " +
                 RoundedText(static_cast<double>(n) / (f.max_points / 2), 3) + " samples.";
  }
  return f;
}

html::ReportFigure ResidueFigure(const StudyResult& s) {
  html::ReportFigure f = TimeFigure("Residue", s.unit, s.time_h);
  f.height_px = 150;
  f.series.push_back(Series("residue", s.decomposition.residue));
  f.caption = "The slow trend left after the last IMF (part of the drift group).";
  return f;
}

void AddDecompositionSection(html::HtmlReport& report, const StudyResult& s) {
  report.AddHeading("2. BEEMDAN decomposition and mode selection");
  report.AddParagraph(s.decomposition.report.Summary() + ". " + s.selection.Summary() + ".");
  report.AddFigure(SelectionCurvesFigure(s));
  report.AddFigure(EnergyFigure(s));
  report.AddFigure(GroupsFigure(s));
  for (int k = 0; k < s.decomposition.num_imfs(); ++k) report.AddFigure(ImfFigure(s, k));
  report.AddFigure(ResidueFigure(s));
}

// test_h: the times of the predict-mode test block.
html::ReportFigure PredictionsFigure(const StudyResult& s, const Eigen::VectorXd& test_h) {
  html::ReportFigure f =
      TimeFigure("Predict mode: one-step-ahead predictions on the test block", s.unit, test_h);
  // MS-ELM under both protocols and the best method that does not decompose (a single model or
  // a baseline); every row is in predict_estimates.csv.
  if (!s.simulated) f.series.push_back(Measured("measured output", s.predict.reference));
  const drift::EvaluationRow* best = nullptr;
  for (const auto& r : s.predict.rows) {
    if (r.method == drift::Method::kMsElm) {
      f.series.push_back(Series("ms-elm " + std::string(drift::ToString(r.protocol)), r.estimate));
    } else if (!drift::UsesDecomposition(r.method) && (!best || r.rmse < best->rmse)) {
      best = &r;
    }
  }
  if (best)
    f.series.push_back(
        Series(std::string(drift::ToString(best->method)) + " (best of the rest)", best->estimate));
  if (s.simulated) f.series.push_back(Reference("true drift", s.predict.reference));
  f.caption =
      "Each model predicts the next output sample from the previous ones (MS-ELM under both "
      "protocols and the best method that does not decompose; every method is in "
      "predict_estimates.csv). Under the "
      "paper protocol the sub-series were decomposed with the future in view. Predictions of a "
      "noisy output are noisy: zoom into a few minutes to compare them with the " +
      std::string(s.simulated ? "thick black true drift." : "grey measured output they predict.");
  return f;
}

html::ReportFigure PredictResidualsFigure(const StudyResult& s, const Eigen::VectorXd& test_h) {
  const Eigen::Index w =
      std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::lround(300.0 * s.rate_hz)), 1,
                               std::max<Eigen::Index>(1, test_h.size() / 20));
  html::ReportFigure f =
      TimeFigure("Predict mode: residuals (reference - prediction), trailing mean over " +
                     std::to_string(w) + " samples",
                 s.unit, test_h);
  for (const auto& r : s.predict.rows) {
    if (!drift::UsesDecomposition(r.method) && r.protocol == drift::Protocol::kCausal) continue;
    std::string name = std::string(drift::ToString(r.method));
    if (drift::UsesDecomposition(r.method)) name += " " + std::string(drift::ToString(r.protocol));
    f.series.push_back(Series(name, TrailingMean(s.predict.reference - r.estimate, w)));
  }
  f.caption = "Averaged over " + RoundedText(static_cast<double>(w) / s.rate_hz) +
              " s so that the sample-to-sample noise drops out: what remains is drift the model "
              "missed or a bias it added. Near zero is good; single models are one curve (the same "
              "under both protocols).";
  return f;
}

void AddPredictSection(html::HtmlReport& report, const StudyResult& s) {
  report.AddHeading("3. Predict mode (the paper's task)");
  report.AddTable(s.predict_table.Report());
  const Eigen::Index split = s.predict.split_index;
  const Eigen::VectorXd test_h = s.time_h.tail(s.time_h.size() - split);
  report.AddFigure(PredictionsFigure(s, test_h));
  report.AddFigure(PredictResidualsFigure(s, test_h));
}

html::ReportFigure CompensateEstimatesFigure(const StudyResult& s) {
  html::ReportFigure f = TimeFigure(
      s.simulated ? "Compensate mode: drift estimated from temperature on run B vs the true drift"
                  : "Compensate mode: drift estimated from temperature vs the measured output",
      s.unit, s.compensate_time_h);
  if (!s.simulated) f.series.push_back(Measured("measured output", s.compensate_reference));
  for (const auto& r : s.compensate) {
    if (!s.simulated && DuplicateRow(r.method, r.protocol)) continue;
    f.series.push_back(Series(CompensateRowName(s, r), r.estimate));
  }
  if (s.simulated) f.series.push_back(Reference("true drift (run B)", s.compensate_reference));
  f.caption =
      s.simulated
          ? "Only the temperature channel reaches these models, as on a navigation computer. A "
            "good model tracks the thick black true drift through ramps it was not trained on."
          : "Only the temperature channel reaches these models, as on a navigation computer. A "
            "good model runs through the middle of the grey measured output over the test "
            "block, which it never saw. Single models are drawn once (the same under both "
            "protocols).";
  return f;
}

html::ReportFigure CompensateResidualsFigure(const StudyResult& s) {
  html::ReportFigure f = TimeFigure("Compensate mode: residual drift (reference - estimate)",
                                    s.unit, s.compensate_time_h);
  for (const auto& r : s.compensate) {
    if (!s.simulated && DuplicateRow(r.method, r.protocol)) continue;
    f.series.push_back(Series(CompensateRowName(s, r), s.compensate_reference - r.estimate));
  }
  f.caption =
      s.simulated
          ? "What is left after compensation. Flat near zero is good; spikes at the ramps are "
            "the Shupe part the temperature history did not explain."
          : "The measured output minus the estimate, noise included. A band centred on zero "
            "is good; a trend or a step is drift the temperature history did not explain, or "
            "a bias the model added.";
  return f;
}

void AddCompensateSection(html::HtmlReport& report, const StudyResult& s) {
  report.AddHeading(s.simulated ? "4. Compensate mode: trained on run A, tested on run B"
                                : "4. Compensate mode: chronological split");
  report.AddTable(s.compensate_table.Report());
  report.AddFigure(CompensateEstimatesFigure(s));
  report.AddFigure(CompensateResidualsFigure(s));
}

}  // namespace

// The report page built from its parts, in the order of the study's steps.
std::string RenderStudyReport(const StudyResult& s, const html::DygraphsAssets& assets) {
  html::HtmlReport report(s.simulated
                              ? "gyrodrift demo: thermal drift of a simulated navigation FOG"
                              : "gyrodrift demo: " + s.source);
  AddIntroduction(report, s);
  AddRecordSection(report, s);
  AddDecompositionSection(report, s);
  AddPredictSection(report, s);
  AddCompensateSection(report, s);

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

}  // namespace gyrodrift::study
