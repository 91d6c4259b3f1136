#include "support/report_check.h"

#include <cctype>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "gyrodrift/html/report.h"

namespace gyrodrift::test {

namespace {

bool IsVoid(const std::string& tag) {
  static const char* kVoid[] = {"area",  "base", "br",   "col",    "embed", "hr", "img",
                                "input", "link", "meta", "source", "track", "wbr"};
  for (const char* v : kVoid) {
    if (tag == v) return true;
  }
  return false;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct Attribute {
  std::string name, value;
};

// Parses the attributes of a start tag; returns false on an unquoted or unterminated value.
bool ParseAttributes(std::string_view text, std::vector<Attribute>& out) {
  size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i >= text.size() || text[i] == '/') break;
    size_t start = i;
    while (i < text.size() && text[i] != '=' &&
           !std::isspace(static_cast<unsigned char>(text[i])) && text[i] != '/') {
      ++i;
    }
    Attribute a{Lower(std::string(text.substr(start, i - start))), ""};
    if (i < text.size() && text[i] == '=') {
      ++i;
      if (i >= text.size() || (text[i] != '"' && text[i] != '\'')) return false;
      const char quote = text[i++];
      const size_t end = text.find(quote, i);
      if (end == std::string_view::npos) return false;
      a.value = std::string(text.substr(i, end - i));
      i = end + 1;
    }
    out.push_back(std::move(a));
  }
  return true;
}

bool External(const std::string& url) {
  const std::string u = Lower(url);
  return !(u.empty() || u[0] == '#' || u.rfind("data:", 0) == 0);
}

void CheckFigureData(const std::string& text, int index, ReportCheck& check) {
  const std::string where = "figure data block " + std::to_string(index);
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const std::exception& e) {
    check.problems.push_back(where + ": not JSON (" + e.what() + ")");
    return;
  }
  if (!j.contains("x") || !j["x"].is_array() || j["x"].empty()) {
    check.problems.push_back(where + ": empty or missing x array");
    return;
  }
  if (!j.contains("series") || !j["series"].is_array() || j["series"].empty()) {
    check.problems.push_back(where + ": no series");
    return;
  }
  const size_t n = j["x"].size();
  for (const auto& s : j["series"]) {
    const std::string name = s.value("name", std::string("?"));
    if (!s.contains("y") || !s["y"].is_array() || s["y"].size() != n) {
      check.problems.push_back(where + ": series '" + name + "' does not have one value per x");
      continue;
    }
    bool any = false;
    for (const auto& v : s["y"]) any = any || v.is_number();
    if (!any) check.problems.push_back(where + ": series '" + name + "' has no finite value");
  }
}

}  // namespace

