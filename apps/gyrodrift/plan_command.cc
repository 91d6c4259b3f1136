// gyrodrift plan: a chamber programme that identifies what `fit --mode compensate` needs.
#include <fmt/core.h>

#include "cli_util.h"
#include "command.h"
#include "gyrodrift/drift/calibration_plan.h"
#include "gyrodrift/io/csv.h"

namespace gyrodrift::cli {
namespace {

struct PlanArgs {
  drift::PlanSettings settings;
  std::string output;
  bool quiet = false;
};

void Run(const PlanArgs& a) {
  const drift::CalibrationPlan plan = drift::PlanCalibration(a.settings);
  const auto n = static_cast<Eigen::Index>(plan.time_s.size());
  io::WriteCsv(a.output, {{"time_s", Eigen::Map<const Eigen::VectorXd>(plan.time_s.data(), n)},
                          {"temperature_c",
                           Eigen::Map<const Eigen::VectorXd>(plan.temperature_c.data(), n)}});
  for (const std::string& w : plan.warnings) fmt::print(stderr, "warning: {}\n", w);
  if (a.quiet) return;
  fmt::print("{}", plan.Explanation());
  fmt::print("wrote {} (set points; try it: gyrodrift simulate --profile {} -o run.csv)\n",
             a.output, a.output);
}

const RegisterCommand kRegister("plan", 8, [](CLI::App& app) {
  auto a = std::make_shared<PlanArgs>();
  CLI::App* cmd = app.add_subcommand(
      "plan", "Write a thermal-chamber programme that identifies a compensate-mode model.");
  BindSetting(cmd->add_option("--hours", a->settings.hours, "length of the programme, h")
                  ->capture_default_str(),
              {"hours"});
  BindSetting(cmd->add_option("--min", a->settings.min_c, "bottom of the range, degC")
                  ->capture_default_str(),
              {"min_c"});
  BindSetting(cmd->add_option("--max", a->settings.max_c, "top of the range, degC")
                  ->capture_default_str(),
              {"max_c"});
  BindSetting(cmd->add_option("--rate", a->settings.rate_k_per_min,
                              "the fast ramp rate, K/min, in [0.5, 2] (the slow one is half); 0 = "
                              "auto: 1, or faster where the dwells would be shorter than "
                              "--dwell-min")
                  ->capture_default_str(),
              {"rate_k_per_min"});
  BindSetting(cmd->add_option("--dwell-min", a->settings.shortest_dwell_min,
                              "shortest dwell, minutes")
                  ->capture_default_str(),
              {"shortest_dwell_min"});
  cmd->add_option("-o,--output", a->output, "CSV of set points: time_s, temperature_c")
      ->required();
  cmd->add_flag("-q,--quiet", a->quiet, "print nothing on success");
  cmd->footer(
      "Example:\n"
      "  gyrodrift plan --hours 8 --min -20 --max 60 -o plan.csv\n"
      "  gyrodrift simulate --profile plan.csv -o run.csv      # try it before booking the chamber\n"
      "  gyrodrift fit run.csv -t rate_dph -T temperature_c --mode compensate -o model.json\n"
      "The programme: ramps both ways at two rates, dwells at three levels (docs/drift.md 4.9).");
  cmd->callback([a] { Run(*a); });
});

}  // namespace
}  // namespace gyrodrift::cli
