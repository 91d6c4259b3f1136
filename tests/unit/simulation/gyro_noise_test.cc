#include "gyrodrift/simulation/gyro_noise.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

// Overlapping Allan variance of rate samples y at factor m (IEEE 952 / NIST SP 1065 eq. 11),
// written out here so the generator is checked independently of the allan module.
double Oavar(const Eigen::VectorXd& y, double dt, Eigen::Index m) {
  const Eigen::Index n = y.size();
  Eigen::VectorXd x(n + 1);
  x[0] = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) x[i + 1] = x[i] + y[i] * dt;
  const double tau = m * dt;
  double sum = 0.0;
  const Eigen::Index terms = n + 1 - 2 * m;
  for (Eigen::Index i = 0; i < terms; ++i) {
    const double d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
    sum += d * d;
  }
  return sum / (2.0 * tau * tau * static_cast<double>(terms));
}

NoiseParameters Only(double q, double n, double b, double k, double r) {
  NoiseParameters p;
  p.quantization_urad = q;
  p.arw_dpsh = n;
  p.bias_instability_dph = b;
  p.rrw_dphpsh = k;
  p.rate_ramp_dphph = r;
  return p;
}

TEST(GyroNoise, EachTermHasItsIeee952AllanVariance) {
  struct Case {
    const char* name;
    NoiseParameters params;
    double dt;
    Eigen::Index n;
    std::vector<Eigen::Index> factors;
    double tolerance;  // relative, on the variance
  };
  const std::vector<Case> cases = {
      {"Q", Only(0.786, 0, 0, 0, 0), 0.01, 200000, {1, 4, 30}, 0.08},
      {"N", Only(0, 4.58e-3, 0, 0, 0), 1.0, 200000, {1, 10, 100}, 0.08},
      {"K", Only(0, 0, 0, 2e-3, 0), 1.0, 400000, {10, 100, 1000}, 0.25},
      {"R", Only(0, 0, 0, 0, 0.5), 1.0, 20000, {10, 100, 1000}, 1e-6},
  };
  for (const auto& c : cases) {
    const Eigen::VectorXd noise = GenerateNoise(c.params, c.dt, c.n, 11);
    for (const Eigen::Index m : c.factors) {
      const double model = NoiseAllanVariance(c.params, c.dt, m);
      EXPECT_NEAR(Oavar(noise, c.dt, m) / model, 1.0, c.tolerance) << c.name << " m = " << m;
    }
  }
  // The IEEE forms themselves: 3 Q^2 / tau^2, N^2 / tau, K^2 tau / 3, R^2 tau^2 / 2 in deg/h.
  const double q = 0.786e-6 * kDegPerHourPerRadPerSecond;
  EXPECT_NEAR(NoiseAllanVariance(Only(0.786, 0, 0, 0, 0), 0.01, 100), 3 * q * q, 1e-12 * q * q);
  EXPECT_NEAR(NoiseAllanVariance(Only(0, 4.58e-3, 0, 0, 0), 1.0, 100),
              std::pow(4.58e-3 * 60, 2) / 100, 1e-15);
  EXPECT_NEAR(NoiseAllanVariance(Only(0, 0, 0, 2e-3, 0), 1.0, 10000),
              std::pow(2e-3 / 60, 2) * 10000 / 3, 1e-6 * std::pow(2e-3 / 60, 2) * 10000 / 3);
}

TEST(GyroNoise, BiasInstabilityBankHasAFlatFloor) {
  const NoiseParameters p = Only(0, 0, 0.01, 0, 0);
  const BiasBank bank = DesignBiasBank(p, 1.0);
  EXPECT_EQ(bank.tau_s.size(), 20u);  // 0.6 s .. 1e6 s: 6.2 decades x 3 + 1
  EXPECT_DOUBLE_EQ(bank.tau_s.front(), 0.6);
  EXPECT_LT(bank.floor_ripple, 0.03);
  const double floor = std::sqrt(2 * std::numbers::ln2 / std::numbers::pi) * 0.01;
  for (const Eigen::Index m : {1, 2, 5, 10, 100, 1000, 10000, 100000}) {
    EXPECT_NEAR(std::sqrt(NoiseAllanVariance(p, 1.0, m)) / floor, 1.0, 0.045) << m;
  }
  const Eigen::VectorXd noise = GenerateNoise(p, 1.0, 1000000, 5);
  for (const Eigen::Index m : {30, 100, 300, 1000}) {
    EXPECT_NEAR(std::sqrt(Oavar(noise, 1.0, m)) / floor, 1.0, 0.1) << m;
  }
}

