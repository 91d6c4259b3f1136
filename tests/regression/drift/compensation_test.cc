// Issue 4's compensation claim on the simulator, end to end: a model fitted on one chamber
// programme (builtin "chamber", seed 1) compensates a gyro run through another ("chamber-b",
// seed 2) it never saw. Navigation preset, 8 h at 1 Hz, scored against the simulator's true
// thermal drift (drift_dph), i.e. the drift the compensation is meant to remove.
//
// Measured (docs/drift.md, section 4.1): MS-ELM removes 94.2 % of the true drift's RMS, with the
// default BEEMDAN ensemble (100) and with the 20 realisations (and 20 Monte-Carlo noise records)
// used here to keep the test fast: compensate-mode sub-models are linear, so the grouping does
// not change the estimate. The classic baseline (poly: degree-2 polynomial in T and a 60-s
// smoothed dT/dt) removes 82.5 %. The bounds keep most of each measured margin: 92 % (measured
// 94.2; other noise seeds gave 88.1 to 93.6, docs/drift.md) and 6 points over poly (11.7).
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

TEST(Compensation, MsElmRemovesNinetyPercentOfAnUnseenProgrammesDriftAndBeatsThePolynomial) {
  const simulation::SimulationResult train = Simulate8h("chamber", 1);
  const simulation::SimulationResult test = Simulate8h("chamber-b", 2);
  ASSERT_EQ(train.samples, 28800);

  DriftOptions o;
  o.mode = Mode::kCompensate;
  o.method = Method::kMsElm;
  o.decomposition.ensemble_size = 20;
  o.selection.monte_carlo.realisations = 20;
  o.threads = 2;
  const DriftModel ms_elm = FitDriftModel(train.rate_dph, train.temperature_c, o);
  const double ms_elm_removed =
      ShareRemovedPercent(EstimateDrift(ms_elm, test.temperature_c), test.drift_dph);

  o.method = Method::kPoly;
  const DriftModel poly = FitDriftModel(train.rate_dph, train.temperature_c, o);
  ASSERT_EQ(poly.num_inputs(), 2) << "the classic baseline sees T and dT/dt only";
  const double poly_removed =
      ShareRemovedPercent(EstimateDrift(poly, test.temperature_c), test.drift_dph);

  std::printf("removed share of the true drift RMS: ms-elm %.1f %%, poly %.1f %%\n", ms_elm_removed,
              poly_removed);
  RecordProperty("ms_elm_removed_percent", std::to_string(ms_elm_removed));
  RecordProperty("poly_removed_percent", std::to_string(poly_removed));
  EXPECT_GE(ms_elm_removed, 92.0) << ms_elm.Summary();
  EXPECT_GE(ms_elm_removed - poly_removed, 6.0)
      << "ms-elm " << ms_elm_removed << " %, poly " << poly_removed << " %";
}

}  // namespace
}  // namespace gyrodrift::drift
