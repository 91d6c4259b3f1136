#include "gyrodrift/tasks/compensate_task.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/drift/records.h"

namespace gyrodrift::tasks {
namespace {

using nlohmann::json;

json SummaryJson(const drift::SignalSummary& s) {
  return {{"mean", s.mean}, {"rms", s.rms}, {"std", s.std}, {"slow_variation", s.slow}};
}

std::string Columns(const io::CsvTable& table) {
  std::string names;
  for (const auto& h : table.header()) names += (names.empty() ? "" : ", ") + h;
  return names;
}

// One axis's part of the sidecar.
json AxisRecord(const io::LoadedModel& loaded, const AxisCompensation& c,
                const std::string& truth_column) {
  const drift::DriftModel& model = loaded.model;
  json j;
  j["model"] = {{"summary", model.Summary()},
                {"method", drift::ToString(model.options.method)},
                {"target_column", loaded.info.target_column},
                {"rate_unit", loaded.info.rate_unit},
                {"temperature_column", loaded.info.temperature_column},
                {"seed", model.options.seed},
                {"tool_version", loaded.info.tool_version}};
  j["samples"] = c.summary.samples;
  j["std_before"] = c.summary.before.std;
  j["std_after"] = c.summary.after.std;
  j["before"] = SummaryJson(c.summary.before);
  j["after"] = SummaryJson(c.summary.after);
  j["slow_variation_block_s"] = c.summary.block_s;
  j["slow_variation_blocks"] = c.summary.blocks;
  if (c.has_truth) {
    j["truth"] = {{"column", truth_column},
                  {"rms", c.truth_rms},
                  {"residual_rms", c.residual_rms},
                  {"removed_percent", 100.0 * c.truth_removed}};
  }
  j["outside_training_temperature_share"] = c.outside_share;
  if (c.identified) j["drift_sd_mean"] = c.drift_sd_mean;
  return j;
}

// One axis's console lines.
std::string AxisText(const io::LoadedModel& loaded, const AxisCompensation& c,
                     const std::vector<bool>& logged, const std::string& truth_column) {
  const drift::DriftModel& model = loaded.model;
  // Files before format 4 did not record the unit: the table then names none.
  std::string text =
      model.Summary() + "\n" + c.summary.Table(loaded.info.target_column, loaded.info.rate_unit);
  // Filled gaps: the figures leave the made-up rows out (the slow variation's blocks are blocks
  // of time, each the mean of its logged samples).
  if (!logged.empty()) {
    text += fmt::format("{}: statistics over the {} logged rows ({} made up left out)\n",
                        loaded.info.target_column, c.summary.samples,
                        logged.size() - static_cast<size_t>(c.summary.samples));
  }
  if (c.has_truth) {
    // A zero truth has no share to remove: say so instead of printing "nan %".
    const std::string share = c.truth_rms > 0.0
                                  ? fmt::format("{:.1f} % removed", 100.0 * c.truth_removed)
                                  : "no drift to remove";
    text += fmt::format("{}: RMS {:.6g}, residual after compensation {:.6g} ({})\n", truth_column,
                        c.truth_rms, c.residual_rms, share);
  }
  // A thermal model beyond the temperatures it was fitted on extrapolates: say where.
  if (c.outside_share > 0.0) {
    text += fmt::format(
        "note: {:.1f} % of the samples lie outside the training temperature range [{:.4g}, {:.4g}] "
        "degC: the estimate extrapolates there\n",
        100.0 * c.outside_share, model.temperature_min_c, model.temperature_max_c);
  }
  // A model the calibration run could not identify says so every time it is used.
  for (const auto& sub : model.sub_models) {
    if (!sub.thermal) continue;
    for (const std::string& w : sub.thermal->report.warnings) {
      text += "warning: the model's calibration run (" + sub.name + "): " + w + "\n";
    }
  }
  return text;
}

std::vector<std::string> Suffixes(const std::vector<io::LoadedModel>& axes) {
  std::vector<std::string> out;
  for (const io::LoadedModel& axis : axes) {
    out.push_back(axes.size() == 1 ? "" : "_" + axis.info.target_column);
  }
  return out;
}

// The refusals of RunCompensate that need no estimate.
void CheckLog(const std::vector<io::LoadedModel>& axes, const TaskLog& log,
              const io::LogOptions& o, const CompensateSettings& settings,
              const std::string& model_path) {
  for (const std::string& suffix : Suffixes(axes)) {
    for (const char* name : {"drift_est", "drift_sd", "compensated"}) {
      if (log.table.HasColumn(name + suffix)) {
        throw DataError(log.path + " already has a column '" + name + suffix +
                        "': compensate an uncompensated log");
      }
    }
  }
  std::string how;
  const double log_hz = io::ResolveSampleRate(log.table, settings.rate_hz, &how);
  RequireModelRate(axes, model_path, log.path, log_hz, how, SpeltAsFlags(o));
  if (!log.logged.empty() && o.gaps != io::GapPolicy::kCarry &&
      log.table.HasColumn("interpolated")) {
    throw DataError(log.path + " already has a column 'interpolated': " +
                    io::SpellGaps(o, io::GapPolicy::kInterpolate) +
                    " marks the rows it makes up in one (rename it, or use " +
                    io::SpellGaps(o, io::GapPolicy::kCarry) + ")");
  }
  if (!settings.truth.empty() && axes.size() > 1) {
    throw UsageError((SpeltAsFlags(o) ? "--truth = " : "truth = ") + settings.truth + ": " +
                     model_path + " holds " + std::to_string(axes.size()) +
                     " axes; a true drift column scores a one-axis model");
  }
  // The truth is what the estimate is scored against: the measured target, or a temperature the
  // estimate is made of, would score the model against its own input.
  if (!settings.truth.empty()) {
    const io::CsvTable& table = log.table;
    const std::string truth =
        table.header()[static_cast<size_t>(table.ResolveColumn(settings.truth))];
    const io::LoadedModel& axis = axes.front();
    std::vector<std::string> inputs{axis.info.target_column};
    if (axis.model.uses_temperature()) {
      for (const std::string& c : SplitColumns(axis.info.temperature_column)) inputs.push_back(c);
    }
    if (std::find(inputs.begin(), inputs.end(), truth) != inputs.end()) {
      throw UsageError((SpeltAsFlags(o) ? "--truth = " : "truth = ") + settings.truth +
                       ": must be another column than the model's target and temperatures (" +
                       truth + " is one of them)");
    }
  }
}

}  // namespace

void CompensateSettings::Validate() const {
  if (rate_hz != 0.0) RequireInRange("rate_hz", rate_hz, 1e-9, 1e9);
  RequireInRange("drift_window_s", drift_window_s, 1e-3, 1e9);
}

std::vector<io::CsvColumn> AxisCompensation::Columns(const std::string& suffix) const {
  std::vector<io::CsvColumn> out;
  out.push_back({"drift_est" + suffix, estimate});
  // Identified models give each estimate a standard deviation (thermal_model.h).
  if (identified) out.push_back({"drift_sd" + suffix, sd});
  out.push_back({"compensated" + suffix, compensated});
  return out;
}

AxisCompensation CompensateAxis(const io::LoadedModel& loaded, const Eigen::VectorXd& y_all,
                                const Eigen::MatrixXd& temperature_all,
                                const std::vector<Eigen::Index>& record_starts,
                                const std::vector<bool>& logged, const Eigen::VectorXd& truth_all,
                                const CompensateSettings& settings) {
  settings.Validate();
  // Arrays from Python come unchecked (a log's cells are checked when it is read).
  drift::RequireFiniteLogged("y", y_all, logged, 1);
  if (truth_all.size() > 0) drift::RequireFiniteLogged("truth", truth_all, logged, 1);
  const drift::DriftModel& model = loaded.model;
  AxisCompensation c;
  const Eigen::MatrixXd estimate_sd =
      drift::EstimateDriftWithSd(model, temperature_all, record_starts);
  c.estimate = estimate_sd.col(0);
  c.sd = estimate_sd.col(1);
  c.compensated = y_all - c.estimate;
  c.identified = model.identified();
  const Eigen::VectorXd estimate = drift::LoggedRows(c.estimate, logged);
  // The mean, RMS, std and slow variation before and after (a calibration mostly moves the
  // bias, which the std alone hides), over the logged rows, blocks timed at the model's sample
  // rate unless given.
  c.summary = drift::SummariseCompensation(
      y_all, c.compensated,
      settings.rate_hz > 0.0 ? settings.rate_hz : model.options.features.rate_hz,
      settings.drift_window_s, logged);
  // Against a known drift: how much of its RMS the estimate removes, RMS about zero (the
  // drift's offset is part of it).
  if (truth_all.size() > 0) {
    const Eigen::VectorXd truth = drift::LoggedRows(truth_all, logged);
    c.has_truth = true;
    c.truth_rms = std::sqrt(truth.squaredNorm() / static_cast<double>(truth.size()));
    c.residual_rms =
        std::sqrt((truth - estimate).squaredNorm() / static_cast<double>(truth.size()));
    c.truth_removed = c.truth_rms > 0.0 ? 1.0 - c.residual_rms / c.truth_rms
                                        : std::numeric_limits<double>::quiet_NaN();
  }
  const Eigen::MatrixXd temperature = drift::LoggedRows(temperature_all, logged);
  c.outside_share = drift::ShareOutsideRange(temperature.col(0), model.temperature_min_c,
                                             model.temperature_max_c);
  if (c.identified) c.drift_sd_mean = drift::LoggedRows(c.sd, logged).mean();
  return c;
}

void RequireModelColumns(const io::LoadedModel& loaded, const io::CsvTable& table) {
  auto require = [&](const std::string& column, const char* option) {
    if (table.HasColumn(column)) return;
    throw DataError("model needs column '" + column + "' (trained with " + option + " " + column +
                    "); " + table.source() + " has: " + Columns(table));
  };
  require(loaded.info.target_column, "--target");
  if (loaded.model.uses_temperature()) {
    for (const std::string& c : SplitColumns(loaded.info.temperature_column)) {
      require(c, "--temperature");
    }
  }
}

void RequireModelRate(const std::vector<io::LoadedModel>& axes, const std::string& model_path,
                      const std::string& log_path, double log_hz, const std::string& how,
                      bool flags) {
  for (const io::LoadedModel& axis : axes) {
    RequireRateOfModel(log_path, log_hz, how, flags, model_path,
                       axis.model.options.features.rate_hz, [](double ratio) {
                         return fmt::format(
                             "its thermal lags and temperature rates would run {:.3g} times too {}",
                             ratio > 1.0 ? ratio : 1.0 / ratio, ratio > 1.0 ? "fast" : "slow");
                       });
  }
}

void RequireCompensateMode(const std::vector<io::LoadedModel>& axes,
                           const std::string& model_path) {
  for (const io::LoadedModel& axis : axes) {
    if (axis.model.options.mode != drift::Mode::kCompensate) {
      throw UsageError(model_path +
                       " is a predict-mode model: use 'gyrodrift predict' (compensate "
                       "needs a model fitted with --mode compensate)");
    }
  }
}

std::vector<std::string> CompensateWarnings(const std::vector<io::LoadedModel>& axes,
                                            const TaskLog& log, const io::LogOptions& o) {
  for (const io::LoadedModel& axis : axes) RequireModelColumns(axis, log.table);
  std::vector<std::string> temperature_columns;  // each column once
  for (const io::LoadedModel& axis : axes) {
    if (!axis.model.uses_temperature()) continue;
    for (const std::string& c : SplitColumns(axis.info.temperature_column)) {
      if (std::find(temperature_columns.begin(), temperature_columns.end(), c) ==
          temperature_columns.end()) {
        temperature_columns.push_back(c);
      }
    }
  }
  return LogWarnings(log, "", temperature_columns,
                     SpeltAsFlags(o) ? Audience::kFlags : Audience::kManifest);
}

CompensateResult RunCompensate(const std::vector<io::LoadedModel>& axes, const TaskLog& log,
                               const io::LogOptions& o, const CompensateSettings& settings,
                               const std::string& model_path) {
  RequireCompensateMode(axes, model_path);
  for (const io::LoadedModel& axis : axes) RequireModelColumns(axis, log.table);
  CheckLog(axes, log, o, settings, model_path);
  const io::CsvTable& table = log.table;
  // Read before the work, so a misspelt column fails fast.
  const std::string truth_column =
      settings.truth.empty() ? ""
                             : table.header()[static_cast<size_t>(table.ResolveColumn(settings.truth))];
  const Eigen::VectorXd truth = settings.truth.empty() ? Eigen::VectorXd() : table.Column(settings.truth);
  const bool carry = !log.logged.empty() && o.gaps == io::GapPolicy::kCarry;
  const bool mark_made_up = !log.logged.empty() && !carry;  // column `interpolated`

  CompensateResult r;
  if (!log.gap_note.empty()) r.text = log.gap_note + "\n";
  for (int c = 0; c < static_cast<int>(table.header().size()); ++c) {
    r.columns.push_back({table.header()[static_cast<size_t>(c)], table.Column(c)});
  }
  r.record["options"] = {{"model", model_path},
                         {"input", log.path},
                         {"gaps", io::ToString(o.gaps)},
                         {"records", log.record_starts.size() + 1}};
  // Made-up rows: the statistics leave them out; the output marks them (interpolate) or leaves
  // them out too (carry: one output row per logged row, as for a log without gaps).
  const Eigen::Index logged_rows = drift::CountLogged(log.logged, table.rows());
  r.record["rows"] = {{"logged", logged_rows},
                      {"made_up", table.rows() - logged_rows},
                      {"written", o.gaps == io::GapPolicy::kCarry ? logged_rows : table.rows()},
                      {"statistics_over", "logged rows"}};
  const std::vector<std::string> suffixes = Suffixes(axes);
  for (size_t i = 0; i < axes.size(); ++i) {
    const io::LoadedModel& axis = axes[i];
    const Eigen::VectorXd y = table.Column(axis.info.target_column);
    const Eigen::MatrixXd temperature =
        ReadColumns(table, axis.info.temperature_column, "--temperature").values;
    AxisCompensation c;
    try {
      c = CompensateAxis(axis, y, temperature, log.record_starts, log.logged, truth, settings);
    } catch (const DataError& e) {
      // The library sees arrays (y, temperature): the column and the log are named here, as
      // fit names them.
      throw DataError(fmt::format("compensating '{}' on '{}' ({}): {}", axis.info.target_column,
                                  axis.info.temperature_column, log.path, e.what()));
    }
    for (io::CsvColumn& column : c.Columns(suffixes[i])) r.columns.push_back(std::move(column));
    // One axis: its fields at the top level (the layout of one-axis models); several: "axes".
    if (axes.size() == 1) {
      r.record.update(AxisRecord(axis, c, truth_column));
    } else {
      r.record["axes"].push_back(AxisRecord(axis, c, truth_column));
    }
    r.text += AxisText(axis, c, log.logged, truth_column);
    r.axes.push_back(std::move(c));
  }
  if (carry) {
    for (io::CsvColumn& column : r.columns) column.values = drift::LoggedRows(column.values, log.logged);
  } else if (mark_made_up) {
    Eigen::VectorXd flag(table.rows());
    for (Eigen::Index k = 0; k < flag.size(); ++k) flag[k] = log.logged[static_cast<size_t>(k)] ? 0.0 : 1.0;
    r.columns.insert(r.columns.begin() + static_cast<std::ptrdiff_t>(table.header().size()),
                     {"interpolated", flag});
  }
  return r;
}

}  // namespace gyrodrift::tasks