TEST(GyroNoise, NamedStreamsAreIndependentOfEachOther) {
  const NoiseParameters all;  // defaults: Q, N, B and K on
  const Eigen::VectorXd total = GenerateNoise(all, 1.0, 5000, 3);
  Eigen::VectorXd sum = GenerateNoise(Only(all.quantization_urad, 0, 0, 0, 0), 1.0, 5000, 3) +
                        GenerateNoise(Only(0, all.arw_dpsh, 0, 0, 0), 1.0, 5000, 3) +
                        GenerateNoise(Only(0, 0, all.bias_instability_dph, 0, 0), 1.0, 5000, 3) +
                        GenerateNoise(Only(0, 0, 0, all.rrw_dphpsh, 0), 1.0, 5000, 3);
  EXPECT_LT((total - sum).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_EQ(total, GenerateNoise(all, 1.0, 5000, 3));
  EXPECT_GT((total - GenerateNoise(all, 1.0, 5000, 4)).cwiseAbs().maxCoeff(), 0.1);
}

TEST(GyroNoise, RejectsBadParameters) {
  NoiseParameters p;
  p.arw_dpsh = -1;
  EXPECT_THROW(GenerateNoise(p, 1.0, 10, 1), UsageError);
  p = {};
  p.bias_tau_min_s = 10.0;
  p.bias_tau_max_s = 500.0;
  EXPECT_THROW(p.Validate(), UsageError);
  p = {};
  p.bias_tau_max_s = 50.0;  // fine at 10 Hz (automatic minimum 0.06 s) ...
  EXPECT_NO_THROW(DesignBiasBank(p, 0.1));
  EXPECT_THROW(DesignBiasBank(p, 1.0), UsageError);  // ... not at 1 Hz
  p = {};
  EXPECT_THROW(GenerateNoise(p, 0.0, 10, 1), UsageError);
}

TEST(TemperatureSensor, LagsARampByItsTimeConstant) {
  TemperatureSensorParameters p;
  p.noise_k = 0.0;
  p.resolution_k = 0.0;
  p.time_constant_s = 30.0;
  Eigen::VectorXd ramp(1000);
  for (int k = 0; k < 1000; ++k) ramp[k] = 0.01 * k;
  const Eigen::VectorXd reading = SenseTemperature(p, ramp, 1.0, 1);
  EXPECT_NEAR((ramp[999] - reading[999]) / 0.01, 30.0, 1e-6);
}

TEST(TemperatureSensor, QuantisesAndAddsNoise) {
  TemperatureSensorParameters p;  // 0.02 K noise, 0.0625 K steps
  const Eigen::VectorXd flat = Eigen::VectorXd::Constant(20000, 21.3);
  const Eigen::VectorXd reading = SenseTemperature(p, flat, 1.0, 9);
  for (Eigen::Index k = 0; k < reading.size(); ++k) {
    const double steps = reading[k] / 0.0625;
    ASSERT_NEAR(steps, std::round(steps), 1e-9);
  }
  const double mean = reading.mean();
  const double sd = std::sqrt((reading.array() - mean).square().mean());
  EXPECT_NEAR(mean, 21.3, 0.005);
  // Noise 0.02 K plus uniform rounding error 0.0625 / sqrt(12) = 0.018 K, roughly in quadrature.
  EXPECT_GT(sd, 0.02);
  EXPECT_LT(sd, 0.035);
}

}  // namespace
}  // namespace gyrodrift::simulation
