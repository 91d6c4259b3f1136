// The study tests' user log: 40 minutes of the simulator's chamber run (rate_dph and the case
// sensor) at 1 Hz, as a user's CSV would give it.
#pragma once

#include "gyrodrift/simulation/fog_simulator.h"
#include "gyrodrift/simulation/temperature_programme.h"
#include "gyrodrift/study/study.h"

namespace gyrodrift::study {

inline StudyLog ChamberLog() {
  namespace sim = gyrodrift::simulation;
  sim::SimulationOptions so;
  so.duration_s = 2400.0;
  so.seed = 5;
  const sim::SimulationResult run = sim::Simulate(
      sim::BuiltinProgramme("chamber"), sim::PresetParameters(sim::Preset::kNavigation), so);
  StudyLog log;
  log.source = "chamber.csv";
  log.target_name = "rate_dph";
  log.temperature_name = "temperature_c";
  log.output = run.rate_dph;
  log.temperature = run.temperature_c;
  log.rate_hz = 1.0;
  log.rate_source = "given";
  return log;
}

}  // namespace gyrodrift::study
