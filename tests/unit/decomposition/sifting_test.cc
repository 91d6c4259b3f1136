// The sifting internals against the 10-sample case published with the Rilling/Flandrin EMD
// (../shared/testdata/emd_rilling_doppler/sifting_unit_case_10pt.json) and the first-sift
// envelope nodes of the Doppler signal.
#include "decomposition/sifting.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "gyrodrift/common/random.h"
#include "gyrodrift/io/files.h"
#include "support/test_support.h"

namespace gyrodrift::decomposition::internal {
namespace {

using nlohmann::json;

std::vector<double> ToVector(const json& j) { return j.get<std::vector<double>>(); }

TEST(Sifting, TenPointCaseMatchesReference) {
  const json ref = json::parse(
      io::ReadTextFile(test::TestDataPath("emd_rilling_doppler/sifting_unit_case_10pt.json")));
  const std::vector<double> x = ToVector(ref["input"]);
  const Eigen::Index n = static_cast<Eigen::Index>(x.size());
  const ExtremaCounts counts = CountExtrema(x.data(), n);
  EXPECT_EQ(counts.extrema(), ref["n_extrema"].get<int>());
  EXPECT_EQ(counts.zero_crossings, ref["n_zero_crossings"].get<int>());

  Sifter sifter(n, SiftingOptions{});
  std::vector<double> tmin, zmin, tmax, zmax;
  ASSERT_TRUE(sifter.EnvelopeNodes(x.data(), &tmin, &zmin, &tmax, &zmax));
  EXPECT_EQ(tmin, ToVector(ref["extended_tmin"]));
  EXPECT_EQ(zmin, ToVector(ref["extended_zmin"]));
  EXPECT_EQ(tmax, ToVector(ref["extended_tmax"]));
  EXPECT_EQ(zmax, ToVector(ref["extended_zmax"]));

  std::vector<double> mean(x.size()), amplitude(x.size());
  ASSERT_TRUE(sifter.MeanAndAmplitude(x.data(), mean.data(), amplitude.data()));
  const auto ref_mean = ToVector(ref["mean_envelope"]);
  const auto ref_amp = ToVector(ref["half_amplitude"]);
  for (size_t i = 0; i < x.size(); ++i) {
    // The reference is published with 9 decimals.
    EXPECT_NEAR(mean[i], ref_mean[i], 1e-9) << i;
    EXPECT_NEAR(amplitude[i], ref_amp[i], 1e-9) << i;
  }
}

TEST(Sifting, DopplerFirstSiftNodesMatchReference) {
  const Eigen::VectorXd x = test::ReadF64(test::TestDataPath("emd_rilling_doppler/doppler4096_f64le.bin"));
  const Eigen::VectorXd ref_min =
      test::ReadF64(test::TestDataPath("emd_rilling_doppler/first_sift_zmin24_f64le.bin"));
  const Eigen::VectorXd ref_max =
      test::ReadF64(test::TestDataPath("emd_rilling_doppler/first_sift_zmax24_f64le.bin"));
  Sifter sifter(x.size(), SiftingOptions{});
  std::vector<double> tmin, zmin, tmax, zmax;
  ASSERT_TRUE(sifter.EnvelopeNodes(x.data(), &tmin, &zmin, &tmax, &zmax));
  ASSERT_EQ(zmin.size(), static_cast<size_t>(ref_min.size()));
  ASSERT_EQ(zmax.size(), static_cast<size_t>(ref_max.size()));
  for (size_t k = 0; k < zmin.size(); ++k) {
    EXPECT_EQ(zmin[k], ref_min[static_cast<Eigen::Index>(k)]) << k;
    EXPECT_EQ(zmax[k], ref_max[static_cast<Eigen::Index>(k)]) << k;
  }
}

TEST(Sifting, PlateausCountOnceAtTheirMiddle) {
  // Plateau maximum over samples 2..4 (0-based), a strict maximum at 8; plateau minima over 6..7
  // and over the zeros at 9..10 (falling into the run, rising out of it).
  const std::vector<double> x{0, 1, 3, 3, 3, 1, -2, -2, 1, 0, 0, 2};
  const ExtremaCounts c = CountExtrema(x.data(), static_cast<Eigen::Index>(x.size()));
  EXPECT_EQ(c.maxima, 2);
  EXPECT_EQ(c.minima, 2);
  // Sign changes 5->6 and 7->8, the run of zeros at 9..10, and x[0] = 0.
  EXPECT_EQ(c.zero_crossings, 4);
}

TEST(Sifting, InputWithoutEnoughExtremaGivesNoImf) {
  const std::vector<double> ramp{0, 1, 2, 3, 4, 5};
  Sifter sifter(6, SiftingOptions{});
  std::vector<double> imf(6, 42.0);
  const SiftOutcome outcome = sifter.ExtractImf(ramp.data(), imf.data());
  EXPECT_FALSE(outcome.extracted);
  EXPECT_EQ(imf[0], 42.0);
}

TEST(Sifting, ReleasingTheNodeBuffersChangesNoResult) {
  // The node buffers given back between IMFs (long signals) read as zeros afterwards, where a
  // sifter that kept them still holds the last IMF's nodes: every value is written before it is
  // read, so both extract the same bits. 20000 samples: the buffers span many pages; both ways
  // of applying the upper envelope (stored, or fused into the sift) run.
  const Eigen::Index n = 20000;
  Eigen::VectorXd a(n), b(n);
  Rng(5, 0).FillNormal(a);
  Rng(5, 1).FillNormal(b);
  for (StopRule rule : {StopRule::kRilling, StopRule::kSNumber}) {
    const SiftingOptions o{.stop_rule = rule};
    Sifter released(n, o), kept(n, o);
    Eigen::VectorXd first(n), again(n), reference(n);
    released.ExtractImf(a.data(), first.data());
    kept.ExtractImf(a.data(), first.data());
    released.ReleaseNodeBuffers();
    const SiftOutcome u = released.ExtractImf(b.data(), again.data());
    const SiftOutcome f = kept.ExtractImf(b.data(), reference.data());
    EXPECT_EQ(u.sifts, f.sifts);
    EXPECT_TRUE((again.array() == reference.array()).all());
  }
}

}  // namespace
}  // namespace gyrodrift::decomposition::internal
