#include "gyrodrift/io/firmware_export.h"

#include <fmt/core.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/version.h"
#include "gyrodrift/drift/features.h"

namespace gyrodrift::io {
namespace {

constexpr internal::EnumNames<ExportFormat, 2> kFormats{{
    {ExportFormat::kC, "c"},
    {ExportFormat::kCoefficientsJson, "json-coefficients"},
}};
constexpr size_t kLongestPrefix = 32;
constexpr std::string_view kCoefficientsFormat = "gyrodrift-coefficients";
// 2: a sub-model may hold a hysteresis term.
// 3: "static" (powers of a channel with their range) replaces "linear"; a state's rate holds
// within [rate_min, rate_max] (null: unheld, models of format 6 and older).
constexpr int kCoefficientsFormatVersion = 3;

// ---------------------------------------------------------------------------------------------
// The models reduced to what the step computes, shared by both renderers.

// A chain of first-order lags of one channel with one time constant; every state of that channel
// and constant reads its stages (they are the same recursion), up to the deepest order asked.
struct Chain {
  int channel = 0;  // global channel index
  double tau_s = 0.0;
  double gain = 0.0;  // 1 - exp(-dt/tau)
  int stages = 0;
  int first = 0;  // index of its first stage in the state's lag array
};

struct State {
  int chain = 0;
  int order = 0;
  double centre_c = 0.0, scale_k = 0.0;
  double level_min = 0.0, level_max = 0.0;
  std::vector<double> powers;  // coefficients of the level's powers 1..max_power
  double rate = 0.0;           // coefficient of the level's rate, per K/s
  double rate_min = -std::numeric_limits<double>::infinity();  // the rate is held within
  double rate_max = std::numeric_limits<double>::infinity();
};

// Static powers of one channel's standardised level, continued along their tangent beyond
// [level_min, level_max].
struct Static {
  int channel = 0;  // global channel index
  double centre_c = 0.0, scale_k = 0.0;
  double level_min = 0.0, level_max = 0.0;
  std::vector<double> powers;  // coefficients of the powers 1..
};

// The hysteresis term of a sub-model: the play operator of one of its states' level.
struct Hysteresis {
  int state = -1;  // index in Sub::states; -1: none
  int slot = 0;    // index of its play in the step's state arrays
  double width_k = 0.0;
  double coefficient = 0.0;
};

struct Sub {
  std::string name;
  bool zero = false;  // a sub-model without a model (old files' noise group): contributes 0
  double intercept = 0.0;
  double reference_estimate = 0.0;  // subtracted when the model has a reference temperature
  std::vector<Static> statics;
  std::vector<State> states;
  Hysteresis hysteresis;
};

struct Axis {
  std::string name;  // target column
  std::string summary;
  std::string source;  // training file
  std::string method;
  double reference_c = std::numeric_limits<double>::quiet_NaN();
  std::vector<Sub> subs;
};

struct Plan {
  double rate_hz = 0.0;
  std::vector<std::string> channels;
  std::vector<Chain> chains;
  std::vector<Axis> axes;
  int lag_stages = 0;
  int states = 0;
  int plays = 0;  // hysteresis terms
};

std::vector<std::string> SplitNames(const std::string& names) {
  std::vector<std::string> out;
  size_t start = 0;
  while (true) {
    const size_t comma = names.find(',', start);
    out.push_back(names.substr(start, comma == std::string::npos ? comma : comma - start));
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

std::string AxisLabel(size_t i, const LoadedModel& m) {
  return fmt::format("axis {} ({})", i, m.info.target_column);
}

Plan MakePlan(const std::vector<LoadedModel>& axes) {
  RequireExportable(axes);
  Plan plan;
  for (size_t a = 0; a < axes.size(); ++a) {
    const LoadedModel& loaded = axes[a];
    const drift::DriftModel& model = loaded.model;
    const std::vector<std::string> names = SplitNames(loaded.info.temperature_column);
    std::vector<int> global;  // model channel -> plan channel
    for (const std::string& name : names) {
      const auto at = std::find(plan.channels.begin(), plan.channels.end(), name);
      global.push_back(static_cast<int>(at - plan.channels.begin()));
      if (at == plan.channels.end()) plan.channels.push_back(name);
    }
    Axis axis;
    axis.name = loaded.info.target_column;
    axis.summary = model.Summary();
    axis.source = loaded.info.source;
    axis.method = drift::ToString(model.options.method);
    axis.reference_c = model.options.reference_c.value_or(std::numeric_limits<double>::quiet_NaN());
    const bool referenced = !std::isnan(axis.reference_c);
    for (const drift::SubModel& sub : model.sub_models) {
      Sub s;
      s.name = sub.name;
      if (!sub.thermal) {
        s.zero = true;
        axis.subs.push_back(std::move(s));
        continue;
      }
      const drift::ThermalRegression& t = *sub.thermal;
      plan.rate_hz = t.rate_hz;
      Eigen::Index k = 0;
      s.intercept = t.coefficients[k++];
      for (int c = 0; c < t.channels(); ++c) {
        const auto cu = static_cast<size_t>(c);
        if (t.static_power[cu] == 0) continue;
        Static st{global[cu], t.centre_c[cu], t.scale_k[cu], t.static_min[cu], t.static_max[cu], {}};
        for (int p = 1; p <= t.static_power[cu]; ++p) st.powers.push_back(t.coefficients[k++]);
        s.statics.push_back(std::move(st));
      }
      const double dt_s = 1.0 / t.rate_hz;  // as ThermalRegression::Regressors
      for (const drift::ThermalState& ts : t.states) {
        const auto cu = static_cast<size_t>(ts.channel);
        const int channel = global[cu];
        auto chain = std::find_if(plan.chains.begin(), plan.chains.end(), [&](const Chain& c) {
          return c.channel == channel && c.tau_s == ts.tau_s;
        });
        if (chain == plan.chains.end()) {
          plan.chains.push_back(
              {channel, ts.tau_s, drift::FirstOrderLagGain(ts.tau_s, dt_s), 0, 0});
          chain = plan.chains.end() - 1;
        }
        chain->stages = std::max(chain->stages, t.order);
        State state;
        state.chain = static_cast<int>(chain - plan.chains.begin());
        state.order = t.order;
        state.centre_c = t.centre_c[cu];
        state.scale_k = t.scale_k[cu];
        state.level_min = ts.level_min;
        state.level_max = ts.level_max;
        for (int p = 1; p <= t.max_power; ++p) state.powers.push_back(t.coefficients[k++]);
        state.rate = t.coefficients[k++];
        state.rate_min = ts.rate_min;
        state.rate_max = ts.rate_max;
        s.states.push_back(std::move(state));
        ++plan.states;
      }
      if (t.has_hysteresis()) {
        s.hysteresis = {t.hysteresis_state, plan.plays++, t.hysteresis_width_k, t.coefficients[k++]};
      }
      if (referenced) {
        // The library's own estimate of a record in equilibrium at the reference.
        s.reference_estimate =
            t.Estimate(Eigen::MatrixXd::Constant(1, t.channels(), axis.reference_c))[0];
      }
      axis.subs.push_back(std::move(s));
    }
    plan.axes.push_back(std::move(axis));
  }
  for (Chain& c : plan.chains) {
    c.first = plan.lag_stages;
    plan.lag_stages += c.stages;
  }
  if (plan.rate_hz == 0.0) plan.rate_hz = axes[0].model.options.features.rate_hz;
  return plan;
}

// ---------------------------------------------------------------------------------------------
// C text

// Text safe inside a /* */ comment: printable ASCII, no "*/", no trigraph.
std::string CommentText(std::string_view text) {
  std::string out;
  for (char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    out += (u >= 0x20 && u < 0x7f) ? ch : '_';
    if (out.size() >= 2 && out.compare(out.size() - 2, 2, "*/") == 0)
      out.insert(out.size() - 1, " ");
    if (out.size() >= 2 && out.compare(out.size() - 2, 2, "??") == 0)
      out.insert(out.size() - 1, " ");
  }
  return out;
}

// A C string literal: quotes, backslashes and '?' (trigraphs) escaped, other bytes outside
// printable ASCII as three-digit octal escapes.
std::string CString(std::string_view text) {
  std::string out = "\"";
  for (char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\' || ch == '?') {
      out += '\\';
      out += ch;
    } else if (u >= 0x20 && u < 0x7f) {
      out += ch;
    } else {
      out += fmt::format("\\{:03o}", u);
    }
  }
  return out + "\"";
}

class CWriter {
 public:
  CWriter(const Plan& plan, const ExportOptions& options)
      : plan_(plan), single_(options.single_precision), p_(options.prefix) {
    for (char ch : p_) P_ += static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    real_ = p_ + "_real";
  }

  std::string Render() {
    Header();
    Definitions();
    Helpers();
    Init();
    Step();
    out_ += fmt::format("\n#endif /* {}_H */\n", P_);
    return std::move(out_);
  }

 private:
  // Shortest decimal that reads back to the constant in the header's precision.
  std::string Literal(double v) const {
    if (single_ && !(std::abs(v) <= std::numeric_limits<float>::max())) {
      throw UsageError(fmt::format("constant {} is beyond float's range: export in double precision",
                                   FormatValue(v)));
    }
    std::string s = single_ ? fmt::format("{}", static_cast<float>(v)) : fmt::format("{}", v);
    if (s.find_first_of(".e") == std::string::npos) s += ".0";
    return single_ ? s + "f" : s;
  }

  std::string StateName(const State& s) const {
    const Chain& c = plan_.chains[static_cast<size_t>(s.chain)];
    return fmt::format("L{}({}; {:.4g} s)", s.order, plan_.channels[static_cast<size_t>(c.channel)],
                       c.tau_s);
  }

  void Header() {
    const size_t n = plan_.axes.size();
    out_ += fmt::format(
        "/* {}.h: thermal drift compensation of {} gyro ax{}, generated by gyrodrift {} export.\n"
        " *\n",
        p_, n, n == 1 ? "is" : "es", kVersion);
    for (size_t a = 0; a < n; ++a) {
      const Axis& axis = plan_.axes[a];
      out_ +=
          fmt::format(" * Axis {}: {}, fitted on {}:\n *   {};\n *   {}.\n", a,
                      CommentText(axis.name), CommentText(axis.source), CommentText(axis.summary),
                      std::isnan(axis.reference_c)
                          ? std::string("the fitted intercept (repeatable bias) kept")
                          : fmt::format("referenced to equilibrium at {} degC", axis.reference_c));
    }
    for (size_t c = 0; c < plan_.channels.size(); ++c) {
      out_ +=
          fmt::format(" * Temperature channel {}: {} (degC).\n", c, CommentText(plan_.channels[c]));
    }
    out_ += fmt::format(
        " * Sample rate: {} Hz. The model is tied to it: its lag gains are for this period, and\n"
        " * stepping at another rate silently changes every time constant.\n"
        " *\n"
        " * Use:\n"
        " *   {p}_state s;\n"
        " *   {p}_init(&s, t);        once, with the first sample's temperature(s)\n"
        " *   {p}_step(&s, t, drift); at every sample, the first one included\n"
        " *   compensated[a] = measured[a] - drift[a]   (units of the axis' target column)\n"
        " * t: {P}_N_CHANNELS temperatures in degC; drift: {P}_N_AXES estimates.\n"
        " * drift[a] is what 'gyrodrift compensate' writes as drift_est, the same model:\n"
        " * thermal states are cascaded first-order lags started in equilibrium at the first\n"
        " * sample; a state's standardised level z has its powers continued along their tangent\n"
        " * beyond the calibration's range, as are the static powers of a channel; its rate is\n"
        " * (input - output of its last lag) / tau, K/s, held within the rates the calibration\n"
        " * showed; a hysteresis term is the play operator (backlash) of half-width w on a state's\n"
        " * level, (level - play) / w, started with no direction. The lags run on each stage's\n"
        " * deviation u below its input, the same recursion rewritten so that a slow lag's small\n"
        " * increments do not vanish against T in float.\n"
        " * See docs/firmware.md.\n"
        " * Arithmetic: {}. No allocation, no libm (the lag gains 1 - exp(-dt/tau) are\n"
        " * precomputed literals), no other header: C99, also valid C++.\n"
        " */\n"
        "#ifndef {P}_H\n#define {P}_H\n\n",
        plan_.rate_hz, single_ ? "float" : "double", fmt::arg("p", p_), fmt::arg("P", P_));
  }

  void Definitions() {
    out_ += fmt::format("#define {}_N_AXES {}\n", P_, plan_.axes.size());
    out_ += fmt::format("#define {}_N_CHANNELS {}\n", P_, plan_.channels.size());
    out_ += fmt::format("#define {}_N_LAGS {}\n", P_, plan_.lag_stages);
    if (plan_.plays > 0) out_ += fmt::format("#define {}_N_PLAYS {}\n", P_, plan_.plays);
    out_ += fmt::format("#define {}_RATE_HZ {}\n", P_, Literal(plan_.rate_hz));
    for (size_t a = 0; a < plan_.axes.size(); ++a) {
      out_ += fmt::format("#define {}_AXIS_{}_NAME {}\n", P_, a, CString(plan_.axes[a].name));
    }
    for (size_t c = 0; c < plan_.channels.size(); ++c) {
      out_ += fmt::format("#define {}_CHANNEL_{}_NAME {}\n", P_, c, CString(plan_.channels[c]));
    }
    out_ += fmt::format("\ntypedef {} {};\n\n", single_ ? "float" : "double", real_);
    out_ += fmt::format(
        "typedef struct {{\n"
        "  {r} temperature_c[{P}_N_CHANNELS]; /* the previous sample's, degC */\n",
        fmt::arg("r", real_), fmt::arg("P", P_));
    if (plan_.lag_stages > 0) {
      out_ += fmt::format("  {} lag[{}_N_LAGS]; /* each lag stage's input minus its output, K */\n",
                          real_, P_);
    }
    if (plan_.plays > 0) {
      out_ += fmt::format(
          "  {} play[{}_N_PLAYS]; /* each hysteresis term's play output less its centre, K */\n",
          real_, P_);
    }
    out_ += fmt::format("}} {}_state;\n", p_);
  }

  void Helpers() {
    int max_power = 1;
    for (const Axis& a : plan_.axes) {
      for (const Sub& s : a.subs) {
        for (const State& st : s.states) {
          max_power = std::max(max_power, static_cast<int>(st.powers.size()));
        }
        for (const Static& st : s.statics) {
          max_power = std::max(max_power, static_cast<int>(st.powers.size()));
        }
      }
    }
    // The library's pow(edge, p) + p pow(edge, p - 1) (z - edge), edge = z clamped.
    if (max_power >= 2) {
      out_ += fmt::format(
          "\n/* z^2 inside [lo, hi], continued along its tangent beyond. */\n"
          "static inline {r} {p}_power2({r} z, {r} lo, {r} hi) {{\n"
          "  const {r} edge = z < lo ? lo : (hi < z ? hi : z);\n"
          "  return edge * edge + {two} * edge * (z - edge);\n"
          "}}\n",
          fmt::arg("r", real_), fmt::arg("p", p_), fmt::arg("two", Literal(2.0)));
    }
    if (max_power >= 3) {
      out_ += fmt::format(
          "\n/* z^3 inside [lo, hi], continued along its tangent beyond. */\n"
          "static inline {r} {p}_power3({r} z, {r} lo, {r} hi) {{\n"
          "  const {r} edge = z < lo ? lo : (hi < z ? hi : z);\n"
          "  return edge * edge * edge + {three} * (edge * edge) * (z - edge);\n"
          "}}\n",
          fmt::arg("r", real_), fmt::arg("p", p_), fmt::arg("three", Literal(3.0)));
    }
  }

  void Init() {
    out_ += fmt::format(
        "\n/* Every lag in equilibrium at the first sample's temperatures. */\n"
        "static inline void {p}_init({p}_state *s, const {r} temperature_c[{P}_N_CHANNELS]) {{\n"
        "  int i;\n"
        "  for (i = 0; i < {P}_N_CHANNELS; ++i) s->temperature_c[i] = temperature_c[i];\n",
        fmt::arg("p", p_), fmt::arg("r", real_), fmt::arg("P", P_));
    if (plan_.lag_stages > 0) {
      out_ += fmt::format("  for (i = 0; i < {}_N_LAGS; ++i) s->lag[i] = {};\n", P_, Literal(0.0));
    }
    for (const Axis& a : plan_.axes) {
      for (const Sub& sub : a.subs) {
        if (sub.hysteresis.state < 0) continue;
        const State& st = sub.states[static_cast<size_t>(sub.hysteresis.state)];
        const Chain& chain = plan_.chains[static_cast<size_t>(st.chain)];
        out_ += fmt::format("  s->play[{}] = temperature_c[{}] - {};\n", sub.hysteresis.slot,
                            chain.channel, Literal(st.centre_c));
      }
    }
    out_ += "}\n";
  }

  void Step() {
    out_ += fmt::format(
        "\n/* One sample: the lags advance to temperature_c (degC), then drift[a] is axis a's\n"
        " * estimate (units of its target column). */\n"
        "static inline void {p}_step({p}_state *s, const {r} temperature_c[{P}_N_CHANNELS],\n"
        "{indent}{r} drift[{P}_N_AXES]) {{\n",
        fmt::arg("p", p_), fmt::arg("r", real_), fmt::arg("P", P_),
        fmt::arg("indent", std::string(p_.size() + 25, ' ')));
    bool any_z = false, any_estimate = false, any_held = false;
    for (const Axis& a : plan_.axes) {
      for (const Sub& s : a.subs) {
        any_estimate = any_estimate || !s.zero;
        any_z = any_z || !s.states.empty() || !s.statics.empty();
        for (const State& st : s.states) any_held = any_held || std::isfinite(st.rate_min);
      }
    }
    if (!plan_.chains.empty()) out_ += fmt::format("  {} d, w;\n", real_);
    if (any_held) out_ += fmt::format("  {} r;\n", real_);
    if (plan_.plays > 0) out_ += fmt::format("  {} v;\n", real_);
    if (any_z) out_ += fmt::format("  {} z;\n", real_);
    if (any_estimate) out_ += fmt::format("  {} e;\n", real_);
    // Lags: stage k of a chain sees its input move by d; its deviation u = input - output becomes
    // (u + d)(1 - g) and its output moves by g (u + d), the next stage's d.
    for (size_t c = 0; c < plan_.chains.size(); ++c) {
      const Chain& chain = plan_.chains[c];
      out_ += fmt::format("  /* lags of {}, tau {:.4g} s, gain 1 - exp(-{} s / tau) */\n",
                          CommentText(plan_.channels[static_cast<size_t>(chain.channel)]),
                          chain.tau_s, 1.0 / plan_.rate_hz);
      out_ += fmt::format("  d = temperature_c[{0}] - s->temperature_c[{0}];\n", chain.channel);
      for (int k = 0; k < chain.stages; ++k) {
        const int i = chain.first + k;
        out_ += fmt::format("  w = s->lag[{0}] + d;\n  d = {1} * w;\n  s->lag[{0}] = w - d;\n", i,
                            Literal(chain.gain));
      }
    }
    for (size_t a = 0; a < plan_.axes.size(); ++a) {
      const Axis& axis = plan_.axes[a];
      std::string names;
      for (const Sub& sub : axis.subs) names += (names.empty() ? "" : ", ") + sub.name;
      out_ += fmt::format("  /* axis {}: {}, the sum of sub-model{} {} */\n  drift[{}] = {};\n", a,
                          CommentText(axis.name), axis.subs.size() == 1 ? "" : "s",
                          CommentText(names), a, Literal(0.0));
      for (const Sub& sub : axis.subs) {
        if (sub.zero) {
          out_ += fmt::format("  /* sub-model {}: zero */\n", CommentText(sub.name));
          continue;
        }
        SubModel(a, sub, !std::isnan(axis.reference_c));
      }
    }
    out_ += fmt::format(
        "  {{\n    int i;\n    for (i = 0; i < {}_N_CHANNELS; ++i) s->temperature_c[i] = "
        "temperature_c[i];\n  }}\n",
        P_);
    out_ += "}\n";
  }

  // The level of a state less its centre, K: the input less the deviations of the stages up to
  // the state's order.
  std::string LevelLessCentre(const State& st) const {
    const Chain& chain = plan_.chains[static_cast<size_t>(st.chain)];
    std::string deviations;
    for (int k = 0; k < st.order; ++k) {
      deviations += fmt::format("{}s->lag[{}]", k ? " + " : "", chain.first + k);
    }
    return fmt::format("(temperature_c[{}] - {}) - ({})", chain.channel, Literal(st.centre_c),
                       deviations);
  }

  // e += each power of z (the first plain, the others along their tangent beyond [lo, hi]).
  void Powers(const std::vector<double>& powers, double lo, double hi) {
    out_ += fmt::format("  e += {} * z;\n", Literal(powers[0]));
    for (size_t p = 2; p <= powers.size(); ++p) {
      out_ += fmt::format("  e += {} * {}_power{}(z, {}, {});\n", Literal(powers[p - 1]), p_, p,
                          Literal(lo), Literal(hi));
    }
  }

  // One sub-model's estimate in the library's order: the regressors' columns (intercept, static
  // powers, per state its powers and rate, then the hysteresis term) times their coefficients,
  // summed into the axis, less its estimate in equilibrium at the reference temperature.
  void SubModel(size_t a, const Sub& sub, bool referenced) {
    out_ += fmt::format("  /* sub-model {} */\n  e = {};\n", CommentText(sub.name),
                        Literal(sub.intercept));
    for (const Static& st : sub.statics) {
      out_ += fmt::format("  /* {} */\n  z = (temperature_c[{}] - {}) / {};\n",
                          CommentText(plan_.channels[static_cast<size_t>(st.channel)]), st.channel,
                          Literal(st.centre_c), Literal(st.scale_k));
      Powers(st.powers, st.level_min, st.level_max);
    }
    for (const State& st : sub.states) {
      const Chain& chain = plan_.chains[static_cast<size_t>(st.chain)];
      out_ += fmt::format("  /* {} */\n", CommentText(StateName(st)));
      out_ += fmt::format("  z = ({}) / {};\n", LevelLessCentre(st), Literal(st.scale_k));
      Powers(st.powers, st.level_min, st.level_max);
      if (std::isfinite(st.rate_min)) {
        // The rate held within the calibration's, as the library holds it.
        out_ += fmt::format(
            "  r = s->lag[{i}] / {tau};\n  r = r < {lo} ? {lo} : ({hi} < r ? {hi} : r);\n"
            "  e += {c} * r;\n",
            fmt::arg("i", chain.first + st.order - 1), fmt::arg("tau", Literal(chain.tau_s)),
            fmt::arg("lo", Literal(st.rate_min)), fmt::arg("hi", Literal(st.rate_max)),
            fmt::arg("c", Literal(st.rate)));
      } else {
        out_ += fmt::format("  e += {} * (s->lag[{}] / {});\n", Literal(st.rate),
                            chain.first + st.order - 1, Literal(chain.tau_s));
      }
    }
    if (sub.hysteresis.state >= 0) {
      // The play p follows the level v only where v is more than w away: p is held or set to
      // v -+ w, so no rounding accumulates.
      const Hysteresis& h = sub.hysteresis;
      const State& st = sub.states[static_cast<size_t>(h.state)];
      const std::string w = Literal(h.width_k);
      out_ += fmt::format("  /* hysteresis: play of {} K on {} */\n", h.width_k,
                          CommentText(StateName(st)));
      out_ += fmt::format(
          "  v = {level};\n"
          "  if (s->play[{i}] < v - {w}) s->play[{i}] = v - {w};\n"
          "  if (v + {w} < s->play[{i}]) s->play[{i}] = v + {w};\n"
          "  e += {c} * ((v - s->play[{i}]) / {w});\n",
          fmt::arg("level", LevelLessCentre(st)), fmt::arg("i", h.slot), fmt::arg("w", w),
          fmt::arg("c", Literal(h.coefficient)));
    }
    out_ += fmt::format("  drift[{}] += e;\n", a);
    if (referenced) {
      out_ += fmt::format("  drift[{}] -= {}; /* its estimate in equilibrium at the reference */\n",
                          a, Literal(sub.reference_estimate));
    }
  }

  const Plan& plan_;
  bool single_;
  std::string p_, P_, real_;
  std::string out_;
};

}  // namespace

std::string_view ToString(ExportFormat format) { return internal::EnumName(format, kFormats); }

ExportFormat ExportFormatFromString(std::string_view name) {
  return internal::EnumFromName(name, "format", kFormats);
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

void RequireExportable(const std::vector<LoadedModel>& axes) {
  if (axes.empty()) throw UsageError("export needs at least one model (one per gyro axis)");
  double rate_hz = 0.0;
  for (size_t a = 0; a < axes.size(); ++a) {
    const drift::DriftModel& model = axes[a].model;
    const std::string axis = AxisLabel(a, axes[a]);
    if (model.options.mode != drift::Mode::kCompensate) {
      throw UsageError(axis +
                       " is a predict-mode model: firmware runs compensate-mode models, which "
                       "need only temperature (fit in mode compensate)");
    }
    for (const drift::SubModel& sub : model.sub_models) {
      if (sub.learner) {
        throw UsageError(fmt::format(
            "{}: sub-model '{}' is a {} learner on thermal features, not an identified thermal "
            "model: export takes method thermal, ms-elm or emd-elm",
            axis, sub.name, drift::ToString(model.options.method)));
      }
      if (!sub.thermal) continue;
      if (sub.thermal->correction) {
        throw UsageError(fmt::format(
            "{}: sub-model '{}' has a nonlinear correction (linear_compensation = false), whose "
            "sigmoid units need exp at every sample: refit linear to export",
            axis, sub.name));
      }
      if (rate_hz != 0.0 && sub.thermal->rate_hz != rate_hz) {
        throw UsageError(fmt::format(
            "{} was fitted at {} Hz, an earlier axis at {} Hz: one step function serves every "
            "axis, so their models need one sample rate",
            axis, sub.thermal->rate_hz, rate_hz));
      }
      rate_hz = sub.thermal->rate_hz;
    }
    const size_t names = SplitNames(axes[a].info.temperature_column).size();
    if (axes[a].info.temperature_column.empty() ||
        static_cast<int>(names) != model.temperature_channels()) {
      throw DataError(fmt::format(
          "{}: the model takes {} temperature channel(s), its file names {}", axis,
          model.temperature_channels(), axes[a].info.temperature_column.empty() ? 0 : names));
    }
  }
}

std::string RenderFirmwareC(const std::vector<LoadedModel>& axes, const ExportOptions& options) {
  options.Validate();
  const Plan plan = MakePlan(axes);
  return CWriter(plan, options).Render();
}

std::string RenderCoefficientsJson(const std::vector<LoadedModel>& axes,
                                   const ExportOptions& options) {
  options.Validate();
  const Plan plan = MakePlan(axes);
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
                          {"rate_max", finite(st.rate_max)}});
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

std::string RenderExport(const std::vector<LoadedModel>& axes, const ExportOptions& options) {
  return options.format == ExportFormat::kC ? RenderFirmwareC(axes, options)
                                            : RenderCoefficientsJson(axes, options);
}

ExportSummary SummariseExport(const std::vector<LoadedModel>& axes) {
  const Plan plan = MakePlan(axes);
  return {static_cast<int>(plan.axes.size()), static_cast<int>(plan.channels.size()), plan.states,
          plan.lag_stages, plan.rate_hz};
}

std::string ExportSummary::Line() const {
  return fmt::format(
      "{} ax{}, {} temperature channel{}, {} thermal state{} in {} lag stage{}, {} Hz", axes,
      axes == 1 ? "is" : "es", channels, channels == 1 ? "" : "s", states, states == 1 ? "" : "s",
      lag_stages, lag_stages == 1 ? "" : "s", rate_hz);
}

}  // namespace gyrodrift::io
