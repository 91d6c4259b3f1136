// A self-contained HTML report: headings, text, tables and interactive zoomable plots, in one
// file that opens offline in any browser.
//
// What it writes
//   Plots use dygraphs (danvk.org/dygraphs, MIT licence), read at run time from the Debian
//   package libjs-dygraphs (/usr/share/javascript/dygraphs/dygraph.min.{js,css}) and inlined into
//   the file, so the report loads nothing from the network. Each figure's data sit in a
//   <script type="application/json"> block; one small script builds every plot from them.
//   Long series are decimated for plotting: the samples are cut into max_points / 2 buckets of
//   consecutive indices and each bucket becomes two rows (at its first and last x) holding, per
//   series, the bucket's minimum and maximum in the order they occur. The envelope of the curve
//   (spikes included) survives, which a stride would lose; a 28,800-sample series becomes 4,000
//   points, so a report with a few dozen curves stays a few MB.
//   Values are printed with 7 significant digits (plotting precision; the CSV files beside the
//   report keep full precision); NaN and infinities become null (a gap).
// The tests check a report's structure with tests/support/report_check.h.
// Units: whatever the caller labels the axes with. Cost: O(total samples) to decimate and print.
#pragma once

#include <Eigen/Core>
#include <string>
#include <string_view>
#include <vector>

namespace gyrodrift::html {

// Where scripts/setup-deps.sh (Debian package libjs-dygraphs) installs dygraphs.
inline constexpr std::string_view kDygraphsDir = "/usr/share/javascript/dygraphs";

struct DygraphsAssets {
  std::string js;   // dygraph.min.js
  std::string css;  // dygraph.min.css
};
// Reads dygraph.min.js and dygraph.min.css from `dir`. Throws IoError naming the missing file and
// the package that provides it (libjs-dygraphs).
DygraphsAssets LoadDygraphs(const std::string& dir = std::string(kDygraphsDir));

struct ReportSeries {
  std::string name;
  Eigen::VectorXd values;  // one per x; NaN = gap
  // Optional confidence band (both empty, or both of the length of values); drawn shaded.
  Eigen::VectorXd lower, upper;
  bool dashed = false;      // e.g. a fitted model curve
  bool emphasis = false;    // drawn thick and black (the reference the others are judged by)
  bool right_axis = false;  // plotted against the right-hand y axis (y2_label)
  bool markers_only = false;  // a marker per point and no line (values of separate units)
  std::string color;        // CSS colour such as "#1f77b4"; empty = dygraphs' palette
};

// A shaded x interval with a label (the test block, a group of IMFs).
struct ReportShade {
  double x0 = 0.0, x1 = 0.0;
  std::string label;
};

struct ReportFigure {
  std::string title;
  std::string caption;  // what to look at (plain text)
  std::string x_label, y_label;
  std::string y2_label;  // right-hand axis, for series with right_axis
  Eigen::VectorXd x;  // non-decreasing, finite
  std::vector<ReportSeries> series;
  bool log_x = false, log_y = false;
  bool draw_points = false;  // mark every point (short curves such as per-IMF statistics)
  // x holds indices (IMF k): ticks at the integers only, and a margin so the end points show.
  bool integer_x = false;
  std::vector<ReportShade> shades;
  // Plotted rows after decimation, in [16, 1e6]. Default 4000.
  int max_points = 4000;
  int height_px = 300;  // in [100, 2000]
};

struct ReportTable {
  std::string title;
  std::string caption;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;  // each as long as header
  // Empty, or one per row and cell: a non-empty entry makes the cell a link to that relative
  // path (a file beside or below the report, such as a fleet's unit pages; percent-encoded).
  std::vector<std::vector<std::string>> links;
};

// Builds the document in order. Text is escaped; nothing the caller passes is taken as HTML.
class HtmlReport {
 public:
  explicit HtmlReport(std::string title);
  void AddHeading(const std::string& text);    // a section heading (<h2>)
  void AddParagraph(const std::string& text);  // one paragraph
  void AddPreformatted(const std::string& text);
  // Throws DataError when a series' length differs from x's, x is not finite and non-decreasing,
  // a band is half given, or the figure has no series or no samples; UsageError for max_points or
  // height_px out of range.
  void AddFigure(const ReportFigure& figure);
  // Throws DataError when a row's length differs from the header's.
  void AddTable(const ReportTable& table);
  int figures() const { return figures_; }
  // The whole HTML document with `assets` inlined.
  std::string Render(const DygraphsAssets& assets) const;

 private:
  std::string title_;
  std::string body_;  // rendered blocks
  int figures_ = 0;
};

// The min/max decimation described above, for `values` (rows x series, one column per series)
// and optional bands (lower/upper of the same shape, or empty): at most max_points rows; below
// that the input comes back unchanged. Bands keep the bucket's lowest lower and highest upper.
// Exposed for tests.
struct Decimated {
  Eigen::VectorXd x;
  Eigen::MatrixXd values;  // same columns as the input
  Eigen::MatrixXd lower, upper;  // empty when the input had none
};
Decimated DecimateMinMax(const Eigen::Ref<const Eigen::VectorXd>& x,
                         const Eigen::Ref<const Eigen::MatrixXd>& values,
                         const Eigen::Ref<const Eigen::MatrixXd>& lower,
                         const Eigen::Ref<const Eigen::MatrixXd>& upper, int max_points);

// A link to a file beside the report or below it (a fleet report's unit pages): no scheme, not
// absolute, no "..". Such a link loads nothing when the report opens, so an <a href> may use it.
bool IsLocalLink(const std::string& url);

}  // namespace gyrodrift::html
