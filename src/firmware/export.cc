#include "gyrodrift/firmware/export.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/files.h"
#include "plan.h"

namespace gyrodrift::firmware {
namespace {

constexpr gyrodrift::internal::EnumNames<ExportFormat, 3> kFormats{{
    {ExportFormat::kC, "c"},
    {ExportFormat::kCoefficientsJson, "json-coefficients"},
    {ExportFormat::kPx4Params, "px4"},
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
  if (format == ExportFormat::kPx4Params) {
    if (device_ids.empty()) {
      ThrowOption("device_ids", "none",
                  "one per gyro instance with format px4 (PX4 matches its calibration to the "
                  "sensor by it: `gyrodrift convert LOG.ulg --list` shows sensor_gyro's "
                  "device_id)");
    }
    for (size_t i = 0; i < device_ids.size(); ++i) {
      const std::uint32_t id = device_ids[i];
      if (id == 0) ThrowOption("device_ids", "0", "a sensor's DEVID, not 0");
      if (std::find(device_ids.begin(), device_ids.begin() + static_cast<std::ptrdiff_t>(i), id) !=
          device_ids.begin() + static_cast<std::ptrdiff_t>(i)) {
        std::string ids;
        for (std::uint32_t d : device_ids) ids += (ids.empty() ? "" : ",") + std::to_string(d);
        ThrowOption("device_ids", ids,
                    "one DEVID per gyro instance, each once (" + std::to_string(id) + " twice)");
      }
    }
  } else if (!device_ids.empty()) {
    ThrowOption("device_ids", std::to_string(device_ids.size()) + " given",
                "none with format " + std::string(ToString(format)) + " (they are PX4's)");
  }
}

std::string RenderExport(const std::vector<LoadedModel>& axes, const ExportOptions& options) {
  options.Validate();
  switch (options.format) {
    case ExportFormat::kC:
      return RenderFirmwareC(axes, options);
    case ExportFormat::kCoefficientsJson:
      return RenderCoefficientsJson(axes, options);
    case ExportFormat::kPx4Params:
      return RenderPx4Params(axes, options.device_ids);
  }
  throw std::logic_error("unknown export format");
}

ExportResult ExportModelFiles(const std::vector<std::string>& model_paths,
                              const ExportOptions& options) {
  options.Validate();  // before any file is read, so a bad option is the error the user sees
  io::RequireDistinctFiles(model_paths, "model files", "give each file once");
  std::vector<LoadedModel> axes;
  for (const std::string& path : model_paths) {
    for (LoadedModel& axis : io::ReadModelFileAxes(path)) axes.push_back(std::move(axis));
  }
  return ExportAxes(std::move(axes), options);
}

ExportResult ExportAxes(std::vector<LoadedModel> axes, const ExportOptions& options) {
  options.Validate();
  ExportResult out;
  out.axes = std::move(axes);
  if (options.format == ExportFormat::kPx4Params) {
    Px4Params px4 = MakePx4Params(out.axes, options.device_ids);
    out.text = std::move(px4.text);
    out.px4_forms = std::move(px4.forms);
  } else {
    out.text = RenderExport(out.axes, options);
  }
  return out;
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
