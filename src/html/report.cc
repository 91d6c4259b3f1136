#include "gyrodrift/html/report.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::html {
namespace {

std::string Escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// JSON string literal that is also safe inside a <script> block ("</" cannot close it).
std::string JsonString(std::string_view text) {
  std::string s = nlohmann::json(std::string(text)).dump();
  std::string out;
  out.reserve(s.size());
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '<') {
      out += "\\u003c";
    } else {
      out += s[i];
    }
  }
  return out;
}

// Plotting precision; the CSV files keep every digit.
void AppendNumber(std::string& out, double v) {
  if (!std::isfinite(v)) {
    out += "null";
    return;
  }
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.7g", v);
  out += buffer;
}

void AppendArray(std::string& out, const Eigen::Ref<const Eigen::VectorXd>& v) {
  out += '[';
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    if (i) out += ',';
    AppendNumber(out, v[i]);
  }
  out += ']';
}

bool LooksNumeric(const std::string& cell) {
  if (cell.empty()) return false;
  // "-" is an empty numeric cell (no value): aligned with the numbers of its column.
  if (cell == "-" || cell == "nan" || cell == "inf" || cell == "-inf") return true;
  char* end = nullptr;
  std::strtod(cell.c_str(), &end);
  return end == cell.c_str() + cell.size();
}

std::string ReadAsset(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw IoError(path +
                  ": cannot read (the HTML report inlines dygraphs from the Debian package "
                  "libjs-dygraphs: apt-get install libjs-dygraphs, or run scripts/setup-deps.sh)");
  }
  std::ostringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  // The source-map comment would make a browser's developer tools look for a file beside the
  // report; nothing else refers outside the file.
  const size_t map = text.rfind("sourceMappingURL");
  if (map != std::string::npos) {
    const size_t line = text.rfind('\n', map);
    text.erase(line == std::string::npos ? 0 : line + 1);
  }
  return text;
}

// Builds every plot from the JSON blocks. Dygraphs wants rows [x, y1, y2, ...]; with a band the
// cells are [lo, y, hi] (customBars).
constexpr std::string_view kPlotScript = R"JS(
(function () {
  var blocks = document.querySelectorAll('script.fig-data');
  for (var b = 0; b < blocks.length; ++b) {
    var f = JSON.parse(blocks[b].textContent);
    var bars = f.series.some(function (s) { return s.lo !== undefined; });
    var rows = [];
    for (var i = 0; i < f.x.length; ++i) {
      var row = [f.x[i]];
      for (var k = 0; k < f.series.length; ++k) {
        var s = f.series[k], v = s.y[i];
        if (!bars) { row.push(v); continue; }
        if (v === null) { row.push(null); continue; }
        var lo = s.lo !== undefined ? s.lo[i] : v, hi = s.hi !== undefined ? s.hi[i] : v;
        row.push([lo === null ? v : lo, v, hi === null ? v : hi]);
      }
      rows.push(row);
    }
    var seriesOptions = {};
    f.series.forEach(function (s) {
      var o = { axis: s.right ? 'y2' : 'y' };
      if (s.dashed) o.strokePattern = [6, 4];
      if (s.color) o.color = s.color;
      if (s.bold) { o.strokeWidth = 2.2; o.color = s.color || '#000000'; }
      if (s.markers) { o.strokeWidth = 0; o.drawPoints = true; o.pointSize = 4; }
      seriesOptions[s.name] = o;
    });
    var right = f.series.some(function (s) { return s.right; });
    var shades = f.shades;
    var target = document.getElementById(blocks[b].dataset.target);
    // At dygraphs' 30 px per label a short panel (the IMFs) gets one y tick and no scale; labels
    // such as -0.0725 or 0.00007 need more than its 50 px, else they run into the axis title.
    var yAxis = { axisLabelWidth: 64, pixelsPerLabel: target.clientHeight < 200 ? 16 : 30 };
    var xAxis = { logscale: f.logx };
    if (f.intx) {
      xAxis.ticker = function (min, max) {
        var ticks = [];
        for (var v = Math.ceil(min); v <= max; ++v) ticks.push({ v: v, label: String(v) });
        return ticks;
      };
    }
    var axes = { x: xAxis, y: yAxis };
    if (right) {
      axes.y2 = { independentTicks: true, axisLabelWidth: yAxis.axisLabelWidth,
                  pixelsPerLabel: yAxis.pixelsPerLabel };
    }
    var colours = ['rgba(255,200,0,0.15)', 'rgba(0,150,255,0.12)', 'rgba(0,200,100,0.12)',
                   'rgba(200,0,200,0.10)'];
    new Dygraph(target, rows, {
      labels: [f.xlabel].concat(f.series.map(function (s) { return s.name; })),
      xlabel: f.xlabel, ylabel: f.ylabel,
      customBars: bars, logscale: f.logy,
      axes: axes, xRangePad: f.intx ? 12 : 0,
      y2label: right ? f.y2label : undefined,
      drawPoints: f.points, pointSize: 2.5,
      series: seriesOptions,
      legend: 'always', labelsSeparateLines: false,
      labelsDiv: document.getElementById(blocks[b].dataset.target + '-legend'),
      connectSeparatedPoints: false,
      strokeWidth: 1.2, digitsAfterDecimal: 5, maxNumberWidth: 8,
      underlayCallback: function (ctx, area, g) {
        shades.forEach(function (s, n) {
          var l = g.toDomXCoord(s[0]), r = g.toDomXCoord(s[1]);
          ctx.fillStyle = colours[n % colours.length];
          ctx.fillRect(l, area.y, r - l, area.h);
          ctx.fillStyle = '#555';
          ctx.font = '11px sans-serif';
          ctx.fillText(s[2], Math.max(l, area.x) + 3, area.y + 12);
        });
      }
    });
  }
})();
)JS";

