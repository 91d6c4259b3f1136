// The coefficients JSON of export.h (schema in docs/firmware.md): the plan (plan.h) as data.
#include <cmath>
#include <nlohmann/json.hpp>
#include <string_view>

#include "gyrodrift/common/version.h"
#include "plan.h"

namespace gyrodrift::firmware {
namespace {

using namespace internal;

constexpr std::string_view kCoefficientsFormat = "gyrodrift-coefficients";
// 2: a sub-model may hold a hysteresis term.
// 3: "static" (powers of a channel with their range) replaces "linear"; a state's rate holds
// within [rate_min, rate_max] (null: unheld, models of format 6 and older).
// 4: beyond [rate_min, rate_max] a state's rate moves at rate_beyond times its slope (0: held).
constexpr int kCoefficientsFormatVersion = 4;

}  // namespace

std::string RenderCoefficientsJson(const std::vector<LoadedModel>& axes,
                                   const ExportOptions& options) {
  options.Validate();
  const Plan plan = MakePlan(axes);
  RequireDistinctAxes(axes);
  using nlohmann::json;
  json out_axes = json::array();
  for (const Axis& axis : plan.axes) {
    json subs = json::array();
    for (const Sub& sub : axis.subs) {
      auto finite = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
      json statics = json::array();
      for (const Static& st : sub.statics) {
        statics.push_back({{"channel", st.channel},
                           {"centre_c", st.centre_c},
                           {"scale_k", st.scale_k},
                           {"level_min", finite(st.level_min)},
                           {"level_max", finite(st.level_max)},
                           {"powers", st.powers}});
      }
      json states = json::array();
      for (const State& st : sub.states) {
        const Chain& chain = plan.chains[static_cast<size_t>(st.chain)];
        states.push_back({{"channel", chain.channel},
                          {"tau_s", chain.tau_s},
                          {"order", st.order},
                          {"gain", chain.gain},
                          {"centre_c", st.centre_c},
                          {"scale_k", st.scale_k},
                          {"level_min", st.level_min},
                          {"level_max", st.level_max},
                          {"powers", st.powers},
                          {"rate", st.rate},
                          {"rate_min", finite(st.rate_min)},
                          {"rate_max", finite(st.rate_max)},
                          {"rate_beyond", st.rate_beyond}});
      }
      const Hysteresis& h = sub.hysteresis;
      subs.push_back({{"name", sub.name},
                      {"zero", sub.zero},
                      {"intercept", sub.intercept},
                      {"reference_estimate", sub.reference_estimate},
                      {"static", std::move(statics)},
                      {"states", std::move(states)},
                      {"hysteresis", h.state < 0 ? json(nullptr)
                                                 : json{{"state", h.state},
                                                        {"width_k", h.width_k},
                                                        {"coefficient", h.coefficient}}}});
    }
    out_axes.push_back(
        {{"name", axis.name},
         {"method", axis.method},
         {"summary", axis.summary},
         {"source", axis.source},
         {"reference_c", std::isnan(axis.reference_c) ? json(nullptr) : json(axis.reference_c)},
         {"sub_models", std::move(subs)}});
  }
  const json out = {{"format", kCoefficientsFormat}, {"format_version", kCoefficientsFormatVersion},
                    {"tool_version", kVersion},      {"rate_hz", plan.rate_hz},
                    {"channels", plan.channels},     {"axes", std::move(out_axes)}};
  return out.dump(2, ' ', false, json::error_handler_t::replace) + "\n";
}

}  // namespace gyrodrift::firmware
