// gyrodrift compensate: remove the drift a saved compensate-mode model estimates from temperature.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_util.h"
#include "command.h"
#include "drift_cli.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/compensation_summary.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::cli {
namespace {

struct CompensateArgs {
  std::string model;
  std::string input;
  std::string output;
  std::string truth;  // "" = none
  LogArgs log;  // --gaps, --delimiter
  bool quiet = false;
};

nlohmann::json SummaryJson(const drift::SignalSummary& s) {
  return {{"mean", s.mean}, {"rms", s.rms}, {"std", s.std}, {"slow_variation", s.slow}};
}

// One axis compensated: the columns it adds, its part of the sidecar, its console lines.
struct AxisResult {
  std::vector<io::CsvColumn> columns;
  nlohmann::json sidecar;
  std::string text;
};

// `suffix` is "" for a one-axis model (drift_est, drift_sd, compensated), "_<target>" otherwise.
// The estimate runs over every row (the thermal states across filled gaps); the statistics use
// the logged rows only (`logged`, empty = every row).
AxisResult CompensateAxis(const io::LoadedModel& loaded, const io::CsvTable& table,
                          const std::vector<Eigen::Index>& record_starts,
                          const std::vector<bool>& logged, const Eigen::VectorXd& truth_all,
                          const std::string& truth_column, const std::string& suffix) {
  const drift::DriftModel& model = loaded.model;
  const Eigen::VectorXd y_all = table.Column(loaded.info.target_column);
  const Eigen::MatrixXd temperature_all =
      ReadColumns(table, loaded.info.temperature_column, "--temperature").values;
  const Eigen::MatrixXd estimate_sd =
      drift::EstimateDriftWithSd(model, temperature_all, record_starts);
  const Eigen::VectorXd estimate_all = estimate_sd.col(0);
  const Eigen::VectorXd compensated_all = y_all - estimate_all;

  AxisResult r;
  r.columns.push_back({"drift_est" + suffix, estimate_all});
  // Identified models give each estimate a standard deviation (thermal_model.h).
  if (model.identified()) r.columns.push_back({"drift_sd" + suffix, estimate_sd.col(1)});
  r.columns.push_back({"compensated" + suffix, compensated_all});
  const Eigen::VectorXd y = drift::LoggedRows(y_all, logged);
  const Eigen::VectorXd estimate = drift::LoggedRows(estimate_all, logged);
  const Eigen::VectorXd compensated = drift::LoggedRows(compensated_all, logged);
  const Eigen::VectorXd truth = drift::LoggedRows(truth_all, truth_all.size() ? logged
                                                                               : std::vector<bool>{});
  const Eigen::MatrixXd temperature = drift::LoggedRows(temperature_all, logged);

  nlohmann::json& j = r.sidecar;
  j["model"] = {{"summary", model.Summary()},
                {"method", drift::ToString(model.options.method)},
                {"target_column", loaded.info.target_column},
                {"rate_unit", loaded.info.rate_unit},
                {"temperature_column", loaded.info.temperature_column},
                {"seed", model.options.seed},
                {"tool_version", loaded.info.tool_version}};
  // The mean, RMS, std and slow variation before and after (a calibration mostly moves the
  // bias, which the std alone hides), blocks timed at the model's sample rate.
  const drift::CompensationSummary summary =
      drift::SummariseCompensation(y, compensated, model.options.features.rate_hz);
  j["samples"] = y.size();
  j["std_before"] = summary.before.std;
  j["std_after"] = summary.after.std;
  j["before"] = SummaryJson(summary.before);
  j["after"] = SummaryJson(summary.after);
  j["slow_variation_block_s"] = summary.block_s;
  j["slow_variation_blocks"] = summary.blocks;
  // Files before format 4 did not record the unit: the table then names none.
  r.text = model.Summary() + "\n" + summary.Table(loaded.info.target_column, loaded.info.rate_unit);
  // Filled gaps: the figures above leave the made-up rows out (the slow variation's blocks then
  // hold consecutive logged samples, which span more time).
  if (!logged.empty()) {
    r.text += fmt::format("{}: statistics over the {} logged rows ({} made up left out)\n",
                          loaded.info.target_column, y.size(), logged.size() - static_cast<size_t>(y.size()));
  }
  // Against a known drift (the simulator's drift_dph): how much of its RMS the estimate removes,
  // 1 - RMS(truth - estimate) / RMS(truth), RMS about zero (the drift's offset is part of it).
  if (truth.size() > 0) {
    const double truth_rms = std::sqrt(truth.squaredNorm() / static_cast<double>(truth.size()));
    const double residual_rms =
        std::sqrt((truth - estimate).squaredNorm() / static_cast<double>(truth.size()));
    const double removed = truth_rms > 0.0 ? 100.0 * (1.0 - residual_rms / truth_rms) : NAN;
    j["truth"] = {{"column", truth_column},
                  {"rms", truth_rms},
                  {"residual_rms", residual_rms},
                  {"removed_percent", removed}};
    // A zero truth has no share to remove: say so instead of printing "nan %".
    const std::string share =
        truth_rms > 0.0 ? fmt::format("{:.1f} % removed", removed) : "no drift to remove";
    r.text += fmt::format("{}: RMS {:.6g}, residual after compensation {:.6g} ({})\n",
                          truth_column, truth_rms, residual_rms, share);
  }
  // A thermal model beyond the temperatures it was fitted on extrapolates: say where.
  const double outside = drift::ShareOutsideRange(temperature.col(0), model.temperature_min_c,
                                                 model.temperature_max_c);
  j["outside_training_temperature_share"] = outside;
  if (outside > 0.0) {
    r.text += fmt::format(
        "note: {:.1f} % of the samples lie outside the training temperature range [{:.4g}, {:.4g}] "
        "degC: the estimate extrapolates there\n",
        100.0 * outside, model.temperature_min_c, model.temperature_max_c);
  }
  // A model the calibration run could not identify says so every time it is used.
  for (const auto& sub : model.sub_models) {
    if (!sub.thermal) continue;
    for (const std::string& w : sub.thermal->report.warnings) {
      r.text += "warning: the model's calibration run (" + sub.name + "): " + w + "\n";
    }
  }
  if (model.identified()) j["drift_sd_mean"] = drift::LoggedRows(estimate_sd.col(1), logged).mean();
  return r;
}

void Run(const CompensateArgs& a) {
  RequireOutputsAreNotInputs({a.model, a.input}, {a.output, SidecarPath(a.output)});
  const std::vector<io::LoadedModel> axes = io::ReadModelFileAxes(a.model);
  for (const io::LoadedModel& axis : axes) {
    if (axis.model.options.mode != drift::Mode::kCompensate) {
      throw UsageError(a.model +
                       " is a predict-mode model: use 'gyrodrift predict' (compensate "
                       "needs a model fitted with --mode compensate)");
    }
  }
  std::string text;  // the console report, notes first
  std::vector<Eigen::Index> record_starts;  // --gaps split: the estimate restarts after each gap
  std::vector<bool> logged;  // --gaps interpolate or carry: the rows that were logged
  const io::CsvTable table = ReadLog(a.input, a.log, &text, &record_starts, {}, &logged);
  for (const io::LoadedModel& axis : axes) RequireModelColumns(axis, table);
  // Before the work: a temperature that does not look like degC (each column once).
  std::vector<std::string> temperature_columns;
  for (const io::LoadedModel& axis : axes) {
    if (!axis.model.uses_temperature()) continue;
    for (const std::string& c : SplitColumns(axis.info.temperature_column)) {
      if (std::find(temperature_columns.begin(), temperature_columns.end(), c) ==
          temperature_columns.end()) {
        temperature_columns.push_back(c);
      }
    }
  }
  if (!a.quiet) fmt::print("{}", InputWarnings(a.input, "", table, temperature_columns));
  std::vector<std::string> suffixes;
  for (const io::LoadedModel& axis : axes) {
    suffixes.push_back(axes.size() == 1 ? "" : "_" + axis.info.target_column);
    for (const char* name : {"drift_est", "drift_sd", "compensated"}) {
      if (table.HasColumn(name + suffixes.back())) {
        throw DataError(a.input + " already has a column '" + name + suffixes.back() +
                        "': compensate an uncompensated log");
      }
    }
  }
  const bool mark_made_up = !logged.empty() && a.log.gaps != "carry";  // column `interpolated`
  if (mark_made_up && table.HasColumn("interpolated")) {
    throw DataError(a.input + " already has a column 'interpolated': --gaps interpolate marks the "
                    "rows it makes up in one (rename it, or use --gaps carry)");
  }
  Eigen::VectorXd truth;  // read before the work, so a misspelt column fails fast
  std::string truth_column;
  if (!a.truth.empty()) {
    if (axes.size() > 1) {
      throw UsageError("--truth = " + a.truth + ": " + a.model + " holds " +
                       std::to_string(axes.size()) +
                       " axes; a true drift column scores a one-axis model");
    }
    truth_column = ColumnName(table, a.truth);
    truth = table.Column(a.truth);
  }

  std::vector<io::CsvColumn> columns;
  for (int c = 0; c < static_cast<int>(table.header().size()); ++c) {
    columns.push_back({table.header()[static_cast<size_t>(c)], table.Column(c)});
  }
  nlohmann::json sidecar = SidecarHeader("compensate");
  sidecar["options"] = {{"model", a.model}, {"input", a.input}, {"gaps", a.log.gaps}, {"records", record_starts.size() + 1}};
  // Made-up rows: the statistics leave them out; the output marks them (interpolate) or leaves
  // them out too (carry: one output row per logged row, as for a log without gaps).
  const Eigen::Index logged_rows = drift::CountLogged(logged, table.rows());
  sidecar["rows"] = {{"logged", logged_rows},
                     {"made_up", table.rows() - logged_rows},
                     {"written", a.log.gaps == "carry" ? logged_rows : table.rows()},
                     {"statistics_over", "logged rows"}};
  for (size_t i = 0; i < axes.size(); ++i) {
    AxisResult r =
        CompensateAxis(axes[i], table, record_starts, logged, truth, truth_column, suffixes[i]);
    for (io::CsvColumn& column : r.columns) columns.push_back(std::move(column));
    // One axis: its fields at the top level (the layout of one-axis models); several: "axes".
    if (axes.size() == 1) {
      sidecar.update(r.sidecar);
    } else {
      sidecar["axes"].push_back(std::move(r.sidecar));
    }
    text += r.text;
  }
  if (!logged.empty() && a.log.gaps == "carry") {
    for (io::CsvColumn& column : columns) column.values = drift::LoggedRows(column.values, logged);
  } else if (mark_made_up) {
    Eigen::VectorXd flag(table.rows());
    for (Eigen::Index k = 0; k < flag.size(); ++k) flag[k] = logged[static_cast<size_t>(k)] ? 0.0 : 1.0;
    columns.insert(columns.begin() + static_cast<std::ptrdiff_t>(table.header().size()),
                   {"interpolated", flag});
  }
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) fmt::print("{}wrote {} and {}\n", text, a.output, SidecarPath(a.output));
}