ReportCheck CheckReportHtml(const std::string& html) {
  ReportCheck check;
  check.bytes = html.size();
  std::vector<std::string> open;
  bool dygraphs_inlined = false;
  bool saw_html = false;
  size_t i = 0;
  auto line_of = [&](size_t pos) {
    return std::to_string(std::count(html.begin(), html.begin() + static_cast<long>(pos), '\n') +
                          1);
  };
  while (i < html.size()) {
    const size_t lt = html.find('<', i);
    // Text between tags: no URL may point outside the file.
    const std::string_view text(html.data() + i, (lt == std::string::npos ? html.size() : lt) - i);
    if (text.find("http://") != std::string_view::npos ||
        text.find("https://") != std::string_view::npos) {
      check.problems.push_back("line " + line_of(i) + ": URL in the text");
    }
    if (lt == std::string::npos) break;
    if (html.compare(lt, 4, "<!--") == 0) {
      const size_t end = html.find("-->", lt + 4);
      if (end == std::string::npos) {
        check.problems.push_back("line " + line_of(lt) + ": unterminated comment");
        break;
      }
      i = end + 3;
      continue;
    }
    if (html.compare(lt, 2, "<!") == 0) {
      const size_t end = html.find('>', lt);
      if (end == std::string::npos) break;
      i = end + 1;
      continue;
    }
    const size_t gt = html.find('>', lt);
    if (gt == std::string::npos) {
      check.problems.push_back("line " + line_of(lt) + ": unterminated tag");
      break;
    }
    const bool closing = lt + 1 < html.size() && html[lt + 1] == '/';
    const size_t name_start = lt + (closing ? 2 : 1);
    size_t name_end = name_start;
    while (name_end < gt &&
           (std::isalnum(static_cast<unsigned char>(html[name_end])) || html[name_end] == '-')) {
      ++name_end;
    }
    const std::string name = Lower(html.substr(name_start, name_end - name_start));
    if (name.empty()) {
      check.problems.push_back("line " + line_of(lt) + ": '<' that starts no tag (unescaped text)");
      i = lt + 1;
      continue;
    }
    if (closing) {
      if (open.empty() || open.back() != name) {
        check.problems.push_back("line " + line_of(lt) + ": </" + name + "> closes " +
                                 (open.empty() ? std::string("nothing") : "<" + open.back() + ">"));
        // Recover: pop to the matching tag if it is open at all.
        auto it = std::find(open.rbegin(), open.rend(), name);
        if (it != open.rend()) open.erase(std::next(it).base(), open.end());
      } else {
        open.pop_back();
      }
      i = gt + 1;
      continue;
    }
    const bool self_closing = html[gt - 1] == '/';
    std::vector<Attribute> attributes;
    const std::string_view attr_text(html.data() + name_end,
                                     gt - name_end - (self_closing ? 1 : 0));
    if (!ParseAttributes(attr_text, attributes)) {
      check.problems.push_back("line " + line_of(lt) + ": <" + name +
                               "> has an unquoted attribute");
    }
    for (const auto& a : attributes) {
      const bool local_anchor = name == "a" && a.name == "href" && html::IsLocalLink(a.value);
      if ((a.name == "src" || a.name == "href" || a.name == "action") && External(a.value) &&
          !local_anchor) {
        check.problems.push_back("line " + line_of(lt) + ": <" + name + " " + a.name + "=\"" +
                                 a.value + "\"> refers outside the file");
      }
    }
    if (name == "html") saw_html = true;
    if (name == "link")
      check.problems.push_back("line " + line_of(lt) + ": <link> (external resource)");
    if (name == "table") ++check.tables;
    if (name == "script" || name == "style") {
      const std::string close = "</" + name;
      size_t end = gt + 1;
      for (;;) {
        end = html.find("</", end);
        if (end == std::string::npos || Lower(html.substr(end, close.size())) == close) break;
        end += 2;
      }
      if (end == std::string::npos) {
        check.problems.push_back("line " + line_of(lt) + ": <" + name + "> never closed");
        break;
      }
      const std::string content = html.substr(gt + 1, end - gt - 1);
      if (name == "style" && Lower(content).find("url(http") != std::string::npos) {
        check.problems.push_back("line " + line_of(lt) + ": CSS url() outside the file");
      }
      if (name == "script") {
        bool data_block = false;
        for (const auto& a : attributes) {
          if (a.name == "class" && a.value == "fig-data") data_block = true;
        }
        if (data_block) {
          ++check.figures;
          CheckFigureData(content, check.figures, check);
        } else if (content.size() > 50000 && content.find("Dygraph") != std::string::npos) {
          dygraphs_inlined = true;
        }
      }
      const size_t close_gt = html.find('>', end);
      i = close_gt == std::string::npos ? html.size() : close_gt + 1;
      continue;
    }
    if (!self_closing && !IsVoid(name)) open.push_back(name);
    i = gt + 1;
  }
  if (!saw_html) check.problems.push_back("no <html> element");
  for (auto it = open.rbegin(); it != open.rend(); ++it) {
    check.problems.push_back("<" + *it + "> never closed");
  }
  if (!dygraphs_inlined) check.problems.push_back("the dygraphs library is not inlined");
  return check;
}

std::string ReportCheck::Summary() const {
  return std::string(ok() ? "report ok"
                          : "report has " + std::to_string(problems.size()) + " problem(s)") +
         ": " + std::to_string(figures) + " figures, " + std::to_string(tables) + " tables, " +
         std::to_string(bytes) + " bytes" + (ok() ? "" : "; first: " + problems.front());
}

}  // namespace gyrodrift::test
