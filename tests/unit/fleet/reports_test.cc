// The calibration's pages (src/fleet/reports.cc), rendered from hand-made results so that every
// cell and curve can be traced to its field: a unit's page shows its verification figures as
// they are in the result (rounded to 4 significant digits, shares as percentages, "-" for none),
// its limits and verdict, and each log's curves; the fleet page plots each unit's worst log per
// axis against the limit, names the outliers, and links every calibrated unit's page.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fleet/unit_report.h"  // private to src/fleet
#include "gyrodrift/fleet/calibration.h"
#include "gyrodrift/html/report.h"
#include "gyrodrift/io/csv.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift::fleet {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

std::string Unescape(std::string s) {
  const std::vector<std::pair<std::string, std::string>> entities = {
      {"&lt;", "<"}, {"&gt;", ">"}, {"&quot;", "\""}, {"&#39;", "'"}, {"&amp;", "&"}};
  for (const auto& [entity, text] : entities) {
    for (size_t p = 0; (p = s.find(entity, p)) != std::string::npos; p += text.size()) {
      s.replace(p, entity.size(), text);
    }
  }
  return s;
}

struct HtmlCell {
  std::string text;  // unescaped
  std::string link;  // the href, or ""
};

// The rows of the table titled `title` (header row excluded).
std::vector<std::vector<HtmlCell>> TableRows(const std::string& html, const std::string& title) {
  std::vector<std::vector<HtmlCell>> rows;
  const size_t start = html.find("<h3>" + title + "</h3>\n<table>");
  if (start == std::string::npos) {
    ADD_FAILURE() << "no table " << title;
    return rows;
  }
  const size_t end = html.find("</table>", start);
  for (size_t p = html.find("<tr><td", start); p < end; p = html.find("<tr><td", p + 1)) {
    std::vector<HtmlCell> row;
    const size_t row_end = html.find("</tr>", p);
    for (size_t c = html.find("<td", p); c < row_end; c = html.find("<td", c + 1)) {
      const size_t open = html.find('>', c) + 1;
      std::string inner = html.substr(open, html.find("</td>", open) - open);
      HtmlCell cell;
      if (inner.rfind("<a href=\"", 0) == 0) {
        const size_t q = inner.find('"', 9);
        cell.link = Unescape(inner.substr(9, q - 9));
        inner = inner.substr(inner.find('>') + 1);
        inner = inner.substr(0, inner.rfind("</a>"));
      }
      cell.text = Unescape(inner);
      row.push_back(cell);
    }
    rows.push_back(row);
  }
  return rows;
}

std::vector<std::string> Texts(const std::vector<HtmlCell>& row) {
  std::vector<std::string> out;
  for (const HtmlCell& c : row) out.push_back(c.text);
  return out;
}

// Every figure's data block, in order.
std::vector<nlohmann::json> Figures(const std::string& html) {
  std::vector<nlohmann::json> out;
  const std::string tag = "class=\"fig-data\"";
  for (size_t p = html.find(tag); p != std::string::npos; p = html.find(tag, p + 1)) {
    const size_t open = html.find('>', p) + 1;
    out.push_back(nlohmann::json::parse(html.substr(open, html.find("</script>", open) - open)));
  }
  return out;
}

const nlohmann::json* Figure(const std::vector<nlohmann::json>& figures, const std::string& title) {
  for (const auto& f : figures) {
    if (f["title"] == title) return &f;
  }
  return nullptr;
}

// A series' values as doubles (null, a NaN or infinity, as NaN).
std::vector<double> Values(const nlohmann::json& series) {
  std::vector<double> out;
  for (const auto& v : series["y"]) out.push_back(v.is_null() ? kNan : v.get<double>());
  return out;
}

Manifest TwoAxisManifest() {
  Manifest m;
  m.path = "/data/fleet.toml";
  m.limits.residual_drift_rms = 0.05;
  m.limits.removed_share_min = 0.75;
  m.axes = {AxisSpec{.target = "gyro_x", .temperature = {"temp_x"}, .truth = "drift_x"},
            AxisSpec{.target = "gyro_y", .temperature = {"temp_y"}, .truth = "drift_y"}};
  return m;
}

