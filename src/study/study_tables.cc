// The study's tables: what each step's results look like on the terminal, in the report and in
// the CSV files.
#include <cmath>
#include <limits>
#include <string>

#include "gyrodrift/common/check.h"
#include "gyrodrift/simulation/gyro_noise.h"
#include "study_steps.h"

namespace gyrodrift::study::internal {

void FillPredictTable(StudyResult& s) {
  Table& t = s.predict_table;
  t.title = "Predict mode: one-step-ahead prediction on the last 30 % of " +
            std::string(s.simulated ? "run A" : "the record");
  t.caption = std::string("Scored against ") +
              (s.simulated ? "the true drift (drift_dph)" : "the measured output") +
              ". paper = decompose the whole record, then split (sees the future); causal = only "
              "past samples reach a prediction (trailing-window decomposition). Single models and "
              "baselines are the same computation under both. none = a zero prediction, constant = "
              "the training mean; rmse_measured = against the measured output; slow_removed = "
              "share of the slow variation (RMS of 10-min block means) removed.";
  t.header = {"method", "protocol", "rmse",          "mae",     "max_abs",
              "rmse_measured", "slow_removed_%", "train_s", "predict_s"};
  for (const auto& r : s.predict.rows) {
    t.Add({std::string(drift::ToString(r.method)),
           std::string(drift::ToString(r.protocol)),
           r.rmse,
           r.mae,
           r.max_abs,
           r.rmse_measured,
           {100.0 * r.slow_removed, 4},
           {r.train_s, 3},
           {r.predict_s, 3}});
  }
}

void FillCompensateTable(StudyResult& s) {
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
  t.header = {"method",    "protocol",       "rmse",    "mae",       "max_abs",
              "removed_%", "slow_removed_%", "train_s", "estimate_s"};
  for (const auto& r : s.compensate) {
    t.Add({std::string(drift::ToString(r.method)),
           r.protocol,
           r.metrics.rmse,
           r.metrics.mae,
           r.metrics.max_abs,
           {100.0 * r.share_removed, 4},
           {100.0 * r.slow_removed, 4},
           {r.train_s, 3},
           {r.estimate_s, 3}});
  }
}

void FillNoiseTermsTable(StudyResult& s) {
  namespace sim = gyrodrift::simulation;
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
                                   value(s.terms_compensated, r.term)};
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
                                 min_dev(s.terms_compensated)};
  if (!s.best_by.empty()) cells.emplace_back(min_dev(s.terms_best));
  if (s.simulated) {
    cells.emplace_back(min_dev(s.terms_noise));
    cells.emplace_back(std::numeric_limits<double>::quiet_NaN());
  }
  t.Add(cells);
}

void FillSettingsTable(StudyResult& s) {
  const StudyOptions& a = s.options;
  const drift::DriftOptions& base = s.drift_options;
  Table& settings = s.settings_table;
  settings.title = "Settings of this run";
  settings.header = {"setting", "value"};
  settings.Add(
      {"source", s.simulated
                     ? "simulation: navigation preset, programmes chamber (A) and chamber-b (B)"
                     : s.source});
  if (s.simulated) {
    settings.Add({"duration, rate", RoundedText(a.duration_s / 3600.0) + " h per run at 1 Hz (" +
                                        std::to_string(s.run_a.samples) + " samples)"});
  } else {
    // The rate sets every time axis and the thermal time constants: say where it came from.
    settings.Add({"columns", "output " + s.target_name + " (" + s.unit + "), temperature " +
                                 s.temperature_name});
    settings.Add({"samples, rate", std::to_string(s.output.size()) + " samples at " +
                                       RoundedText(s.rate_hz) + " Hz (" + s.rate_source + "), " +
                                       RoundedText(s.time_h[s.time_h.size() - 1]) + " h"});
  }
  settings.Add({"seed", std::to_string(a.seed) +
                            (s.simulated ? " (run A), " + std::to_string(RunBSeed(a.seed)) + " (run B)"
                                         : " (decomposition and learners)")});
  settings.Add({"decomposition",
                "BEEMDAN, ensemble " + std::to_string(a.ensemble_size) +
                    ", noise 0.2, noise assistance bounded by the ensemble's white-noise band"});
  settings.Add({"selection", "PDF similarity (L2), Monte-Carlo level from " +
                                 std::to_string(a.realisations) + " white-noise realisations"});
  settings.Add(
      {"learner", "ELM sigmoid, hidden units <= " + std::to_string(base.learner.elm.hidden_units) +
                      " and ridge by leave-one-out; SVR/BP/poly library defaults"});
  const drift::CausalOptions& causal = a.causal;
  const std::vector<Eigen::Index> lengths = causal.WindowLengths();
  settings.Add({"predict mode",
                std::to_string(base.features.lags) + " lags, split 70/30, causal window" +
                    (lengths.size() > 1 ? "s of " + std::to_string(lengths.front()) + " down to " +
                                              std::to_string(lengths.back()) + " samples (" +
                                              std::to_string(lengths.size()) + ", ends averaged)"
                                        : " " + std::to_string(lengths.front()) + " samples") +
                    ", each with a mirrored tail " + FormatValue(causal.mirror) + " of it and " +
                    std::to_string(causal.ensemble_size) +
                    (causal.ensemble_size == 1 ? " realisation" : " realisations")});
  settings.Add(
      {"compensate mode",
       std::string("thermal models identified from the calibration run") +
           ", estimate referenced to " +
           (!base.reference_c ? std::string("the fitted intercept (user log)")
                              : "equilibrium at " + RoundedText(*base.reference_c) + " degC")});
  settings.Add({"threads", s.threads == 0 ? "all cores" : std::to_string(s.threads)});
}

void FillTimingTable(StudyResult& s, double total_s) {
  Table& timing = s.timing_table;
  timing.title = "Wall time of each stage";
  timing.header = {"stage", "seconds"};
  for (const auto& [name, sec] : s.stage_s) timing.Add({name, {sec, 3}});
  timing.Add({"total until the report (files written after)", {total_s, 3}});
}

}  // namespace gyrodrift::study::internal
