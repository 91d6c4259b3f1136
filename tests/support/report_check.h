// A structural check of an HTML report of html::HtmlReport (balanced tags outside <script>/<style>,
// figure data present and non-empty, dygraphs inlined, no external resource; an <a href> may point
// to a relative path beside or below the report). Test code: the study, fleet and CLI tests check
// every report they write with it. Cost: O(bytes).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace gyrodrift::test {

// Result of CheckReportHtml.
struct ReportCheck {
  std::vector<std::string> problems;  // empty when the report passes
  int figures = 0;                    // figure data blocks found
  int tables = 0;
  std::size_t bytes = 0;
  bool ok() const { return problems.empty(); }
  std::string Summary() const;  // one line
};
// Structural check of a report: every tag outside <script>/<style> is balanced (void elements
// aside), attributes are quoted, each figure's JSON data block has non-empty x and series arrays
// of equal length, the dygraphs library is inlined (no <script src>, no <link>), and no src/href
// or CSS url() points outside the file.
ReportCheck CheckReportHtml(const std::string& html);

}  // namespace gyrodrift::test
