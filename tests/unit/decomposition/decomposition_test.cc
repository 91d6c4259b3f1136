// The entry points of src/decomposition/decomposition.cc: enum names shared with the CLI, option
// validation (every refusal names the field as the caller reaches it), option equality, the
// checks on the signal and on supplied noise, and the report's summary line. The methods
// themselves have their own files (emd_test.cc, eemd_test.cc, ...).
#include "gyrodrift/decomposition/decomposition.h"
#include "unit/decomposition/hand_made.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"

namespace gyrodrift::decomposition {
namespace {

Eigen::VectorXd Noisy(Eigen::Index n) {
  Eigen::VectorXd x(n);
  Rng rng(81, 0);
  for (Eigen::Index i = 0; i < n; ++i) {
    x[i] = 0.5 * rng.Normal() + std::sin(2 * std::numbers::pi * i / 32.0);
  }
  return x;
}

// The spellings documented in decomposition.h (and used by the CLI and model metadata).
TEST(Decomposition, EnumNamesRoundTrip) {
  const std::vector<std::pair<Method, std::string>> methods = {{Method::kEmd, "emd"},
                                                               {Method::kEemd, "eemd"},
                                                               {Method::kCeemdan, "ceemdan"},
                                                               {Method::kIceemdan, "iceemdan"},
                                                               {Method::kBeemdan, "beemdan"}};
  for (const auto& [m, name] : methods) {
    EXPECT_EQ(ToString(m), name);
    EXPECT_EQ(MethodFromString(name), m);
  }
  const std::vector<std::pair<StopRule, std::string>> rules = {{StopRule::kRilling, "rilling"},
                                                               {StopRule::kSNumber, "snumber"},
                                                               {StopRule::kFixed, "fixed"},
                                                               {StopRule::kCauchySd, "sd"}};
  for (const auto& [r, name] : rules) {
    EXPECT_EQ(ToString(r), name);
    EXPECT_EQ(StopRuleFromString(name), r);
  }
  const std::vector<std::pair<BeemdanBound, std::string>> bounds = {
      {BeemdanBound::kEnergyBand, "energy"},
      {BeemdanBound::kFixedStages, "stages"},
      {BeemdanBound::kFull, "full"},
      {BeemdanBound::kEnsembleBand, "ensemble"}};
  for (const auto& [b, name] : bounds) {
    EXPECT_EQ(ToString(b), name);
    EXPECT_EQ(BeemdanBoundFromString(name), b);
  }
  EXPECT_EQ(ToString(NoiseScaling::kColominas2014), "colominas2014");
  EXPECT_EQ(ToString(NoiseScaling::kConstantSnr), "constant-snr");
  EXPECT_EQ(NoiseScalingFromString("colominas2014"), NoiseScaling::kColominas2014);
  EXPECT_EQ(NoiseScalingFromString("constant-snr"), NoiseScaling::kConstantSnr);
}

TEST(Decomposition, UnknownNamesAreRefusedListingTheChoices) {
  try {
    MethodFromString("EMD");  // names are case-sensitive
    FAIL();
  } catch (const OptionError& e) {
    EXPECT_EQ(e.option(), "method");
    EXPECT_STREQ(e.what(), "method = 'EMD': must be one of emd, eemd, ceemdan, iceemdan, beemdan");
  }
  auto option_of = [](const std::function<void()>& f) -> std::string {
    try {
      f();
    } catch (const OptionError& e) {
      return e.option();
    }
    return "(no error)";
  };
  EXPECT_EQ(option_of([] { StopRuleFromString("cauchy"); }), "stop_rule");
  EXPECT_EQ(option_of([] { BeemdanBoundFromString(""); }), "beemdan_bound");
  EXPECT_EQ(option_of([] { NoiseScalingFromString("snr"); }), "noise_scaling");
}

TEST(Decomposition, OnlyTheCeemdanFamilyUsesNoiseEmds) {
  EXPECT_FALSE(UsesNoiseEmds(Method::kEmd));
  EXPECT_FALSE(UsesNoiseEmds(Method::kEemd));  // EEMD adds the raw noise, never its EMD
  EXPECT_TRUE(UsesNoiseEmds(Method::kCeemdan));
  EXPECT_TRUE(UsesNoiseEmds(Method::kIceemdan));
  EXPECT_TRUE(UsesNoiseEmds(Method::kBeemdan));
}

TEST(Decomposition, EffectiveMaxSiftsIsTheRulesCustomaryCapUnlessSet) {
  SiftingOptions s;
  EXPECT_EQ(s.EffectiveMaxSifts(), 2000);  // emd.m
  s.stop_rule = StopRule::kSNumber;
  EXPECT_EQ(s.EffectiveMaxSifts(), 50);  // libeemd
  s.stop_rule = StopRule::kFixed;
  s.fixed_sifts = 7;
  EXPECT_EQ(s.EffectiveMaxSifts(), 7);
  s.stop_rule = StopRule::kCauchySd;
  EXPECT_EQ(s.EffectiveMaxSifts(), 2000);
  s.max_sifts = 12;
  EXPECT_EQ(s.EffectiveMaxSifts(), 12);
}

struct BadOption {
  std::string option;  // the dotted path the refusal must name
  std::string value;   // as the message shows it
  std::function<void(DecompositionOptions&)> spoil;
};

// Every field's range, at and just past its limits; refusals name the field as the caller
// reaches it ("sifting.max_sifts"), the value, and the rule.
TEST(Decomposition, ValidateNamesTheDottedFieldAndValue) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<BadOption> bad = {
      {"sifting.rilling_threshold1", "0", [](auto& o) { o.sifting.rilling_threshold1 = 0; }},
      {"sifting.rilling_threshold1", "1", [](auto& o) { o.sifting.rilling_threshold1 = 1; }},
      {"sifting.rilling_threshold1", "nan", [&](auto& o) { o.sifting.rilling_threshold1 = nan; }},
      {"sifting.rilling_threshold2", "0.04", [](auto& o) { o.sifting.rilling_threshold2 = 0.04; }},
      {"sifting.rilling_threshold2", "inf", [&](auto& o) { o.sifting.rilling_threshold2 = inf; }},
      {"sifting.rilling_tolerance", "1", [](auto& o) { o.sifting.rilling_tolerance = 1; }},
      {"sifting.rilling_tolerance", "-0.01", [](auto& o) { o.sifting.rilling_tolerance = -0.01; }},
      {"sifting.s_number", "0", [](auto& o) { o.sifting.s_number = 0; }},
      {"sifting.s_number", "1001", [](auto& o) { o.sifting.s_number = 1001; }},
      {"sifting.fixed_sifts", "0", [](auto& o) { o.sifting.fixed_sifts = 0; }},
      {"sifting.fixed_sifts", "100001", [](auto& o) { o.sifting.fixed_sifts = 100001; }},
      {"sifting.sd_threshold", "0", [](auto& o) { o.sifting.sd_threshold = 0; }},
      {"sifting.sd_threshold", "inf", [&](auto& o) { o.sifting.sd_threshold = inf; }},
      {"sifting.max_sifts", "-1", [](auto& o) { o.sifting.max_sifts = -1; }},
      {"sifting.max_sifts", "1000001", [](auto& o) { o.sifting.max_sifts = 1000001; }},
      {"max_imfs", "-1", [](auto& o) { o.max_imfs = -1; }},
      {"max_imfs", "1001", [](auto& o) { o.max_imfs = 1001; }},
      {"ensemble_size", "0", [](auto& o) { o.ensemble_size = 0; }},
      {"ensemble_size", "100001", [](auto& o) { o.ensemble_size = 100001; }},
      {"noise_strength", "0", [](auto& o) { o.noise_strength = 0; }},
      {"noise_strength", "10.5", [](auto& o) { o.noise_strength = 10.5; }},
      {"noise_strength", "nan", [&](auto& o) { o.noise_strength = nan; }},
      {"band_confidence", "0.9", [](auto& o) { o.band_confidence = 0.9; }},
      {"noise_stages", "0", [](auto& o) { o.noise_stages = 0; }},
      {"noise_stages", "1001", [](auto& o) { o.noise_stages = 1001; }},
  };
  const Eigen::VectorXd x = Noisy(64);
  for (const BadOption& b : bad) {
    DecompositionOptions o;
    o.method = Method::kEmd;  // every field is checked whatever the method
    b.spoil(o);
    try {
      o.Validate();
      ADD_FAILURE() << b.option << " = " << b.value << " accepted";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.option(), b.option);
      EXPECT_EQ(e.value(), b.value) << b.option;
      EXPECT_EQ(std::string(e.what()).rfind(b.option + " = " + b.value + ": must be ", 0), 0u)
          << e.what();
    }
    // Decompose checks before any work.
    EXPECT_THROW(Decompose(x, o), OptionError) << b.option;
  }
}

