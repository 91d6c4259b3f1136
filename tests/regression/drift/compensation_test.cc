// Issue 4's compensation claim on the simulator, end to end: a model fitted on one chamber
// programme (builtin "chamber", seed 1) compensates a gyro run through another ("chamber-b",
// seed 2) it never saw. Navigation preset, 8 h at 1 Hz, scored against the simulator's true
// thermal drift (drift_dph), i.e. the drift the compensation is meant to remove.
//
// Measured (docs/drift.md, section 4.5): the identified thermal model (the compensate-mode
// default) removes 96.0 % of the true drift's RMS referenced to 20 degC, the simulator's
// convention (its truth is zero in equilibrium at 20 degC and its turn-on bias is drawn anew
// for every run, so a fitted intercept would carry run A's bias into run B: 82.2 % unreferenced).
// The classic baseline (poly: degree-2 polynomial in T and a 60-s smoothed dT/dt), referenced
// alike, removes 82.5 %. Bounds: 92 % and 6 points over poly.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/simulation/fog_simulator.h"

namespace gyrodrift::drift {
namespace {

double ShareRemovedPercent(const Eigen::VectorXd& estimate, const Eigen::VectorXd& truth) {
  return 100.0 * (1.0 - std::sqrt((estimate - truth).squaredNorm() / truth.squaredNorm()));
}

simulation::SimulationResult Simulate8h(const char* programme, std::uint64_t seed) {
  simulation::SimulationOptions o;
  o.seed = seed;
  return simulation::Simulate(simulation::BuiltinProgramme(programme),
                              simulation::PresetParameters(simulation::Preset::kNavigation), o);
}

TEST(Compensation, ThermalModelRemovesNinetyPercentOfAnUnseenProgrammesDriftAndBeatsThePolynomial) {
  const simulation::SimulationResult train = Simulate8h("chamber", 1);
  const simulation::SimulationResult test = Simulate8h("chamber-b", 2);
  ASSERT_EQ(train.samples, 28800);

  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kThermal;
  o.reference_c = 20.0;
  const DriftModel thermal =
      FitDriftModel(train.rate_dph, train.temperature_c, o, {}, {.threads = 2});
  const double thermal_removed =
      ShareRemovedPercent(EstimateDrift(thermal, test.temperature_c), test.drift_dph);

  o.method = Method::kPoly;
  const DriftModel poly = FitDriftModel(train.rate_dph, train.temperature_c, o, {}, {.threads = 2});
  ASSERT_EQ(poly.num_inputs(), 2) << "the classic baseline sees T and dT/dt only";
  const double poly_removed =
      ShareRemovedPercent(EstimateDrift(poly, test.temperature_c), test.drift_dph);

  std::printf("removed share of the true drift RMS: thermal %.1f %%, poly %.1f %%\n",
              thermal_removed, poly_removed);
  RecordProperty("thermal_removed_percent", std::to_string(thermal_removed));
  RecordProperty("poly_removed_percent", std::to_string(poly_removed));
  EXPECT_GE(thermal_removed, 92.0) << thermal.Summary();
  EXPECT_GE(thermal_removed - poly_removed, 6.0)
      << "ms-elm " << thermal_removed << " %, poly " << poly_removed << " %";
}

}  // namespace
}  // namespace gyrodrift::drift
