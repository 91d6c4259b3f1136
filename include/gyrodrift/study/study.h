// The thermal-drift study: one pipeline from a gyro record to comparison tables, fitted
// compensation models and the data of every figure, behind `gyrodrift demo`. study_files.h
// renders and writes its files and its HTML report.
//
// What it computes (docs/demo.md gives the choices and the measured results)
//   0. Data: two simulated runs of a navigation-grade FOG (simulation::Preset::kNavigation, 1 Hz)
//      through the programmes 'chamber' (run A, seed S) and 'chamber-b' (run B, seed S + 1); or a
//      user's log (StudyLog).
//   1. BEEMDAN decomposition of the analysed record (run A or the log) and the PDF-similarity
//      grouping (for display: the models decompose their own training data).
//   2. Predict mode: drift::Evaluate, 70/30 chronological split, paper and causal protocols,
//      scored against the true drift (simulation) or the measured output (log).
//   3. Compensate mode: every method fitted on run A (FitDriftModel) and applied to run B's
//      temperature (EstimateDrift); for a log, drift::Evaluate's chronological split under both
//      protocols, and the saved models fitted on the whole log.
//   4. Allan deviation (overlapping, octave grid, 68.3 % bands) of the compensate-mode test
//      record raw and compensated, and IEEE 952 noise terms fitted to each (allan::IdentifyNoise).
// References: Chen & Cui, Signal Processing 128 (2016) for MS-ELM; IEEE Std 952-1997 for the
// noise terms; docs/drift.md for the models and protocols.
// Units: the simulated output is in deg/h, a log's in StudyOptions::units; temperatures in degC
// (a log's in whatever unit it has); times in s (hours on the time axes of the result).
// Cost: dominated by the causal protocol, `causal.windows` BEEMDANs of up to `causal.window`
// samples and their mirrored tails per test sample for each decomposing method (ms-elm,
// emd-elm): the defaults take about 30 s on 2 cores.
// Nothing here reads files or prints: RunStudy reports through its StudyContext, which also holds
// the worker threads; StudyOptions are plain values (comparable with ==) that decide the result.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/allan/noise_fit.h"
#include "gyrodrift/decomposition/decomposition.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/evaluation.h"
#include "gyrodrift/selection/selection.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/study/table.h"

namespace gyrodrift::study {

// The seed of the simulated run B (a different thermal history, the held-out run): derived from
// the study's seed by the named path "run-b" (common/random.h), so it never coincides with run A's.
std::uint64_t RunBSeed(std::uint64_t seed);

// The size of the study. The defaults are smaller than the library's (docs/demo.md, "Settings
// and cost"): they keep the simulated study near 30 s on 2 cores. Ranges the library owns are
// checked by the library's own Validate (named as it names them); the rest here.
struct StudyOptions {
  // Length of each simulated run, s; at least 7200 (run A must show the model a ramp and a dwell
  // at a new level: the chamber programme ramps from 30 to 70 min; on shorter runs the level and
  // rate responses cannot be told apart). Default 8 h. Not used for a log.
  double duration_s = 8 * 3600.0;
  // BEEMDAN ensemble size of the study's decompositions (the causal windows take CausalOptions'
  // own, 1 realisation; the study's 20 until 2026-11-28); in [1, 10000], a bound on a study's
  // cost (DecompositionOptions' is 100000). Default 20 (the library's is 100).
  int ensemble_size = 20;
  // White-noise realisations of the selection's Monte-Carlo level; MonteCarloOptions' range
  // [20, 100000]. Default 20, the least the level estimator accepts.
  int realisations = 20;
  // The causal protocol's windows: CausalOptions' defaults and ranges but the longest window,
  // 256 samples (the library's is 2896), the cost of each of the test block's windows. 128 until
  // 2026-11-28, when one window of 128 samples with the study's 20 realisations cost more than
  // six of 256 down to 128 with one each (docs/demo.md).
  drift::CausalOptions causal{.window = 256};
  // The methods compared: each a method of compensate mode (predict mode runs those it
  // supports), none twice (each saves one model file). Default: all, in drift::AllMethods order.
  std::vector<drift::Method> methods = drift::AllMethods(drift::Mode::kCompensate);
  // Unit of the analysed output, for the Allan noise terms (reported in deg/h). The simulated
  // output is in deg/h, so any other value only fits a log (see the note in docs/demo.md).
  allan::RateUnit units = allan::RateUnit::kDegPerHour;
  // Seed of the simulation (run B uses RunBSeed(seed)), the decompositions and the learners.
  // Default 1.
  std::uint64_t seed = 1;

