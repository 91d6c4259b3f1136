// The unit pages and the fleet page of a calibration (calibration.h).
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "gyrodrift/fleet/calibration.h"
#include "unit_report.h"

namespace gyrodrift::fleet {
namespace {

// One colour per axis in every figure of the fleet page.
constexpr std::array<const char*, 6> kAxisColours = {"#1f77b4", "#ff7f0e", "#2ca02c",
                                                     "#9467bd", "#8c564b", "#17becf"};

std::string Num(double v, int digits = 4) {
  return std::isnan(v) ? "-" : fmt::format("{:.{}g}", v, digits);
}

// A noise term the Allan fit did not identify: said, not its 0.
std::string TermText(const allan::NoiseTerm& t) {
  return t.identified ? Num(t.value) : "not identified";
}

std::string Percent(double share) {
  return std::isnan(share) ? "-" : fmt::format("{:.1f} %", 100.0 * share);
}

std::string LimitsText(const Limits& l) {
  std::string out;
  if (!std::isnan(l.residual_drift_rms)) out += fmt::format("residual drift <= {:.4g}; ", l.residual_drift_rms);
  if (!std::isnan(l.bias_instability_dph)) out += fmt::format("bias instability <= {:.4g} deg/h; ", l.bias_instability_dph);
  if (!std::isnan(l.removed_share_min)) out += fmt::format("true drift removed >= {:.1f} %; ", 100.0 * l.removed_share_min);
  return out.empty() ? "no limits set" : out.substr(0, out.size() - 2);
}

html::ReportSeries Line(std::string name, Eigen::VectorXd v, const char* color, bool dashed = false) {
  html::ReportSeries s;
  s.name = std::move(name);
  s.values = std::move(v);
  s.color = color;
  s.dashed = dashed;
  return s;
}

// A fleet.csv cell as a number (NaN when empty).
double Cell(const FleetRow& row, const std::string& column) {
  const auto& c = FleetColumns();
  const size_t i = static_cast<size_t>(std::find(c.begin(), c.end(), column) - c.begin());
  const std::string& text = row.cells[i];
  return text.empty() ? std::numeric_limits<double>::quiet_NaN() : std::strtod(text.c_str(), nullptr);
}
const std::string& Text(const FleetRow& row, const std::string& column) {
  const auto& c = FleetColumns();
  return row.cells[static_cast<size_t>(std::find(c.begin(), c.end(), column) - c.begin())];
}

// An axis's model and verification table on its unit's page.
void AddAxisSummary(html::HtmlReport& report, const Manifest& m, const AxisResult& a,
                    const std::string& unit_name) {
  report.AddHeading(fmt::format("Axis {} ({})", a.target, a.pass() ? "pass" : "fail"));
  std::string model = a.model_summary + "\nregressors: ";
  for (size_t i = 0; i < a.regressors.size(); ++i) model += (i ? ", " : "") + a.regressors[i];
  if (!std::isnan(a.bias)) model += fmt::format("\nintercept (repeatable bias): {:.6g} {}", a.bias, unit_name);
  if (!std::isnan(a.cv_rmse)) model += fmt::format("\ncross-validated RMSE {:.4g} {}, skill {:.3f}", a.cv_rmse, unit_name, a.skill);
  if (!a.autopilot.empty()) model += "\nautopilot form (export --format px4): " + a.autopilot;
  if (a.identified && !*a.identified) {
    model += "\nnot identified: the calibration run could not identify this model (warnings below)";
  }
  for (const std::string& w : a.warnings) model += "\nwarning: " + w;
  report.AddPreformatted(model);
  html::ReportTable table;
  table.title = "Verification of " + a.target;
  table.header = {"log", "samples", "mean before", "mean after", "std before", "std after",
                  "residual drift before",
                  "residual drift after", "true drift removed", "ARW after (deg/rt h)",
                  "B before (deg/h)", "B after (deg/h)", "outside cal. range", "limits broken"};
  for (const VerificationResult& v : a.verification) {
    std::string failures;
    for (const std::string& f : v.failures) failures += (failures.empty() ? "" : "; ") + f;
    table.rows.push_back({v.log, std::to_string(v.samples), Num(v.mean_before), Num(v.mean_after),
                          Num(v.std_before), Num(v.std_after), Num(v.drift_rms_before),
                          Num(v.drift_rms_after), Percent(v.truth_removed),
                          TermText(v.noise_after.n_dpsh), TermText(v.noise_before.b_dph),
                          TermText(v.noise_after.b_dph), Percent(v.outside_share),
                          failures.empty() ? "none" : failures});
  }
  table.caption = fmt::format(
      "Residual drift: RMS of the output's {:g}-s means about their mean, {}. True drift "
      "removed: 1 - RMS(truth - estimate) / RMS(truth). Noise terms: IEEE 952 fit to the "
      "overlapping Allan deviation.",
      m.drift_window_s, unit_name);
  report.AddTable(table);
}

// An axis's figures on its unit's page: per verification log, the block means and the Allan
// deviation before and after.
void AddAxisFigures(html::HtmlReport& report, const Manifest& m, const AxisResult& a,
                    const std::string& unit_name) {
  for (size_t k = 0; k < a.verification.size(); ++k) {
    const VerificationResult& v = a.verification[k];
    html::ReportFigure drift;
    drift.title = fmt::format("{}: verification log {} ({:g}-s means)", a.target, k + 1,
                              m.drift_window_s);
    drift.caption = "The output before and after compensation, and the model's estimate"
                    " (with the true drift when the log has it). After compensation the "
                    "curve should be flat.";
    drift.x_label = "time (h)";
    drift.y_label = unit_name;
    drift.x = v.block_hours;
    drift.series.push_back(Line("output", v.output_means, "#999999"));
    drift.series.push_back(Line("compensated", v.compensated_means, "#1f77b4"));
    drift.series.push_back(Line("estimate", v.estimate_means, "#d62728", true));
    if (v.truth_means.size() == v.block_hours.size()) {
      drift.series.push_back(Line("true drift", v.truth_means, "#2ca02c"));
    }
    report.AddFigure(drift);
    html::ReportFigure adev;
    adev.title = fmt::format("{}: Allan deviation, verification log {}", a.target, k + 1);
    adev.caption = "Overlapping Allan deviation before and after compensation: the thermal "
                   "drift lifts the long-tau end; compensation should bring it down.";
    adev.x_label = "tau (s)";
    adev.y_label = unit_name;
    adev.x = v.tau_s;
    adev.log_x = adev.log_y = true;
    adev.draw_points = true;
    adev.series.push_back(Line("before", v.adev_before, "#999999"));
    adev.series.push_back(Line("after", v.adev_after, "#1f77b4"));
    report.AddFigure(adev);
  }
}

}  // namespace

std::string RenderUnitReport(const Manifest& m, const UnitSpec& spec, const UnitResult& unit,
                             const html::DygraphsAssets& assets) {
  const std::string unit_name(allan::ToString(m.rate_unit));
  html::HtmlReport report("gyrodrift calibration: " + unit.serial);
  auto names = [](const std::vector<std::string>& logs) {
    std::string out;
    for (const std::string& log : logs) {
      out += (out.empty() ? "" : ", ") + std::filesystem::path(log).filename().string();
    }
    return out;
  };
  const std::string calibration = names(spec.calibration), verification = names(spec.verification);
  report.AddParagraph(fmt::format(
      "Unit {}: method {} (compensate mode), fitted on {} and verified on {}. Limits: {}. "
      "Result: {}.",
      unit.serial, drift::ToString(m.FitMethod()),
      calibration, verification,
      LimitsText(m.limits), unit.pass() ? "PASS" : "FAIL"));
  for (const AxisResult& a : unit.axes) {
    AddAxisSummary(report, m, a, unit_name);
    AddAxisFigures(report, m, a, unit_name);
  }
  return report.Render(assets);
}

namespace {

// The fleet page's findings: the unit axes whose model was not identified, and the outliers.
void AddFindings(html::HtmlReport& report, const FleetResult& fleet) {
  std::vector<std::string> outliers;
  for (const FleetRow& row : fleet.rows) {
    if (!Text(row, "outliers").empty()) {
      outliers.push_back(fmt::format("{} {} ({})", row.cells[0], Text(row, "axis"), Text(row, "outliers")));
    }
  }
  // Units whose calibration run could not identify their model (fleet.csv's identified = no):
  // their compensation rests on a model the data did not support.
  std::vector<std::string> unidentified;
  for (const FleetRow& row : fleet.rows) {
    if (Text(row, "identified") != "no") continue;
    const std::string entry = fmt::format("{} {}", row.cells[0], Text(row, "axis"));
    if (std::find(unidentified.begin(), unidentified.end(), entry) == unidentified.end()) {
      unidentified.push_back(entry);
    }
  }
  if (!unidentified.empty()) {
    std::string list;
    for (const std::string& u : unidentified) list += (list.empty() ? "" : "; ") + u;
    report.AddParagraph(fmt::format(
        "Not identified ({} unit axes, marked \"not identified\" in the table below): the "
        "calibration run could not identify the model (see the warnings on the unit's page): {}.",
        unidentified.size(), list));
  }
  report.AddParagraph(outliers.empty()
                          ? "No outliers: every unit's figures lie within 3.5 robust standard "
                            "deviations of its axis's fleet median."
                          : "Outliers (more than 3.5 robust standard deviations from the axis's "
                            "fleet median): " + [&] {
                              std::string s;
                              for (const std::string& o : outliers) s += (s.empty() ? "" : "; ") + o;
                              return s;
                            }() + ".");

}

// Distributions: one point per unit (x = its row in the table below), one series per axis, the
// limit as a dashed line.
void AddDistributions(html::HtmlReport& report, const Manifest& m, const FleetResult& fleet,
                      const std::vector<std::string>& serials, const std::string& unit_name) {
  auto distribution = [&](const std::string& column, const std::string& title,
                          const std::string& y_label, double limit, double scale) {
    html::ReportFigure f;
    f.title = title;
    f.caption = std::string("One point per unit (x: the unit's number in the table below), one "
                            "colour per axis") +
                (std::isnan(limit) ? "." : "; the dashed line is the limit.");
    f.x_label = "unit";
    f.y_label = y_label;
    f.integer_x = true;
    f.draw_points = true;
    const auto n = static_cast<Eigen::Index>(serials.size());
    f.x = Eigen::VectorXd::LinSpaced(n, 1.0, static_cast<double>(n));
    bool any = false;
    for (const AxisSpec& axis : m.axes) {
      Eigen::VectorXd v = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
      for (const FleetRow& row : fleet.rows) {
        if (Text(row, "axis") != axis.target || Text(row, "verification").empty()) continue;
        const auto i = std::find(serials.begin(), serials.end(), row.cells[0]) - serials.begin();
        // Several verification logs: the unit's worst is the one that decides pass/fail.
        const double x = scale * Cell(row, column);
        if (std::isnan(v[i]) || (column == "truth_removed" ? x < v[i] : x > v[i])) v[i] = x;
        any |= !std::isnan(x);
      }
      html::ReportSeries s;
      s.name = axis.target;
      s.values = v;
      s.markers_only = true;
      s.color = kAxisColours[(&axis - m.axes.data()) % kAxisColours.size()];
      f.series.push_back(s);
    }
    if (!any || n == 0) return;
    if (!std::isnan(limit)) {
      html::ReportSeries s;
      s.name = "limit";
      s.values = Eigen::VectorXd::Constant(n, scale * limit);
      s.dashed = true;
      s.color = "#d62728";
      f.series.push_back(s);
    }
    report.AddFigure(f);
  };
  report.AddHeading("Distributions across the fleet");
  distribution("drift_rms_after", "Residual drift after compensation", unit_name,
               m.limits.residual_drift_rms, 1.0);
  distribution("drift_rms_before", "Drift before compensation (same measure)", unit_name,
               std::numeric_limits<double>::quiet_NaN(), 1.0);
  distribution("truth_removed", "Share of the true drift removed", "%", m.limits.removed_share_min,
               100.0);
  distribution("bias_instability_after_dph", "Bias instability B after compensation", "deg/h",
               m.limits.bias_instability_dph, 1.0);
  distribution("arw_after_dpsh", "Angle random walk N after compensation", "deg/rt h",
               std::numeric_limits<double>::quiet_NaN(), 1.0);
  distribution("bias", "Repeatable bias (the thermal model's intercept)", unit_name,
               std::numeric_limits<double>::quiet_NaN(), 1.0);

}

// The table of every unit, axis and verification log, with links to the units' pages.
void AddUnitsTable(html::HtmlReport& report, const FleetResult& fleet,
                   const std::vector<std::string>& serials, const std::string& unit_name) {
  report.AddHeading("Units");
  html::ReportTable table;
  table.title = "Every unit, axis and verification log (fleet.csv)";
  table.header = {"#", "serial", "axis", "log", "status", "residual drift before",
                  "residual drift after", "true drift removed", "B after (deg/h)",
                  "ARW after (deg/rt h)", "bias", "model", "outliers", "limits broken / error"};
  for (const FleetRow& row : fleet.rows) {
    const auto i = std::find(serials.begin(), serials.end(), row.cells[0]) - serials.begin();
    const bool error = Text(row, "status") == "error";
    table.rows.push_back({std::to_string(i + 1), row.cells[0], Text(row, "axis"),
                          Text(row, "verification"), Text(row, "status"),
                          Num(Cell(row, "drift_rms_before")), Num(Cell(row, "drift_rms_after")),
                          Percent(Cell(row, "truth_removed")),
                          Num(Cell(row, "bias_instability_after_dph")),
                          Num(Cell(row, "arw_after_dpsh")), Num(Cell(row, "bias")),
                          Text(row, "identified") == "no" ? "not identified" : "",
                          Text(row, "outliers"), Text(row, "failures")});
    std::vector<std::string> links(table.header.size());
    if (!error) links[1] = row.cells[0] + "/report.html";
    table.links.push_back(links);
  }
  table.caption = "Click a serial for the unit's page (its models, figures and files are in its "
                  "folder). Residual drift in " + unit_name + ". Model: \"not identified\" where "
                  "the calibration run could not identify the thermal model (its warnings are on "
                  "the unit's page and in fleet.csv).";
  report.AddTable(table);
}

}  // namespace

std::string RenderFleetReport(const Manifest& m, const FleetResult& fleet,
                              const html::DygraphsAssets& assets) {
  const std::string unit_name(allan::ToString(m.rate_unit));
  html::HtmlReport report("gyrodrift fleet calibration");
  report.AddParagraph(fleet.Summary() + ". Limits: " + LimitsText(m.limits) + ".");
  std::vector<std::string> serials;
  for (const FleetRow& row : fleet.rows) {
    if (std::find(serials.begin(), serials.end(), row.cells[0]) == serials.end()) {
      serials.push_back(row.cells[0]);
    }
  }
  AddFindings(report, fleet);
  AddDistributions(report, m, fleet, serials, unit_name);
  AddUnitsTable(report, fleet, serials, unit_name);
  return report.Render(assets);
}

}  // namespace gyrodrift::fleet
