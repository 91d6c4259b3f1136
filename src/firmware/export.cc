#include "gyrodrift/firmware/export.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "plan.h"

namespace gyrodrift::firmware {
namespace {

constexpr gyrodrift::internal::EnumNames<ExportFormat, 2> kFormats{{
    {ExportFormat::kC, "c"},
    {ExportFormat::kCoefficientsJson, "json-coefficients"},
}};
constexpr size_t kLongestPrefix = 32;

}  // namespace

std::string_view ToString(ExportFormat format) { return gyrodrift::internal::EnumName(format, kFormats); }

ExportFormat ExportFormatFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "format", kFormats);
}

void ExportOptions::Validate() const {
  const bool identifier = !prefix.empty() && prefix.size() <= kLongestPrefix &&
                          std::isalpha(static_cast<unsigned char>(prefix[0])) &&
                          std::all_of(prefix.begin(), prefix.end(), [](char ch) {
                            const auto u = static_cast<unsigned char>(ch);
                            return u < 0x80 && (std::isalnum(u) || ch == '_');
                          });
  if (!identifier) {
    ThrowOption("prefix", "'" + prefix + "'",
                "a C identifier: a letter, then letters, digits or underscores, at most " +
                    std::to_string(kLongestPrefix) + " characters");
  }
  if (single_precision && format != ExportFormat::kC) {
    ThrowOption("single_precision", "true",
                "false with format " + std::string(ToString(format)) +
                    " (it chooses the C header's arithmetic)");
  }
}

std::string RenderExport(const std::vector<LoadedModel>& axes, const ExportOptions& options) {
  return options.format == ExportFormat::kC ? RenderFirmwareC(axes, options)
                                            : RenderCoefficientsJson(axes, options);
}

ExportSummary SummariseExport(const std::vector<LoadedModel>& axes) {
  const internal::Plan plan = internal::MakePlan(axes);
  return {static_cast<int>(plan.axes.size()), static_cast<int>(plan.channels.size()), plan.states,
          plan.lag_stages, plan.rate_hz};
}

std::string ExportSummary::Line() const {
  return fmt::format(
      "{} ax{}, {} temperature channel{}, {} thermal state{} in {} lag stage{}, {} Hz", axes,
      axes == 1 ? "is" : "es", channels, channels == 1 ? "" : "s", states, states == 1 ? "" : "s",
      lag_stages, lag_stages == 1 ? "" : "s", rate_hz);
}
}  // namespace gyrodrift::firmware