  // Throws OptionError naming the field (duration_s, ensemble_size, realisations, methods,
  // causal.window, ...).
  void Validate() const;
  bool operator==(const StudyOptions&) const = default;
};

// A user's log for the study: one gyro output and one temperature channel, uniformly sampled.
struct StudyLog {
  std::string source;            // where it came from (a file name): report, settings, models
  std::string target_name;       // the output column, named in the saved models
  std::string temperature_name;  // the temperature column, named in the saved models
  Eigen::VectorXd output;        // in StudyOptions::units; at least 64 samples
  Eigen::VectorXd temperature;   // one per output sample, any unit (degC for reference_c)
  double rate_hz = 1.0;          // sample rate; FeatureOptions' range [1e-9, 1e6]
  std::string rate_source;       // how the rate was found, shown beside it ("given")
  std::string time_note;         // a note on a non-uniform time axis (one line), or empty
  double read_s = 0.0;           // seconds the caller took to read it (the timing table's "read")
};

// The stages RunStudy reports, in order: 0 data, 1 decomposition and selection, 2 predict mode,
// 3 compensate mode, 4 Allan deviation.
inline constexpr int kStudyStages = 5;

// How RunStudy runs and what it reports as it goes; nothing here changes a result (but the
// timings). The study's own Execution: its progress names the stage, and a stage's results are
// reported when it ends.
struct StudyContext {
  // Worker threads of every step (decompositions, causal windows, fits, Allan deviations), in
  // [0, 1024]; 0 (default) = every core. Recorded in the settings table.
  int threads = 0;
  // Progress: the stage (in [0, kStudyStages); RunDemo adds kStudyStages, writing the files),
  // the fraction of it done in [0, 1] and what is being done. Called with fraction 0 when a stage
  // begins; never concurrently, from the calling thread or a worker. The fraction weighs each
  // evaluation trial by its expected cost, not by its count. May be empty (default); throw from it
  // to cancel the study.
  std::function<void(int stage, double fraction, const std::string& what)> progress = {};
  // A finished stage's results as the text `gyrodrift demo` prints: "1. simulated run A: ...",
  // the tables of stages 2-4 (Table::Text), each ending in a newline. May be empty (default).
  std::function<void(int stage, const std::string& summary)> stage_done = {};
};

// A file the study writes: its name under the output folder ("/"-separated) and its contents.
struct StudyFile {
  std::string name;
  std::string contents;
};

// Everything the study produced: the files, the report and a caller's own analysis read it.
struct StudyResult {
  StudyOptions options;
  int threads = 0;                    // StudyContext::threads, as asked (0 = every core)
  drift::DriftOptions drift_options;  // the models' options (method and mode set per model)
  bool simulated = false;
  std::string source;            // "simulation" or StudyLog::source
  std::string target_name;       // the analysed column
  std::string unit;              // of the analysed output ("deg/h", "deg/s", "rad/s")
  std::string temperature_name;  // the temperature column (what a saved model reads)
  double rate_hz = 1.0;
  std::string rate_source;  // how the rate was found
  std::string time_note;    // a log's non-uniform time axis, empty otherwise
  // Simulation: runs A and B (empty for a log).
  simulation::SimulationResult run_a, run_b;
  // The analysed record: run A or the log; truth is run A's drift (empty for a log).
  Eigen::VectorXd output, temperature, truth, time_h;
  decomposition::Decomposition decomposition;
  selection::SelectionResult selection;
  drift::EvaluationResult predict;
  // A log's compensate-mode evaluation (chronological split); empty for the simulation.
  drift::EvaluationResult compensate_split;
  struct CompensateRow {
    drift::Method method = drift::Method::kMsElm;
    std::string protocol;  // "train A test B", or the split's "paper" / "causal"
    drift::Metrics metrics;
    double share_removed = 0.0;  // 1 - RMS(error) / RMS(reference); negative: adds error
    double train_s = 0.0, estimate_s = 0.0;
    Eigen::VectorXd estimate;  // on the test record
    std::string summary;       // the model's one-line summary
    // Share of the reference's slow variation removed (drift::SlowVariationRemoved; NaN for a
    // test record shorter than 10 min).
    double slow_removed = std::numeric_limits<double>::quiet_NaN();
  };
  std::vector<CompensateRow> compensate;
  // The compensate-mode test record: run B or the log's last 30 %.
  Eigen::VectorXd compensate_reference;  // run B's true drift, or the measured output
  Eigen::VectorXd compensate_time_h;
  Eigen::VectorXd compensate_output;  // the raw gyro output
  // The compensation models to save ("models/<method>_compensate.json", io::RenderModelFile).
  std::vector<StudyFile> model_files;
  // Allan deviation of the test record: raw, compensated by compensated_by, compensated by
  // best_by (when another method is clearly better) and the simulated noise alone.
  allan::AllanResult allan_raw, allan_compensated, allan_best, allan_noise;
  std::optional<allan::NoiseTerms> terms_raw, terms_compensated, terms_best, terms_noise;
  std::string terms_note;       // noise fits that failed, "; "-separated
  std::string compensated_by;   // "ms-elm (causal)"; the first method if ms-elm did not run
  std::string best_by;          // the lowest-RMSE method if clearly better, else empty
  Table predict_table, compensate_table, terms_table, settings_table, timing_table;
  std::vector<std::pair<std::string, double>> stage_s;  // wall seconds per stage
};

// The simulated study. Throws what StudyOptions::Validate throws, and OptionError naming
// `threads` for a context's thread count out of range, before any work.
StudyResult RunStudy(const StudyOptions& options, const StudyContext& context = {});
// The study of a user's log. Also throws DataError for fewer than 64 samples or a temperature
// of another length, and what DriftOptions::Validate throws for the rate.
StudyResult RunStudy(const StudyOptions& options, const StudyLog& log,
                     const StudyContext& context = {});

}  // namespace gyrodrift::study