const RegisterCommand kRegister("compensate", 70, [](CLI::App& app) {
  auto args = std::make_shared<CompensateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "compensate", "Subtract the drift a saved compensate-mode model estimates from temperature.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift fit train.csv --target rate_dph --temperature temperature_c --mode compensate "
      "\\\n"
      "      -o model.json\n"
      "  gyrodrift compensate model.json test.csv -o out.csv\n"
      "writes out.csv: every column of test.csv, then drift_est (the model's drift estimate,\n"
      "from the temperature history only), drift_sd (its standard deviation, for identified\n"
      "models: thermal, ms-elm, emd-elm) and compensated (= target column - drift_est), one\n"
      "row per input row; out.csv.json records the model and the std before and after.\n"
      "A model of several axes (fit --target gyro_x,gyro_y,gyro_z) adds drift_est_<target>,\n"
      "drift_sd_<target> and compensated_<target> for each.\n"
      "With --truth drift_dph (a simulated log) it also reports how much of the true drift's\n"
      "RMS the estimate removes: 1 - RMS(truth - drift_est) / RMS(truth).\n"
      "test.csv needs the columns the model was trained with (here rate_dph and temperature_c).\n"
      "A log with gaps: --gaps interpolate fills them and marks the made-up rows in a column\n"
      "interpolated (1 = made up); --gaps carry runs the estimate across them on the interpolated\n"
      "temperature and writes the logged rows only. Either way the std and the truth share are\n"
      "over the logged rows.");
  cmd->add_option("model", args->model, "model file written by 'gyrodrift fit --mode compensate'")
      ->required()
      ->check(kInputFile);
  cmd->add_option("input", args->input, "CSV log with the model's target and temperature columns")
      ->required()
      ->check(kInputFile);
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  cmd->add_option("--truth", args->truth,
                  "column of the true drift (e.g. the simulator's drift_dph): also report the "
                  "share of its RMS the estimate removes");
  AddLogOptions(cmd, &args->log);
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