constexpr std::string_view kPageStyle = R"CSS(
body { font-family: sans-serif; max-width: 1200px; margin: 1em auto; padding: 0 1em; color: #222; }
h1 { font-size: 1.6em; } h2 { margin-top: 1.6em; border-bottom: 1px solid #ccc; }
.fig { margin: 1.2em 0 2em 0; }
.fig h3 { font-size: 1.05em; margin-bottom: 0.2em; }
.plot { width: 100%; }
.legend { font-size: 0.85em; min-height: 1.3em; }
.caption { font-size: 0.9em; color: #444; margin-top: 0.3em; }
table { border-collapse: collapse; font-size: 0.85em; margin: 0.5em 0; }
th, td { border: 1px solid #bbb; padding: 2px 8px; text-align: left; }
th { background: #eee; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
pre { background: #f6f6f6; padding: 0.6em; overflow-x: auto; font-size: 0.85em; }
)CSS";

// Percent-encodes what a path may hold but a URL may not (spaces, #, ?, %, non-ASCII bytes).
std::string PercentEncode(const std::string& path) {
  std::string out;
  for (const unsigned char ch : path) {
    if (std::isalnum(ch) || ch == '/' || ch == '-' || ch == '_' || ch == '.' || ch == '~') {
      out += static_cast<char>(ch);
    } else {
      static const char* kHex = "0123456789ABCDEF";
      out += '%';
      out += kHex[ch >> 4];
      out += kHex[ch & 15];
    }
  }
  return out;
}

}  // namespace

DygraphsAssets LoadDygraphs(const std::string& dir) {
  DygraphsAssets assets;
  assets.js = ReadAsset(dir + "/dygraph.min.js");
  assets.css = ReadAsset(dir + "/dygraph.min.css");
  return assets;
}

Decimated DecimateMinMax(const Eigen::Ref<const Eigen::VectorXd>& x,
                         const Eigen::Ref<const Eigen::MatrixXd>& values,
                         const Eigen::Ref<const Eigen::MatrixXd>& lower,
                         const Eigen::Ref<const Eigen::MatrixXd>& upper, int max_points) {
  const Eigen::Index n = x.size();
  const Eigen::Index cols = values.cols();
  const bool bands = lower.size() > 0;
  Decimated out;
  if (n <= max_points) {
    out.x = x;
    out.values = values;
    if (bands) {
      out.lower = lower;
      out.upper = upper;
    }
    return out;
  }
  const Eigen::Index buckets = std::max<Eigen::Index>(1, max_points / 2);
  out.x.resize(2 * buckets);
  out.values.resize(2 * buckets, cols);
  if (bands) {
    out.lower.resize(2 * buckets, cols);
    out.upper.resize(2 * buckets, cols);
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index b = 0; b < buckets; ++b) {
    const Eigen::Index i0 = b * n / buckets;
    const Eigen::Index i1 = (b + 1) * n / buckets - 1;
    out.x[2 * b] = x[i0];
    out.x[2 * b + 1] = x[i1];
    for (Eigen::Index c = 0; c < cols; ++c) {
      Eigen::Index arg_min = -1, arg_max = -1;
      for (Eigen::Index i = i0; i <= i1; ++i) {
        const double v = values(i, c);
        if (!std::isfinite(v)) continue;
        if (arg_min < 0 || v < values(arg_min, c)) arg_min = i;
        if (arg_max < 0 || v > values(arg_max, c)) arg_max = i;
      }
      if (arg_min < 0) {
        out.values(2 * b, c) = out.values(2 * b + 1, c) = nan;
      } else {
        // The extreme that occurs first goes first, so the drawn line follows the signal.
        const bool min_first = arg_min <= arg_max;
        out.values(2 * b, c) = values(min_first ? arg_min : arg_max, c);
        out.values(2 * b + 1, c) = values(min_first ? arg_max : arg_min, c);
      }
      if (bands) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (Eigen::Index i = i0; i <= i1; ++i) {
          if (std::isfinite(lower(i, c))) lo = std::min(lo, lower(i, c));
          if (std::isfinite(upper(i, c))) hi = std::max(hi, upper(i, c));
        }
        out.lower(2 * b, c) = out.lower(2 * b + 1, c) = std::isfinite(lo) ? lo : nan;
        out.upper(2 * b, c) = out.upper(2 * b + 1, c) = std::isfinite(hi) ? hi : nan;
      }
    }
  }
  return out;
}

namespace {

// Refuses a figure that cannot be drawn (naming it); true when a series has a band.
bool CheckFigure(const ReportFigure& f) {
  if (f.max_points < 16 || f.max_points > 1000000) {
    ThrowOption("max_points", std::to_string(f.max_points), "an integer in [16, 1000000]");
  }
  if (f.height_px < 100 || f.height_px > 2000) {
    ThrowOption("height_px", std::to_string(f.height_px), "an integer in [100, 2000]");
  }
  const std::string where = "figure '" + f.title + "'";
  const Eigen::Index n = f.x.size();
  if (n == 0 || f.series.empty()) throw DataError(where + ": no samples or no series");
  for (Eigen::Index i = 0; i < n; ++i) {
    if (!std::isfinite(f.x[i]) || (i > 0 && f.x[i] < f.x[i - 1])) {
      throw DataError(where + ": x must be finite and non-decreasing (sample " +
                      std::to_string(i + 1) + ")");
    }
  }
  bool bands = false;
  for (const auto& s : f.series) {
    if (s.values.size() != n) {
      throw DataError(where + ": series '" + s.name + "' has " + std::to_string(s.values.size()) +
                      " values for " + std::to_string(n) + " x");
    }
    if ((s.lower.size() == 0) != (s.upper.size() == 0) ||
        (s.lower.size() != 0 && (s.lower.size() != n || s.upper.size() != n))) {
      throw DataError(where + ": series '" + s.name + "' needs both band limits, one per x");
    }
    bands = bands || s.lower.size() != 0;
  }
  return bands;
}

// The figure's series as columns (and their bands, a series without one banded by itself when
// another has one), reduced to at most f.max_points rows.
Decimated DecimateFigure(const ReportFigure& f, bool bands) {
  const Eigen::Index n = f.x.size();
  const Eigen::Index cols = static_cast<Eigen::Index>(f.series.size());
  Eigen::MatrixXd values(n, cols), lower, upper;
  if (bands) {
    lower.resize(n, cols);
    upper.resize(n, cols);
  }
  for (Eigen::Index c = 0; c < cols; ++c) {
    const auto& s = f.series[static_cast<size_t>(c)];
    values.col(c) = s.values;
    if (bands) {
      lower.col(c) = s.lower.size() ? s.lower : s.values;
      upper.col(c) = s.upper.size() ? s.upper : s.values;
    }
  }
  return DecimateMinMax(f.x, values, lower, upper, f.max_points);
}

// The figure's data as the page's script reads it: labels, axes, series and shades.
std::string FigureJson(const ReportFigure& f, const Decimated& d) {
  std::string json =
      "{\"title\":" + JsonString(f.title) + ",\"xlabel\":" + JsonString(f.x_label) +
      ",\"ylabel\":" + JsonString(f.y_label) + ",\"y2label\":" + JsonString(f.y2_label) +
      ",\"logx\":" + (f.log_x ? "true" : "false") + ",\"logy\":" + (f.log_y ? "true" : "false") +
      ",\"points\":" + (f.draw_points ? "true" : "false") +
      ",\"intx\":" + (f.integer_x ? "true" : "false") + ",\"x\":";
  AppendArray(json, d.x);
  json += ",\"series\":[";
  for (size_t c = 0; c < f.series.size(); ++c) {
    const auto& s = f.series[c];
    const Eigen::Index col = static_cast<Eigen::Index>(c);
    if (c) json += ',';
    json += "{\"name\":" + JsonString(s.name) + ",\"dashed\":" + (s.dashed ? "true" : "false") +
            ",\"bold\":" + (s.emphasis ? "true" : "false") +
            (s.color.empty() ? std::string() : ",\"color\":" + JsonString(s.color)) +
            (s.markers_only ? ",\"markers\":true" : "") +
            ",\"right\":" + (s.right_axis ? "true" : "false") + ",\"y\":";
    AppendArray(json, d.values.col(col));
    if (s.lower.size()) {
      json += ",\"lo\":";
      AppendArray(json, d.lower.col(col));
      json += ",\"hi\":";
      AppendArray(json, d.upper.col(col));
    }
    json += '}';
  }
  json += "],\"shades\":[";
  for (size_t i = 0; i < f.shades.size(); ++i) {
    if (i) json += ',';
    json += '[';
    AppendNumber(json, f.shades[i].x0);
    json += ',';
    AppendNumber(json, f.shades[i].x1);
    json += ',' + JsonString(f.shades[i].label) + ']';
  }
  json += "]}";
  return json;
}

}  // namespace

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::AddHeading(const std::string& text) { body_ += "<h2>" + Escape(text) + "</h2>\n"; }

void HtmlReport::AddParagraph(const std::string& text) { body_ += "<p>" + Escape(text) + "</p>\n"; }

void HtmlReport::AddPreformatted(const std::string& text) {
  body_ += "<pre>" + Escape(text) + "</pre>\n";
}

void HtmlReport::AddFigure(const ReportFigure& f) {
  const Decimated d = DecimateFigure(f, CheckFigure(f));
  const std::string id = "fig" + std::to_string(++figures_);
  const std::string json = FigureJson(f, d);
  body_ += "<div class=\"fig\">\n<h3>" + Escape(f.title) + "</h3>\n";
  body_ += "<div id=\"" + id + "\" class=\"plot\" style=\"height:" + std::to_string(f.height_px) +
           "px\"></div>\n";
  body_ += "<div id=\"" + id + "-legend\" class=\"legend\"></div>\n";
  body_ += "<p class=\"caption\">" + Escape(f.caption) + "</p>\n";
  body_ += "<script type=\"application/json\" class=\"fig-data\" data-target=\"" + id + "\">" +
           json + "</script>\n</div>\n";
}

void HtmlReport::AddTable(const ReportTable& t) {
  if (!t.links.empty() && t.links.size() != t.rows.size()) {
    throw DataError("table '" + t.title + "': links must be empty or one row per row");
  }
  for (size_t r = 0; r < t.links.size(); ++r) {
    if (t.links[r].size() != t.header.size()) {
      throw DataError("table '" + t.title + "': links row " + std::to_string(r + 1) + " has " +
                      std::to_string(t.links[r].size()) + " cells for " +
                      std::to_string(t.header.size()) + " columns");
    }
    for (const std::string& link : t.links[r]) {
      if (!link.empty() && !IsLocalLink(link)) {
        throw UsageError("table '" + t.title + "': link '" + link +
                         "' must be a relative path to a file beside or below the report");
      }
    }
  }
  for (size_t r = 0; r < t.rows.size(); ++r) {
    if (t.rows[r].size() != t.header.size()) {
      throw DataError("table '" + t.title + "': row " + std::to_string(r + 1) + " has " +
                      std::to_string(t.rows[r].size()) + " cells for " +
                      std::to_string(t.header.size()) + " columns");
    }
  }
  body_ += "<div class=\"table\">\n<h3>" + Escape(t.title) + "</h3>\n<table>\n<tr>";
  for (const auto& h : t.header) body_ += "<th>" + Escape(h) + "</th>";
  body_ += "</tr>\n";
  for (size_t r = 0; r < t.rows.size(); ++r) {
    body_ += "<tr>";
    for (size_t c = 0; c < t.rows[r].size(); ++c) {
      const std::string& cell = t.rows[r][c];
      const std::string link = t.links.empty() ? std::string() : t.links[r][c];
      body_ += (LooksNumeric(cell) ? "<td class=\"num\">" : "<td>");
      body_ += link.empty()
                   ? Escape(cell)
                   : "<a href=\"" + Escape(PercentEncode(link)) + "\">" + Escape(cell) + "</a>";
      body_ += "</td>";
    }
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
  if (!t.caption.empty()) body_ += "<p class=\"caption\">" + Escape(t.caption) + "</p>\n";
  body_ += "</div>\n";
}

std::string HtmlReport::Render(const DygraphsAssets& assets) const {
  std::string html;
  html.reserve(body_.size() + assets.js.size() + assets.css.size() + 8192);
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"/>\n";
  html += "<title>" + Escape(title_) + "</title>\n";
  html += "<style>\n" + assets.css + "\n" + std::string(kPageStyle) + "</style>\n";
  html += "<script>\n" + assets.js + "\n</script>\n</head>\n<body>\n";
  html += "<h1>" + Escape(title_) + "</h1>\n";
  html +=
      "<p class=\"caption\">Plots: drag to zoom, shift-drag to pan, double-click to reset.</p>\n";
  html += body_;
  html += "<script>\n" + std::string(kPlotScript) + "</script>\n</body>\n</html>\n";
  return html;
}

bool IsLocalLink(const std::string& url) {
  if (url.empty() || url[0] == '/' || url.find(':') != std::string::npos) return false;
  return ("/" + url + "/").find("/../") == std::string::npos;
}

}  // namespace gyrodrift::html
