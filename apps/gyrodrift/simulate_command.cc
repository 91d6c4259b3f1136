// gyrodrift simulate: a thermal-chamber FOG log with the drift truth kept apart.
#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/io/csv.h"
#include "gyrodrift/io/files.h"
#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/tasks/simulate_task.h"

namespace gyrodrift::cli {
namespace {

namespace sim = gyrodrift::simulation;

struct SimulateArgs {
  std::string preset = "navigation";
  std::string profile = "chamber";
  std::string duration;  // empty: the programme's own length (8 h for the built-in ones)
  double rate_hz = simulation::SimulationOptions{}.rate_hz;
  std::uint64_t seed = simulation::SimulationOptions{}.seed;
  std::string winding;              // empty: the preset's
  double asymmetry = 0.0;
  CLI::Option* asymmetry_option = nullptr;  // not given: the preset's
  double input_rate_dph = simulation::SimulationOptions{}.input_rate_dph;
  bool no_noise = false;
  std::string output;
  bool quiet = false;
};

nlohmann::json ProgrammeJson(const sim::TemperatureProgramme& p) {
  nlohmann::json j = {{"name", p.name()}, {"summary", p.Summary()}};
  if (p.kind() == sim::TemperatureProgramme::Kind::kSine) {
    j["kind"] = "sine";
    j["mean_c"] = p.sine_mean_c();
    j["amplitude_c"] = p.sine_amplitude_c();
    j["period_s"] = p.sine_period_s();
    j["phase_rad"] = p.sine_phase_rad();
  } else {
    j["kind"] = "piecewise-linear";
    j["breakpoint_time_s"] = p.breakpoint_time_s();
    j["breakpoint_temperature_c"] = p.breakpoint_temperature_c();
  }
  return j;
}

nlohmann::json ParametersJson(const sim::FogParameters& p) {
  const auto& c = p.coil;
  const auto& t = p.thermal;
  const auto& s = p.stress;
  const auto& n = p.noise;
  const auto& sensor = p.sensor;
  return {
      {"preset", sim::ToString(p.preset)},
      {"coil",
       {{"fibre_length_m", c.fibre_length_m},
        {"coil_diameter_m", c.coil_diameter_m},
        {"wavelength_m", c.wavelength_m},
        {"refractive_index", c.refractive_index},
        {"dn_dt_per_k", c.dn_dt_per_k},
        {"expansion_per_k", c.expansion_per_k},
        {"layers", c.layers},
        {"layer_pitch_m", c.layer_pitch_m},
        {"inner_radius_m", c.inner_radius_m()},
        {"outer_radius_m", c.outer_radius_m()},
        {"winding", sim::ToString(c.winding)},
        {"winding_asymmetry", c.winding_asymmetry},
        {"sagnac_scale_factor_s", c.SagnacScaleFactorS()}}},
      {"thermal",
       {{"diffusivity_m2_s", t.diffusivity_m2_s},
        {"conductivity_w_mk", t.conductivity_w_mk},
        {"outer_conductance_w_m2k", t.outer_conductance_w_m2k},
        {"inner_conductance_w_m2k", t.inner_conductance_w_m2k},
        {"case_time_constant_s", t.case_time_constant_s},
        {"scheme", sim::ToString(t.scheme)},
        {"max_step_s", t.max_step_s}}},
      {"stress",
       {{"core_modulus_pa", s.core_modulus_pa},
        {"poisson_ratio", s.poisson_ratio},
        {"p11", s.p11},
        {"p12", s.p12},
        {"coating_modulus_pa", s.coating_modulus_pa},
        {"coating_expansion_per_k", s.coating_expansion_per_k},
        {"nonreciprocity", s.nonreciprocity},
        {"coefficient_dph_per_k", p.StressCoefficientDphPerK()}}},
      {"bias",
       {{"reference_c", p.bias.reference_c}, {"coefficients_dph", p.bias.coefficients_dph}}},
      {"noise",
       {{"quantization_urad", n.quantization_urad},
        {"arw_dpsh", n.arw_dpsh},
        {"bias_instability_dph", n.bias_instability_dph},
        {"rrw_dphpsh", n.rrw_dphpsh},
        {"rate_ramp_dphph", n.rate_ramp_dphph},
        {"bias_tau_min_s", n.bias_tau_min_s},
        {"bias_tau_max_s", n.bias_tau_max_s},
        {"bias_processes_per_decade", n.bias_processes_per_decade}}},
      {"temperature_sensor",
       {{"time_constant_s", sensor.time_constant_s},
        {"noise_k", sensor.noise_k},
        {"resolution_k", sensor.resolution_k},
        {"offset_k", sensor.offset_k}}},
  };
}

void Run(const SimulateArgs& a) {
  // A --profile FILE is an input; a builtin name is not, even where a file has that name (the
  // name wins: tasks::LoadProgramme).
  const std::vector<std::string> builtin = sim::BuiltinProgrammeNames();
  const bool named = std::find(builtin.begin(), builtin.end(), a.profile) != builtin.end();
  RequireOutputsAreNotInputs(
      named ? std::vector<std::string>{} : std::vector<std::string>{a.profile},
      {a.output, SidecarPath(a.output)});
  sim::FogParameters params = sim::PresetParameters(sim::PresetFromString(a.preset));
  if (!a.winding.empty()) params.coil.winding = sim::WindingPatternFromString(a.winding);
  if (a.asymmetry_option->count() > 0) params.coil.winding_asymmetry = a.asymmetry;
  params.Validate();
  sim::SimulationOptions o;
  o.rate_hz = a.rate_hz;
  o.seed = a.seed;
  o.input_rate_dph = a.input_rate_dph;
  o.include_noise = !a.no_noise;
  // Check what can be checked before the profile file is read.
  if (!a.duration.empty()) o.duration_s = ParseDuration(a.duration);
  RequireInRange("--rate-hz", a.rate_hz, 1e-3, 1e4);
  const sim::TemperatureProgramme programme = tasks::LoadProgramme(a.profile, "--profile");
  if (a.duration.empty()) o.duration_s = programme.DefaultSimulationDuration();
  const sim::SimulationResult r = sim::Simulate(programme, params, o);

  const std::vector<io::CsvColumn> columns = {
      {"time_s", r.time_s},       {"rate_dph", r.rate_dph},   {"temperature_c", r.temperature_c},
      {"drift_dph", r.drift_dph}, {"shupe_dph", r.shupe_dph}, {"stress_dph", r.stress_dph},
      {"bias_dph", r.bias_dph},   {"noise_dph", r.noise_dph}};
  nlohmann::json sidecar = SidecarHeader("simulate");
  sidecar["options"] = {
      {"preset", a.preset},      {"profile", a.profile}, {"duration_s", o.duration_s},
      {"rate_hz", o.rate_hz},    {"seed", o.seed},       {"input_rate_dph", o.input_rate_dph},
      {"noise", o.include_noise}};
  sidecar["seed"] = o.seed;
  sidecar["programme"] = ProgrammeJson(programme);
  sidecar["parameters"] = ParametersJson(params);
  sidecar["columns"] = {
      {"time_s", "end of the averaging interval, s"},
      {"rate_dph", "logged gyro rate = drift + noise + input rate, deg/h"},
      {"temperature_c", "case temperature sensor reading (lag, noise, resolution), degC"},
      {"drift_dph", "true thermal drift = shupe + stress + bias, deg/h"},
      {"shupe_dph", "Shupe (temperature-rate) term, deg/h"},
      {"stress_dph", "coating thermal-stress term (eq. 4), deg/h"},
      {"bias_dph", "static temperature-dependent bias, deg/h"},
      {"noise_dph", "sensor noise (Q, N, B, K, R), deg/h"}};
  sidecar["report"] = {{"summary", r.Summary()},
                       {"samples", r.samples},
                       {"substeps_per_sample", r.substeps_per_sample},
                       {"conduction_step_s", r.conduction_step_s},
                       {"coil_lag_s", r.coil_lag_s},
                       {"stress_coefficient_dph_per_k", r.stress_coefficient_dph_per_k},
                       {"shupe_scale_dph_per_km2s", r.shupe_scale_dph_per_km2s},
                       {"bias_bank_ripple", r.bias_bank_ripple},
                       {"max_abs_shupe_dph", r.max_abs_shupe_dph},
                       {"rms_drift_dph", r.rms_drift_dph},
                       {"rms_noise_dph", r.rms_noise_dph}};
  io::WriteFilesAtomically(
      {{a.output, io::RenderCsv(columns)}, {SidecarPath(a.output), sidecar.dump(2) + "\n"}});
  if (!a.quiet) fmt::print("{}\nwrote {} and {}\n", r.Summary(), a.output, SidecarPath(a.output));
}

const RegisterCommand kRegister("simulate", 10, [](CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Simulate a FOG in a thermal chamber: logged rate, temperature, and the truth.");
  cmd->footer(
      "Example:\n"
      "  gyrodrift simulate --preset navigation --profile chamber --duration 8h --seed 7 -o "
      "train.csv\n"
      "  gyrodrift simulate --profile chamber-b --seed 8 -o test.csv   # a different history\n"
      "writes train.csv with columns\n"
      "  time_s,rate_dph,temperature_c,drift_dph,shupe_dph,stress_dph,bias_dph,noise_dph\n"
      "(rate_dph and temperature_c are what a user logs; the rest is the truth:\n"
      "drift = shupe + stress + bias) and train.csv.json (every parameter and the seed).\n"
      "Profiles: chamber (20 -> 60 -> -20 -> 20 degC at 1 K/min, 8 h), chamber-b (25 -> 45 -> 0\n"
      "-> 35 -> 15 degC, 8 h), sine (20 +- 20 degC, 2 h period), or a CSV file with columns\n"
      "time_s,temperature_c. Durations: 30s, 10min, 8h or plain seconds. Same seed, same bytes.\n"
      "Physics, defaults and checks: docs/simulation.md.");
  cmd->add_option("-o,--output", args->output, "output CSV (a .json sidecar is written beside it)")
      ->required();
  BindSetting(
      cmd->add_option("--preset", args->preset, "navigation|tactical")->capture_default_str(),
      {"preset"});
  BindSetting(cmd->add_option("--profile", args->profile, "chamber|chamber-b|sine|FILE.csv")
                  ->capture_default_str(),
              {"profile"});
  BindSetting(cmd->add_option("--duration", args->duration,
                              "length, e.g. 30s, 10min, 8h, 3600 (default: the profile's, 8 h)"),
              {"duration_s"});
  BindSetting(cmd->add_option("--rate-hz", args->rate_hz, "output rate, Hz")->capture_default_str(),
              {"rate_hz"});
  cmd->add_option("--seed", args->seed, "seed of the noise and sensor streams")
      ->check(kSeed)
      ->capture_default_str();
  BindSetting(
      cmd->add_option("--winding", args->winding,
                      "override the preset: quadrupole|dipole|octupole|conventional|symmetric"),
      {"winding"});
  args->asymmetry_option =
      BindSetting(cmd->add_option("--asymmetry", args->asymmetry,
                                  "override the preset's winding asymmetry (fraction, |a| < 0.5)"),
                  {"coil.winding_asymmetry"});
  BindSetting(
      cmd->add_option("--input-rate-dph", args->input_rate_dph,
                      "true rate on the sensitive axis, e.g. an Earth-rate component, deg/h")
          ->capture_default_str(),
      {"input_rate_dph"});
  cmd->add_flag("--no-noise", args->no_noise, "noise-free rate and an ideal temperature reading");
  cmd->add_flag("--quiet,-q", args->quiet, "print nothing on success");
  cmd->callback([args] { Run(*args); });
});

}  // namespace
}  // namespace gyrodrift::cli