VerificationResult Verification(const std::string& log, double drift_after, double removed) {
  VerificationResult v;
  v.log = log;
  v.samples = 7250;
  v.rate_hz = 1.0;
  v.mean_before = 1.5;
  v.mean_after = -0.25;
  v.std_before = 0.123456;
  v.std_after = 0.0123456;
  v.drift_rms_before = 0.25;
  v.drift_rms_after = drift_after;
  v.truth_removed = removed;
  v.outside_share = 0.125;
  v.noise_after.n_dpsh.value = 0.00458;
  v.noise_before.b_dph.value = 0.5;
  v.noise_after.b_dph.value = 0.0125;
  v.noise_after.n_dpsh.identified = v.noise_before.b_dph.identified = true;
  v.noise_after.b_dph.identified = true;
  v.tau_s = (Eigen::VectorXd(3) << 1.0, 2.0, 4.0).finished();
  v.adev_before = (Eigen::VectorXd(3) << 0.5, 0.375, 0.25).finished();
  v.adev_after = (Eigen::VectorXd(3) << 0.25, 0.125, 0.0625).finished();
  v.block_hours = (Eigen::VectorXd(2) << 0.5, 1.5).finished();
  v.output_means = (Eigen::VectorXd(2) << 1.0, 2.0).finished();
  v.compensated_means = (Eigen::VectorXd(2) << 0.5, 0.25).finished();
  v.estimate_means = (Eigen::VectorXd(2) << 0.5, 1.75).finished();
  v.truth_means = (Eigen::VectorXd(2) << 0.375, 1.625).finished();
  return v;
}

TEST(UnitReport, ShowsTheResultsFiguresLimitsAndVerdict) {
  const Manifest m = TwoAxisManifest();
  UnitSpec spec;
  spec.serial = "SN7";
  spec.calibration = {"/data/logs/SN7_cal_a.csv", "/data/logs/SN7_cal_b.csv"};
  spec.verification = {"/data/logs/SN7_ver.csv", "/data/logs/SN7_ver2.csv"};
  UnitResult unit;
  unit.serial = "SN7";
  AxisResult x;
  x.target = "gyro_x";
  x.model_summary = "thermal: level and rate";
  x.regressors = {"temp_x", "d temp_x/dt"};
  x.bias = 0.125;
  x.cv_rmse = 0.0123456;
  x.skill = 0.875;
  x.warnings = {"narrow span"};
  x.identified = false;  // the warning: the run could not identify the model
  x.verification = {Verification("logs/SN7_ver.csv", 0.0123456, 0.95123),
                    Verification("logs/SN7_ver2.csv", 0.0625, kNan)};
  x.verification[1].failures = {"residual drift 0.0625 > 0.05", "second"};
  x.verification[1].truth_means.resize(0);  // no truth: no true-drift curve
  AxisResult y = x;
  y.target = "gyro_y";
  y.bias = kNan;  // not an identified thermal model: no intercept, no CV line
  y.cv_rmse = kNan;
  y.identified.reset();
  y.verification[1].failures.clear();
  unit.axes = {x, y};

  const std::string html = RenderUnitReport(m, spec, unit, test::FakeDygraphs());
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_EQ(check.tables, 2);
  EXPECT_NE(html.find("<h1>gyrodrift calibration: SN7</h1>"), std::string::npos);
  EXPECT_NE(
      Unescape(html).find(
          "Unit SN7: method thermal (compensate mode), fitted on SN7_cal_a.csv, SN7_cal_b.csv "
          "and verified on SN7_ver.csv, SN7_ver2.csv. Limits: residual drift <= 0.05; true "
          "drift removed >= 75.0 %. Result: FAIL."),
      std::string::npos);
  EXPECT_NE(html.find("<h2>Axis gyro_x (fail)</h2>"), std::string::npos);
  EXPECT_NE(html.find("<h2>Axis gyro_y (pass)</h2>"), std::string::npos);
  EXPECT_NE(Unescape(html).find("thermal: level and rate\nregressors: temp_x, d temp_x/dt\n"
                                "intercept (repeatable bias): 0.125 dph\n"
                                "cross-validated RMSE 0.01235 dph, skill 0.875\n"
                                "not identified: the calibration run could not identify this "
                                "model (warnings below)\n"
                                "warning: narrow span</pre>"),
            std::string::npos);
  EXPECT_NE(Unescape(html).find("thermal: level and rate\nregressors: temp_x, d temp_x/dt\n"
                                "warning: narrow span</pre>"),
            std::string::npos);

  const auto rows = TableRows(html, "Verification of gyro_x");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(Texts(rows[0]),
            (std::vector<std::string>{"logs/SN7_ver.csv", "7250", "1.5", "-0.25", "0.1235",
                                      "0.01235", "0.25", "0.01235", "95.1 %", "0.00458", "0.5",
                                      "0.0125", "12.5 %", "none"}));
  EXPECT_EQ(Texts(rows[1])[8], "-");  // no truth
  EXPECT_EQ(Texts(rows[1])[13], "residual drift 0.0625 > 0.05; second");
  EXPECT_EQ(Texts(TableRows(html, "Verification of gyro_y")[1])[13], "none");

  // Two figures per axis and log: the block means and the Allan deviation.
  const std::vector<nlohmann::json> figures = Figures(html);
  ASSERT_EQ(figures.size(), 8u);
  const nlohmann::json* drift = Figure(figures, "gyro_x: verification log 1 (100-s means)");
  ASSERT_NE(drift, nullptr);
  EXPECT_EQ((*drift)["x"], nlohmann::json::array({0.5, 1.5}));
  ASSERT_EQ((*drift)["series"].size(), 4u);
  const std::vector<std::pair<std::string, std::vector<double>>> curves = {
      {"output", {1.0, 2.0}},
      {"compensated", {0.5, 0.25}},
      {"estimate", {0.5, 1.75}},
      {"true drift", {0.375, 1.625}}};
  for (size_t i = 0; i < curves.size(); ++i) {
    EXPECT_EQ((*drift)["series"][i]["name"], curves[i].first);
    EXPECT_EQ(Values((*drift)["series"][i]), curves[i].second) << curves[i].first;
  }
  const nlohmann::json* no_truth = Figure(figures, "gyro_x: verification log 2 (100-s means)");
  ASSERT_NE(no_truth, nullptr);
  EXPECT_EQ((*no_truth)["series"].size(), 3u);
  const nlohmann::json* adev = Figure(figures, "gyro_y: Allan deviation, verification log 1");
  ASSERT_NE(adev, nullptr);
  EXPECT_TRUE((*adev)["logx"].get<bool>() && (*adev)["logy"].get<bool>());
  EXPECT_EQ((*adev)["x"], nlohmann::json::array({1.0, 2.0, 4.0}));
  EXPECT_EQ(Values((*adev)["series"][0]), (std::vector<double>{0.5, 0.375, 0.25}));
  EXPECT_EQ(Values((*adev)["series"][1]), (std::vector<double>{0.25, 0.125, 0.0625}));

  // Without limits, and with every log within them.
  Manifest open = m;
  open.limits = Limits{};
  unit.axes[0].verification[1].failures.clear();
  EXPECT_NE(
      RenderUnitReport(open, spec, unit, test::FakeDygraphs()).find("Limits: no limits set. Result: PASS."),
      std::string::npos);
}

