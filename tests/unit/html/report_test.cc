// The HTML report writer: a small report renders and passes the structural check; the check
// itself catches each kind of broken report; the min/max decimation keeps the envelope.
#include "gyrodrift/html/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "support/report_check.h"
#include "support/test_support.h"

namespace gyrodrift::html {
namespace {

bool HaveDygraphs() {
  return std::filesystem::exists(std::string(kDygraphsDir) + "/dygraph.min.js");
}

ReportSeries S(std::string name, Eigen::VectorXd values, bool dashed = false) {
  ReportSeries s;
  s.name = std::move(name);
  s.values = std::move(values);
  s.dashed = dashed;
  return s;
}

HtmlReport SmallReport() {
  HtmlReport report("Small <report> & test");
  report.AddHeading("Section with a < sign");
  report.AddParagraph("Text with \"quotes\" and </script> inside.");
  ReportFigure f;
  f.title = "sine";
  f.caption = "look at the peaks";
  f.x_label = "t (s)";
  f.y_label = "y";
  f.x = Eigen::VectorXd::LinSpaced(100, 0.0, 9.9);
  f.series.push_back(S("sin", f.x.array().sin().matrix()));
  f.series.push_back(S("cos", f.x.array().cos().matrix(), true));
  f.series.back().right_axis = true;
  f.series.back().color = "#ff0000";
  f.y2_label = "right";
  f.shades.push_back({2.0, 3.0, "a shade"});
  report.AddFigure(f);
  ReportFigure allan;
  allan.title = "log-log with bands";
  allan.caption = "bands";
  allan.log_x = allan.log_y = true;
  allan.x = Eigen::VectorXd::LinSpaced(8, 1.0, 8.0);
  ReportSeries s = S("adev", allan.x.cwiseInverse());
  s.lower = s.values * 0.8;
  s.upper = s.values * 1.2;
  s.values[3] = std::nan("");  // a gap
  allan.series.push_back(s);
  report.AddFigure(allan);
  report.AddTable({"t", "cap", {"method", "rmse"}, {{"ms-elm", "0.1"}, {"elm<", "0.2"}}, {}});
  return report;
}

TEST(Report, SmallReportRendersAndPassesTheCheck) {
  const std::string html = SmallReport().Render(test::FakeDygraphs());
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  EXPECT_EQ(check.figures, 2);
  EXPECT_EQ(check.tables, 1);
  // Caller text is escaped, never markup.
  EXPECT_NE(html.find("Small &lt;report&gt; &amp; test"), std::string::npos);
  EXPECT_EQ(html.find("</script> inside"), std::string::npos);
  EXPECT_NE(html.find("\"logx\":true"), std::string::npos);
  EXPECT_NE(html.find("\"right\":true"), std::string::npos);
  EXPECT_NE(html.find("\"color\":\"#ff0000\""), std::string::npos);
  EXPECT_NE(html.find("null"), std::string::npos);  // the NaN became a gap
}

TEST(Report, RealDygraphsIsInlinedWithoutItsSourceMap) {
  if (!HaveDygraphs()) GTEST_SKIP() << "libjs-dygraphs not installed";
  const DygraphsAssets assets = LoadDygraphs();
  EXPECT_GT(assets.js.size(), 100000u);
  EXPECT_EQ(assets.js.find("sourceMappingURL"), std::string::npos);
  const std::string html = SmallReport().Render(assets);
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  const std::string out = test::TempDir("report_small") + "/small.html";
  io::WriteFileAtomically(out, html);  // for a look in a browser
}

TEST(Report, MissingDygraphsNamesThePackage) {
  try {
    LoadDygraphs("/nonexistent/dygraphs");
    FAIL() << "no error";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("libjs-dygraphs"), std::string::npos) << e.what();
  }
}

TEST(Report, CheckCatchesBrokenReports) {
  const std::string good = SmallReport().Render(test::FakeDygraphs());
  ASSERT_TRUE(test::CheckReportHtml(good).ok());
  auto broken = [&](std::string from, std::string to) {
    std::string html = good;
    const size_t at = html.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    html.replace(at, from.size(), to);
    return test::CheckReportHtml(html);
  };
  EXPECT_FALSE(broken("</table>", "").ok());                                    // unclosed
  EXPECT_FALSE(broken("<h1>", "<h1><b>").ok());                                 // stray open tag
  EXPECT_FALSE(broken("</h1>", "</h1><img src=\"https://x.org/a.png\"/>").ok());  // external
  EXPECT_FALSE(broken("</h1>", "</h1><link rel=\"stylesheet\" href=\"a.css\"/>").ok());
  EXPECT_FALSE(broken("</h1>", "</h1>see http://example.org").ok());            // URL in text
  EXPECT_FALSE(broken("\"y\":[", "\"y\":[1,").ok());                            // length mismatch
  EXPECT_FALSE(broken("\"x\":[", "\"x\":[],\"old\":[").ok());                   // empty x
  EXPECT_FALSE(broken("var Dygraph", "var Other").ok());                        // not inlined
  EXPECT_FALSE(broken("<div class=\"fig\">", "<div class=fig>").ok());          // unquoted
  EXPECT_FALSE(test::CheckReportHtml("<p>no html element</p>").ok());
}

TEST(Report, FigureErrorsAreDataErrors) {
  HtmlReport report("r");
  ReportFigure f;
  f.title = "bad";
  f.x = Eigen::VectorXd::LinSpaced(10, 0.0, 1.0);
  f.series.push_back(S("short", Eigen::VectorXd::Zero(9)));
  EXPECT_THROW(report.AddFigure(f), DataError);
  f.series[0].values = Eigen::VectorXd::Zero(10);
  f.x[5] = -1.0;  // decreasing
  EXPECT_THROW(report.AddFigure(f), DataError);
  f.x = Eigen::VectorXd::LinSpaced(10, 0.0, 1.0);
  f.series[0].lower = Eigen::VectorXd::Zero(10);  // half a band
  EXPECT_THROW(report.AddFigure(f), DataError);
  f.series[0].lower.resize(0);
  f.max_points = 4;
  EXPECT_THROW(report.AddFigure(f), UsageError);
  EXPECT_THROW(report.AddTable({"t", "", {"a", "b"}, {{"1"}}, {}}), DataError);
  EXPECT_EQ(report.figures(), 0);
}

TEST(Report, DecimationKeepsTheEnvelopeAndOrder) {
  const Eigen::Index n = 100000;
  Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, 0.0, 1.0);
  Eigen::MatrixXd v(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    v(i, 0) = std::sin(0.01 * static_cast<double>(i));
    v(i, 1) = 0.0;
  }
  v(54321, 1) = 7.0;  // one spike: a stride would miss it
  v(12345, 1) = -3.0;
  const Decimated d = DecimateMinMax(x, v, Eigen::MatrixXd(), Eigen::MatrixXd(), 4000);
  ASSERT_EQ(d.x.size(), 4000);
  EXPECT_EQ(d.values.col(1).maxCoeff(), 7.0);
  EXPECT_EQ(d.values.col(1).minCoeff(), -3.0);
  EXPECT_DOUBLE_EQ(d.values.col(0).maxCoeff(), v.col(0).maxCoeff());
  EXPECT_DOUBLE_EQ(d.values.col(0).minCoeff(), v.col(0).minCoeff());
  for (Eigen::Index i = 1; i < d.x.size(); ++i) ASSERT_GE(d.x[i], d.x[i - 1]);
  EXPECT_EQ(d.x[0], 0.0);
  EXPECT_EQ(d.x[d.x.size() - 1], 1.0);
  // Short input comes back unchanged.
  const Decimated same = DecimateMinMax(x.head(100), v.topRows(100), Eigen::MatrixXd(), Eigen::MatrixXd(), 4000);
  EXPECT_EQ(same.values, v.topRows(100));
}

}  // namespace
}  // namespace gyrodrift::html