TEST(Decomposition, ValidateAcceptsTheLimitsOfEachRange) {
  const std::vector<std::function<void(DecompositionOptions&)>> good = {
      [](auto& o) { o.sifting.rilling_threshold2 = o.sifting.rilling_threshold1; },
      [](auto& o) { o.sifting.rilling_tolerance = 0; },
      [](auto& o) { o.sifting.s_number = 1; },
      [](auto& o) { o.sifting.s_number = 1000; },
      [](auto& o) { o.sifting.fixed_sifts = 1; },
      [](auto& o) { o.sifting.max_sifts = 1; },
      [](auto& o) { o.sifting.max_sifts = 1000000; },
      [](auto& o) { o.max_imfs = 1000; },
      [](auto& o) { o.ensemble_size = 1; },
      [](auto& o) { o.ensemble_size = 100000; },
      [](auto& o) { o.noise_strength = 10; },
      [](auto& o) { o.band_confidence = 0.95; },
      [](auto& o) { o.noise_stages = 1000; },
  };
  for (size_t i = 0; i < good.size(); ++i) {
    DecompositionOptions o;
    good[i](o);
    EXPECT_NO_THROW(o.Validate()) << "case " << i;
  }
}

// == compares every field (the noise EMDs and model metadata rely on it): changing any one
// field, nested ones included, makes the options differ.
TEST(Decomposition, OptionsCompareEveryField) {
  const DecompositionOptions base;
  EXPECT_EQ(base, DecompositionOptions{});
  const std::vector<std::function<void(DecompositionOptions&)>> changes = {
      [](auto& o) { o.method = Method::kIceemdan; },
      [](auto& o) { o.sifting.stop_rule = StopRule::kSNumber; },
      [](auto& o) { o.sifting.rilling_threshold1 = 0.06; },
      [](auto& o) { o.sifting.rilling_threshold2 = 0.6; },
      [](auto& o) { o.sifting.rilling_tolerance = 0.1; },
      [](auto& o) { o.sifting.s_number = 5; },
      [](auto& o) { o.sifting.fixed_sifts = 11; },
      [](auto& o) { o.sifting.sd_threshold = 0.3; },
      [](auto& o) { o.sifting.max_sifts = 100; },
      [](auto& o) { o.max_imfs = 4; },
      [](auto& o) { o.ensemble_size = 99; },
      [](auto& o) { o.noise_strength = 0.21; },
      [](auto& o) { o.seed = 2; },
      [](auto& o) { o.noise_scaling = NoiseScaling::kConstantSnr; },
      [](auto& o) { o.beemdan_bound = BeemdanBound::kFull; },
      [](auto& o) { o.band_confidence = 0.95; },
      [](auto& o) { o.noise_stages = 4; },
  };
  for (size_t i = 0; i < changes.size(); ++i) {
    DecompositionOptions o;
    changes[i](o);
    EXPECT_FALSE(o == base) << "change " << i;
  }
}