size_t FleetColumnIndex(const std::string& name) {
  const auto& c = FleetColumns();
  return static_cast<size_t>(std::find(c.begin(), c.end(), name) - c.begin());
}

// A fleet.csv row with the figures the fleet page reads.
FleetRow Row(const std::string& serial, const std::string& axis, const std::string& log,
             const std::string& status, double drift_after, double removed) {
  FleetRow row;
  row.cells.assign(FleetColumns().size(), "");
  const auto set = [&](const std::string& name, const std::string& value) {
    const auto& c = FleetColumns();
    row.cells[static_cast<size_t>(std::find(c.begin(), c.end(), name) - c.begin())] = value;
  };
  set("serial", serial);
  set("axis", axis);
  set("verification", log);
  set("status", status);
  const auto num = [](double v) { return std::isnan(v) ? std::string() : io::FormatDouble(v); };
  set("drift_rms_after", num(drift_after));
  set("drift_rms_before", num(drift_after * 4.0));
  set("truth_removed", num(removed));
  if (status != "error") {
    set("bias_instability_after_dph", "0.0125");
    set("arw_after_dpsh", "0.00458");
    set("bias", "0.5");
  }
  return row;
}

TEST(FleetReport, PlotsEachUnitsWorstLogAndLinksTheCalibratedUnits) {
  const Manifest m = TwoAxisManifest();
  FleetResult fleet;
  fleet.units = 3;
  fleet.calibrated = 2;
  fleet.errors = 1;
  fleet.failed_limits = 1;
  fleet.rows = {Row("SN1", "gyro_x", "a.csv", "pass", 0.0125, 0.9),
                Row("SN1", "gyro_x", "b.csv", "fail", 0.0625, 0.8),  // SN1's worst on x
                Row("SN1", "gyro_y", "a.csv", "pass", 0.025, 0.875),
                Row("SN2", "", "", "error", kNan, kNan),
                Row("SN3", "gyro_x", "a.csv", "pass", 0.03125, 0.7),
                Row("SN3", "gyro_y", "a.csv", "pass", 0.0375, 0.85)};
  fleet.rows[4].cells[5] = "drift_rms_after bias";  // flagged by FinishFleet
  for (const size_t r : {0, 1, 2, 5}) {
    fleet.rows[r].cells[FleetColumnIndex("identified")] = "yes";
  }
  fleet.rows[4].cells[FleetColumnIndex("identified")] = "no";  // SN3 gyro_x
  fleet.rows[3].cells[4] = "log.csv: data row 2 is 'nan'";

  const std::string html = RenderFleetReport(m, fleet, test::FakeDygraphs());
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_NE(Unescape(html).find(fleet.Summary() + ". Limits: residual drift <= 0.05; true drift "
                                                  "removed >= 75.0 %."),
            std::string::npos);
  EXPECT_NE(Unescape(html).find("fleet median): SN3 gyro_x (drift_rms_after bias)."),
            std::string::npos);
  // Units whose calibration could not identify their model: named, and marked in the table.
  EXPECT_NE(Unescape(html).find("Not identified (1 unit axes, marked \"not identified\" in the "
                                "table below): the calibration run could not identify the model "
                                "(see the warnings on the unit's page): SN3 gyro_x."),
            std::string::npos);

  // One point per unit (x = its number in the table) and axis: a unit's worst log, the highest
  // residual drift and the lowest share removed; an error row is a gap.
  const std::vector<nlohmann::json> figures = Figures(html);
  const nlohmann::json* drift = Figure(figures, "Residual drift after compensation");
  ASSERT_NE(drift, nullptr);
  EXPECT_EQ((*drift)["x"], nlohmann::json::array({1.0, 2.0, 3.0}));
  ASSERT_EQ((*drift)["series"].size(), 3u);  // gyro_x, gyro_y, the limit
  EXPECT_EQ((*drift)["series"][0]["name"], "gyro_x");
  const std::vector<double> x_values = Values((*drift)["series"][0]);
  ASSERT_EQ(x_values.size(), 3u);
  EXPECT_EQ(x_values[0], 0.0625);
  EXPECT_TRUE(std::isnan(x_values[1]));
  EXPECT_EQ(x_values[2], 0.03125);
  EXPECT_EQ(Values((*drift)["series"][1])[0], 0.025);
  EXPECT_EQ((*drift)["series"][2]["name"], "limit");
  EXPECT_TRUE((*drift)["series"][2]["dashed"].get<bool>());
  EXPECT_EQ(Values((*drift)["series"][2]), (std::vector<double>{0.05, 0.05, 0.05}));
  const nlohmann::json* removed = Figure(figures, "Share of the true drift removed");
  ASSERT_NE(removed, nullptr);
  EXPECT_EQ(Values((*removed)["series"][0])[0], 80.0);  // percent, the lower of 90 and 80
  EXPECT_EQ(Values((*removed)["series"][0])[2], 70.0);
  EXPECT_EQ(Values((*removed)["series"].back()), (std::vector<double>{75.0, 75.0, 75.0}));
  // No limit on B: no limit line.
  const nlohmann::json* b = Figure(figures, "Bias instability B after compensation");
  ASSERT_NE(b, nullptr);
  EXPECT_EQ((*b)["series"].size(), 2u);

  // The table: every row, numbered by unit; calibrated serials link their page, an error does not.
  const auto rows = TableRows(html, "Every unit, axis and verification log (fleet.csv)");
  ASSERT_EQ(rows.size(), fleet.rows.size());
  EXPECT_EQ(Texts(rows[1]),
            (std::vector<std::string>{"1", "SN1", "gyro_x", "b.csv", "fail", "0.25", "0.0625",
                                      "80.0 %", "0.0125", "0.00458", "0.5", "", "", ""}));
  EXPECT_EQ(rows[1][1].link, "SN1/report.html");
  EXPECT_EQ(Texts(rows[3]),
            (std::vector<std::string>{"2", "SN2", "", "", "error", "-", "-", "-", "-", "-", "-", "",
                                      "", "log.csv: data row 2 is 'nan'"}));
  EXPECT_EQ(rows[3][1].link, "");
  EXPECT_EQ(Texts(rows[4])[0], "3");
  EXPECT_EQ(Texts(rows[4])[11], "not identified");
  EXPECT_EQ(rows[4][1].link, "SN3/report.html");
}

TEST(FleetReport, AFleetWithoutFiguresStillRenders) {
  // Every unit failed: nothing to plot, no outliers, the table alone.
  Manifest m = TwoAxisManifest();
  FleetResult fleet;
  fleet.units = 1;
  fleet.errors = 1;
  fleet.rows = {Row("SN1", "", "", "error", kNan, kNan)};
  const std::string html = RenderFleetReport(m, fleet, test::FakeDygraphs());
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_EQ(check.figures, 0);
  EXPECT_NE(html.find("No outliers"), std::string::npos);
  EXPECT_EQ(TableRows(html, "Every unit, axis and verification log (fleet.csv)").size(), 1u);
}

}  // namespace
}  // namespace gyrodrift::fleet