namespace gyrodrift::html {
namespace {

// A fleet page links its unit pages: relative paths beside or below the report become <a href>
// (percent-encoded) and pass the check; anything that could leave the folder or load a resource
// is refused.
TEST(HtmlReport, TableCellsLinkLocalPagesOnly) {
  HtmlReport report("fleet");
  ReportTable t{"units", "", {"serial", "status"}, {{"SN 1", "pass"}, {"SN2", "fail"}},
                {{"SN 1/report.html", ""}, {"", ""}}};
  report.AddTable(t);
  const std::string html = report.Render(LoadDygraphs());
  EXPECT_NE(html.find("<a href=\"SN%201/report.html\">SN 1</a>"), std::string::npos) << html;
  const test::ReportCheck check = test::CheckReportHtml(html);
  EXPECT_TRUE(check.ok()) << check.Summary();
  for (const char* bad : {"../x.html", "/etc/passwd", "http://example.com/a.html", "a/../../b"}) {
    t.links[0][0] = bad;
    EXPECT_THROW(report.AddTable(t), UsageError) << bad;
  }
  t.links = {{"a.html", ""}};  // one row of links for two rows
  EXPECT_THROW(report.AddTable(t), DataError);
  // The check still refuses a link that leaves the folder, and any src.
  EXPECT_FALSE(test::CheckReportHtml("<!DOCTYPE html><html><body><a href=\"../x.html\">x</a></body></html>").ok());
  EXPECT_FALSE(test::CheckReportHtml("<!DOCTYPE html><html><body><img src=\"x.png\"/></body></html>").ok());
}

}  // namespace
}  // namespace gyrodrift::html