TEST(Decomposition, BadSignalsThrowDataErrorNamingTheProblem) {
  const DecompositionOptions o;
  auto message = [&](const Eigen::VectorXd& x) -> std::string {
    try {
      Decompose(x, o);
    } catch (const DataError& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_EQ(message(Eigen::VectorXd::Zero(3)), "input signal has 3 samples: at least 4 are needed");
  Eigen::VectorXd x = Noisy(40);
  x[39] = std::numeric_limits<double>::infinity();
  EXPECT_EQ(message(x), "input signal sample 40 is inf: every sample must be finite");
  // Four samples is enough to be accepted.
  Eigen::VectorXd four(4);
  four << 0, 1, 0, 1;
  EXPECT_NO_THROW(Decompose(four, o));
}

// A constant signal is not an error: it has no IMF, for every method (the CEEMDAN family would
// otherwise divide by its zero std). The report still says what ran and why nothing came out.
TEST(Decomposition, ConstantSignalHasNoImfAndSaysWhy) {
  const Eigen::VectorXd x = Eigen::VectorXd::Constant(200, -1.25);
  for (const Method m :
       {Method::kEmd, Method::kEemd, Method::kCeemdan, Method::kIceemdan, Method::kBeemdan}) {
    DecompositionOptions o;
    o.method = m;
    o.seed = 99;
    const Decomposition d = Decompose(x, o);
    EXPECT_EQ(d.num_imfs(), 0) << ToString(m);
    EXPECT_EQ(d.imfs.rows(), 200) << ToString(m);
    EXPECT_EQ(d.residue, x) << ToString(m);
    EXPECT_EQ(d.report.method, m);
    EXPECT_EQ(d.report.seed, 99u);
    EXPECT_EQ(d.report.stop_reason, "input has fewer than 3 extrema: no IMF");
    EXPECT_TRUE(d.imfs.allFinite());
  }
}

TEST(Decomposition, SuppliedNoiseIsCheckedAndItsColumnsAreTheEnsemble) {
  const Eigen::VectorXd x = Noisy(128);
  DecompositionOptions o;
  o.method = Method::kIceemdan;
  o.ensemble_size = 100;  // checked, not used: the noise's columns are the ensemble
  const Eigen::MatrixXd w = hand_made::DrawnColumns(5, 3, 128);
  const Decomposition d = DecomposeWithNoise(x, w, o);
  EXPECT_EQ(d.report.ensemble_size, 3);
  EXPECT_TRUE(d.report.supplied_noise);
  EXPECT_NE(d.report.Summary().find("ensemble 3 (supplied noise)"), std::string::npos)
      << d.report.Summary();
  o.ensemble_size = 0;
  EXPECT_THROW(DecomposeWithNoise(x, w, o), OptionError);
  o.ensemble_size = 3;
  EXPECT_THROW(DecomposeWithNoise(x, Eigen::MatrixXd(128, 0), o), DataError);
  Eigen::MatrixXd bad = w;
  bad(5, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(DecomposeWithNoise(x, bad, o), DataError);
  // A magnitude no instrument logs, refused as in the signal (1e200 gave inf IMFs and exit 0).
  bad(5, 1) = 1e200;
  try {
    DecomposeWithNoise(x, bad, o);
    ADD_FAILURE() << "accepted a noise sample of 1e200";
  } catch (const DataError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("supplied noise column 2 sample 6 is 1e+200", 0), 0u)
        << e.what();
  }
  // A constant realisation (zero or not) cannot be scaled to unit variance: refused by column,
  // for every method of the CEEMDAN family, before any work (it used to run without end). EEMD
  // adds the noise unscaled and takes it (eemd_test: a zero member is plain EMD).
  for (const double level : {0.0, 0.3}) {
    Eigen::MatrixXd flat = w;
    flat.col(2).setConstant(level);
    for (const Method m : {Method::kCeemdan, Method::kIceemdan, Method::kBeemdan}) {
      o.method = m;
      try {
        DecomposeWithNoise(x, flat, o);
        ADD_FAILURE() << ToString(m) << " accepted a constant noise column " << level;
      } catch (const DataError& e) {
        EXPECT_STREQ(e.what(), "supplied noise column 3 is constant: a noise realisation must vary");
      }
    }
  }
}

// Supplying stream (seed, i) as column i reproduces the drawn decomposition bit for bit: the
// noise draw is exactly the documented one, for each noise-assisted method.
TEST(Decomposition, SuppliedNoiseEqualToTheDrawnStreamsGivesTheSameBits) {
  const Eigen::VectorXd x = Noisy(512);
  for (const Method m : {Method::kEemd, Method::kCeemdan, Method::kIceemdan, Method::kBeemdan}) {
    DecompositionOptions o;
    o.method = m;
    o.ensemble_size = 4;
    o.seed = 23;
    const Eigen::MatrixXd w = hand_made::DrawnColumns(o.seed, 4, 512);
    const Decomposition drawn = Decompose(x, o);
    const Decomposition supplied = DecomposeWithNoise(x, w, o);
    EXPECT_EQ(drawn.imfs, supplied.imfs) << ToString(m);
    EXPECT_EQ(drawn.residue, supplied.residue) << ToString(m);
    EXPECT_FALSE(drawn.report.supplied_noise);
    EXPECT_TRUE(supplied.report.supplied_noise);
    // And another seed draws other noise.
    o.seed = 24;
    const Decomposition other = Decompose(x, o);
    EXPECT_FALSE(other.imfs.cols() == drawn.imfs.cols() && other.imfs == drawn.imfs) << ToString(m);
  }
}

// Summary(): one line with the method, the IMF count, sifts per IMF, and the parts that apply.
TEST(Decomposition, SummaryIsOneLineWithWhatApplies) {
  const Eigen::VectorXd x = Noisy(256);
  DecompositionOptions o;
  o.method = Method::kEmd;
  const Decomposition emd = Decompose(x, o);
  std::string expected = "emd: " + std::to_string(emd.num_imfs()) + " IMFs, sifts per IMF [";
  for (size_t k = 0; k < emd.report.sifts_per_imf.size(); ++k) {
    expected += (k ? " " : "") + std::to_string(emd.report.sifts_per_imf[k]);
  }
  expected += "]; stop: residue has fewer than 3 extrema";
  EXPECT_EQ(emd.report.Summary(), expected);

  o.method = Method::kBeemdan;
  o.ensemble_size = 4;
  o.seed = 42;
  const std::string s = Decompose(x, o).report.Summary();
  EXPECT_EQ(s.rfind("beemdan: ", 0), 0u) << s;
  EXPECT_NE(s.find("ensemble 4, seed 42"), std::string::npos) << s;
  EXPECT_NE(s.find("noise-assisted stages"), std::string::npos) << s;
  EXPECT_EQ(s.find('\n'), std::string::npos) << s;
  o.method = Method::kEemd;
  EXPECT_EQ(Decompose(x, o).report.Summary().find("noise-assisted"), std::string::npos);
}

}  // namespace
}  // namespace gyrodrift::decomposition
