#include "gyrodrift/drift/temperature_check.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <set>

namespace gyrodrift::drift {

std::string TemperatureWarning(const Eigen::Ref<const Eigen::VectorXd>& temperature,
                               std::string_view name) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  bool integers = true;
  std::set<double> distinct;  // up to 3: enough to tell a step pattern from two levels
  for (Eigen::Index i = 0; i < temperature.size(); ++i) {
    const double t = temperature[i];
    if (!std::isfinite(t)) continue;
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    integers = integers && t == std::round(t);
    if (distinct.size() < 3) distinct.insert(t);
  }
  if (!(lo <= hi)) return "";  // no finite sample: refused where the column is used
  char text[512];
  const std::string column(name);
  const bool outside = lo < kPlausibleMinC || hi > kPlausibleMaxC;
  if (outside) {
    const char* hint = integers ? "; whole numbers only: raw ADC counts?"
                       : lo >= 193.0 && hi <= 473.0 ? ": kelvin?"
                                                    : "";
    std::snprintf(text, sizeof(text),
                  "temperature column '%s' runs from %.6g to %.6g, outside %g..%g degC%s; it is "
                  "taken as degC as given (ramps, dwells, rates in K/min and the reference "
                  "temperature read it so): convert it to degC",
                  column.c_str(), lo, hi, kPlausibleMinC, kPlausibleMaxC, hint);
    return text;
  }
  if (integers && distinct.size() > 2) {
    std::snprintf(text, sizeof(text),
                  "temperature column '%s' holds whole numbers only (%.6g to %.6g), stepping as "
                  "raw counts do: it is taken as degC as given, quantised in 1-K steps (coarse "
                  "for the rate terms); if these are counts, convert them to degC",
                  column.c_str(), lo, hi);
    return text;
  }
  return "";
}

}  // namespace gyrodrift::drift
