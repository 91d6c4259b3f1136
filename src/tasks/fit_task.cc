#include "gyrodrift/tasks/fit_task.h"

#include <fmt/core.h>

#include <utility>

#include "gyrodrift/allan/allan.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"

namespace gyrodrift::tasks {

FitRun AssembleFitRun(const std::vector<TaskLog>& logs, const std::string& target,
                      const std::string& temperature, const io::LogOptions& log,
                      const std::string& target_option, const std::string& temperature_option) {
  std::vector<std::string> paths;
  for (const TaskLog& l : logs) paths.push_back(l.path);
  // A log given twice would be fitted twice and leak into its own held-out folds.
  io::RequireDistinctFiles(paths, "calibration logs",
                           "each log is one record of the calibration (give it once)");
  FitRun run;
  run.logs = logs.size();
  run.temperature_spec = temperature;
  for (const TaskLog& l : logs) {
    const SelectedColumns targets = ReadColumns(l.table, target, target_option);
    SelectedColumns temps;
    if (!temperature.empty()) temps = ReadColumns(l.table, temperature, temperature_option);
    if (run.source.empty()) {
      run.rate_hz = l.rate_hz;
      run.rate_how = l.rate_how;
    } else {
      io::RequireSameSampleRate(logs.front().path, run.rate_hz, l.path, l.rate_hz);
    }
    Eigen::MatrixXd block(l.table.rows(), targets.values.cols() + temps.values.cols());
    block.leftCols(targets.values.cols()) = targets.values;
    if (temps.values.cols() > 0) block.rightCols(temps.values.cols()) = temps.values;
    // interpolate fits on the made-up rows as data; only carry keeps the fit to the logged ones.
    run.rows.Append(block, l.record_starts,
                    log.gaps == io::GapPolicy::kCarry ? l.logged : std::vector<bool>{});
    run.source += (run.source.empty() ? "" : ",") + l.path;
    if (run.ulog.empty() && io::IsUlogFile(l.path)) run.ulog = l.path;
    run.targets = targets.names;
    run.temperatures = temps.names;
  }
  return run;
}

std::string FitResult::ModelFile() const { return io::RenderModelFile(axes); }

void CheckFitRun(const FitRun& run, const drift::DriftOptions& o, const io::LogOptions& log) {
  const bool flags = SpeltAsFlags(log);
  // The names a model file records and compensate looks up (arrays from Python come with the
  // names given for them): none empty, and no temperature's with a comma, which separates them
  // in the file (a semicolon-separated log may name its target with one).
  for (const std::string& name : run.targets) {
    if (name.empty()) ThrowOption(flags ? "--target" : "target", "''", "a column name");
  }
  for (const std::string& name : run.temperatures) {
    const char* setting = flags ? "--temperature" : "temperature";
    if (name.empty()) ThrowOption(setting, "''", "a column name");
    if (name.find(',') == std::string::npos) continue;
    ThrowOption(setting, "'" + name + "'",
                "a column name without a comma (a model file separates its temperature columns "
                "by commas)");
  }
  // The names as given (arrays from Python come without a spec: their names stand for it).
  std::string spec = run.temperature_spec;
  if (spec.empty()) {
    for (const std::string& name : run.temperatures) spec += (spec.empty() ? "" : ",") + name;
  }
  for (size_t i = 0; i < run.temperatures.size(); ++i) {
    const std::string& name = run.temperatures[i];
    for (const std::string& target : run.targets) {
      if (name != target) continue;
      throw UsageError(flags ? "--temperature = " + spec + ": must differ from --target"
                             : "temperature = " + spec + ": must differ from the target");
    }
    // As ReadColumns refuses a spec that names a column twice (arrays from Python come here).
    for (size_t j = 0; j < i; ++j) {
      if (run.temperatures[j] != name) continue;
      ThrowOption(flags ? "--temperature" : "temperature", "'" + spec + "'",
                  "a list without repeats");
    }
  }
  const std::string method(drift::ToString(o.method));
  if (!run.rows.record_starts.empty() && o.method != drift::Method::kThermal) {
    // Keys: the fleet refuses these when it reads its manifest; arrays give record_starts.
    const std::string why = run.logs > 1 ? (flags ? "several input logs" : "several calibration logs")
                            : flags     ? io::SpellGaps(log, io::GapPolicy::kSplit)
                                        : "record_starts";
    throw UsageError(
        flags ? fmt::format("--method {}: several records ({}) are fitted by --method thermal only "
                            "(a decomposition or lags would run across the breaks)",
                            method, why)
              : fmt::format("method = '{}': several records ({}) are fitted by method = "
                            "'thermal' only (a decomposition or lags would run across the breaks)",
                            method, why));
  }
  if (!run.rows.logged.empty() && !o.linear_compensation) {
    throw UsageError(flags ? "--nonlinear: the nonlinear correction needs every sample logged, not "
                             "the gaps carried (--gaps carry): use --gaps interpolate or leave "
                             "--nonlinear out"
                           : "nonlinear: the nonlinear correction needs every sample logged, not "
                             "the gaps carried (logged rows only)");
  }
  if (!run.rows.logged.empty() &&
      (o.mode != drift::Mode::kCompensate || drift::UsesDecomposition(o.method))) {
    const std::string mode(drift::ToString(o.mode));
    const std::string why = o.mode == drift::Mode::kCompensate
                                ? "a decomposition runs across the made-up rows"
                                : "a prediction from the output's past reads made-up rows";
    throw UsageError(
        flags ? fmt::format("--gaps carry: the fit uses the logged rows only, which --mode {} "
                            "--method {} cannot do ({}): use --method thermal or poly in "
                            "compensate mode, or --gaps interpolate",
                            mode, method, why)
              : fmt::format("logged: the fit uses the logged rows only, which mode '{}' method "
                            "'{}' cannot do ({}): use method thermal or poly in compensate mode",
                            mode, method, why));
  }
}

namespace {

// A ULog's rate columns are in log.ulog.units (as convert writes them): a model recording another
// unit would mislabel every estimate and export.
void RequireUlogUnit(const FitRun& run, const std::string& rate_unit, const io::LogOptions& log) {
  const std::string ulog_unit = allan::ToString(log.ulog.units);
  if (run.ulog.empty() || rate_unit == ulog_unit) return;
  throw UsageError(SpeltAsFlags(log)
                       ? fmt::format("--units {}: {} is a ULog read in --ulog-units {}: give the "
                                     "same unit to both",
                                     rate_unit, run.ulog, ulog_unit)
                       : fmt::format("units = '{}': {} is a ULog read in ulog_units = '{}': give "
                                     "the same unit to both",
                                     rate_unit, run.ulog, ulog_unit));
}

}  // namespace

FitResult RunFit(const FitRun& run, const drift::FitSettings& settings,
                 const std::string& rate_unit, const io::LogOptions& log,
                 const FitProgress& progress) {
  (void)allan::RateUnitFromString(rate_unit);  // dph | dps | rads, refused as "units"
  drift::FitSettings s = settings;
  if (run.rate_hz > 0.0) s.rate_hz = run.rate_hz;
  FitResult r;
  r.options = drift::MakeDriftOptions(s);
  Execution execution = drift::MakeExecution(s);
  CheckFitRun(run, r.options, log);
  RequireUlogUnit(run, rate_unit, log);
  const auto targets = static_cast<Eigen::Index>(run.targets.size());
  const Eigen::Index temperatures = run.rows.rows.cols() - targets;
  std::string temperature_column;
  for (size_t c = 0; c < run.temperatures.size(); ++c) {
    temperature_column += (c ? "," : "") + run.temperatures[c];
  }
  const Eigen::MatrixXd temperature = run.rows.rows.rightCols(temperatures);
  for (Eigen::Index i = 0; i < targets; ++i) {
    io::LoadedModel axis;
    axis.info.source = run.source;
    axis.info.target_column = run.targets[static_cast<size_t>(i)];
    axis.info.temperature_column = temperature_column;
    axis.info.rate_unit = rate_unit;
    if (progress) {
      progress(static_cast<int>(i), 0.0, "");  // the axis starts
      execution.progress = [&progress, i](double fraction, std::string_view step) {
        progress(static_cast<int>(i), fraction, step);
      };
    }
    try {
      axis.model = drift::FitDriftModel(run.rows.rows.col(i), temperature, r.options,
                                        run.rows.record_starts, execution, run.rows.logged);
    } catch (const OptionError& e) {
      // The library names its setting; the CLI's user typed the flag.
      if (e.option() != "temperature" || !SpeltAsFlags(log)) throw;
      throw OptionError("--temperature", e.value(), e.rule());
    } catch (const DataError& e) {
      // The library sees arrays ("target", "temperature"): the columns and logs are named here,
      // so that a fleet's unit of several axes says which one.
      throw DataError(
          fmt::format("fitting '{}'{} ({}): {}", axis.info.target_column,
                      temperature_column.empty() ? "" : " on '" + temperature_column + "'",
                      run.source, e.what()));
    }
    r.axes.push_back(std::move(axis));
  }
  return r;
}

}  // namespace gyrodrift::tasks
