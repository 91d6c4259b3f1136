// fleet.csv's rows: the columns, one row per unit, axis and verification log, and the outliers
// flagged across the fleet (calibration.h).
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "gyrodrift/common/statistics.h"
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/io/csv.h"
#include "unit_report.h"

namespace gyrodrift::fleet {
namespace {

namespace fs = std::filesystem;

std::string Fmt(double v) { return std::isnan(v) ? "" : io::FormatDouble(v); }

// A noise term the Allan fit did not identify is empty, not its 0 (a set limit on B is then held
// against B's bound: Failures).
std::string Term(const allan::NoiseTerm& t) { return t.identified ? Fmt(t.value) : ""; }

int ColumnIndex(const std::string& name) {
  const auto& c = FleetColumns();
  return static_cast<int>(std::find(c.begin(), c.end(), name) - c.begin());
}

}  // namespace

// Flags, per axis across the fleet, the rows whose figure lies more than 3.5 robust standard
// deviations (1.4826 MAD) from the fleet's median (Iglewicz & Hoaglin's modified z-score): a unit
// unlike its siblings deserves a look even when it passes its limits.
void FlagOutliers(std::vector<FleetRow>& rows) {
  const int axis_col = ColumnIndex("axis");
  const int outlier_col = ColumnIndex("outliers");
  for (const char* metric : {"drift_rms_after", "truth_removed", "bias_instability_after_dph",
                             "arw_after_dpsh", "bias"}) {
    const int col = ColumnIndex(metric);
    std::vector<std::string> axes;
    for (const FleetRow& r : rows) {
      const std::string& a = r.cells[static_cast<size_t>(axis_col)];
      if (!a.empty() && std::find(axes.begin(), axes.end(), a) == axes.end()) axes.push_back(a);
    }
    for (const std::string& axis : axes) {
      std::vector<std::pair<size_t, double>> values;
      for (size_t i = 0; i < rows.size(); ++i) {
        const auto& cells = rows[i].cells;
        if (cells[static_cast<size_t>(axis_col)] != axis) continue;
        const std::string& text = cells[static_cast<size_t>(col)];
        if (text.empty()) continue;
        const double v = std::strtod(text.c_str(), nullptr);
        if (std::isfinite(v)) values.push_back({i, v});
      }
      // Too few units to call one unusual. Units, not rows: a unit has a row per verification log.
      std::set<std::string> units;
      for (const auto& [i, v] : values) units.insert(rows[i].cells[0]);
      if (units.size() < 5) continue;
      std::vector<double> x;
      for (const auto& [i, v] : values) x.push_back(v);
      const double median = Median(x);
      std::vector<double> dev;
      for (double v : x) dev.push_back(std::abs(v - median));
      const double mad = 1.4826 * Median(dev);
      if (!(mad > 0.0)) continue;
      for (const auto& [i, v] : values) {
        if (std::abs(v - median) / mad <= 3.5) continue;
        std::string& flag = rows[i].cells[static_cast<size_t>(outlier_col)];
        flag += (flag.empty() ? "" : " ") + std::string(metric);
      }
    }
  }
}

const std::vector<std::string>& FleetColumns() {
  static const std::vector<std::string> kColumns = {
      "serial", "axis", "verification", "status", "failures", "outliers", "method", "samples",
      "std_before", "std_after", "drift_rms_before", "drift_rms_after", "drift_removed",
      "truth_removed", "arw_before_dpsh", "arw_after_dpsh", "bias_instability_before_dph",
      "bias_instability_after_dph", "rrw_before_dphpsh", "rrw_after_dphpsh", "bias", "cv_rmse",
      "skill", "autopilot_kept", "regressors", "warnings", "identified", "outside_share", "mean_before",
      "mean_after", "unit_seconds"};
  return kColumns;
}

std::vector<FleetRow> Rows(const UnitResult& unit) {
  std::vector<FleetRow> rows;
  const std::string seconds = io::FormatDouble(unit.seconds);
  if (!unit.error.empty()) {
    FleetRow row;
    row.cells.assign(FleetColumns().size(), "");
    row.cells[0] = unit.serial;
    row.cells[3] = "error";
    row.cells[4] = unit.error;
    row.cells.back() = seconds;
    rows.push_back(std::move(row));
    return rows;
  }
  for (const AxisResult& a : unit.axes) {
    std::string regressors;
    for (const std::string& name : a.regressors) regressors += (regressors.empty() ? "" : "; ") + name;
    std::string warnings;
    for (const std::string& w : a.warnings) warnings += (warnings.empty() ? "" : "; ") + w;
    for (const VerificationResult& v : a.verification) {
      std::string failures;
      for (const std::string& f : v.failures) failures += (failures.empty() ? "" : "; ") + f;
      const double drift_removed =
          v.drift_rms_before > 0.0 ? 1.0 - v.drift_rms_after / v.drift_rms_before
                                   : std::numeric_limits<double>::quiet_NaN();
      rows.push_back(FleetRow{{unit.serial,
                               a.target,
                               v.log,
                               v.failures.empty() ? "pass" : "fail",
                               failures,
                               "",
                               a.model_summary.substr(0, a.model_summary.find(' ')),
                               std::to_string(v.samples),
                               Fmt(v.std_before),
                               Fmt(v.std_after),
                               Fmt(v.drift_rms_before),
                               Fmt(v.drift_rms_after),
                               Fmt(drift_removed),
                               Fmt(v.truth_removed),
                               Term(v.noise_before.n_dpsh),
                               Term(v.noise_after.n_dpsh),
                               Term(v.noise_before.b_dph),
                               Term(v.noise_after.b_dph),
                               Term(v.noise_before.k_dphpsh),
                               Term(v.noise_after.k_dphpsh),
                               Fmt(a.bias),
                               Fmt(a.cv_rmse),
                               Fmt(a.skill),
                               Fmt(a.autopilot_kept),
                               regressors,
                               warnings,
                               !a.identified   ? ""
                               : *a.identified ? "yes"
                                               : "no",
                               Fmt(v.outside_share),
                               Fmt(v.mean_before),
                               Fmt(v.mean_after),
                               seconds}});
    }
  }
  return rows;
}

}  // namespace gyrodrift::fleet
