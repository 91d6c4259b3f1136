// The causal protocol (causal_protocol.cc): nothing after a prediction's origin reaches it,
// windows sharing the white-noise EMDs predict as windows decomposed alone, each window is
// decomposed with its mirrored tail, the ensemble and progress options, the note on sub-models a
// window cannot feed, the averaging of several windows, and the option ranges.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "drift/prediction_steps.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/drift_model.h"
#include "unit/drift/drift_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Fast;
using fixtures::Log;
using fixtures::MakeLog;

// An MS-ELM predict model fitted on the first 500 samples of a 700-sample log, and causal options
// with 64-sample windows (run on 2 threads).
struct CausalCase {
  Log log;
  DriftModel model;
  CausalOptions causal;
};

CausalCase MakeCausalCase(std::uint64_t seed) {
  CausalCase c{MakeLog(700, seed), {}, {}};
  c.model =
      FitDriftModel(c.log.rate.head(500), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  c.causal.window = 64;
  return c;
}

TEST(DriftModel, CausalWindowProgressIsMonotoneAndDoesNotChangeTheResult) {
  auto [log, model, causal] = MakeCausalCase(5);
  Execution execution{.threads = 2};
  const Eigen::VectorXd quiet =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal, execution);
  std::vector<double> seen;
  execution.progress = [&seen](double f, std::string_view step) {
    EXPECT_EQ(step, "causal windows");
    seen.push_back(f);
  };
  const Eigen::VectorXd reported =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal, execution);
  EXPECT_EQ(quiet, reported);
  ASSERT_GE(seen.size(), 10u);
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GT(seen.front(), 0.0);
  EXPECT_EQ(seen.back(), 1.0);
}

// Full windows share one set of white-noise EMDs (computed once, not per window): each
// prediction is still the one a lone decomposition of its window gives, to the bit.
TEST(DriftModel, CausalWindowsSharingTheNoiseEmdsPredictAsAloneWindows) {
  const auto [log, model, causal] = MakeCausalCase(6);
  const Eigen::VectorXd all =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal);
  for (Eigen::Index t : {500, 563, 699}) {
    // A record ending at t has a single full window: nothing to share.
    const Eigen::VectorXd alone = PredictOneStep(model, log.rate.head(t + 1), Eigen::VectorXd(), t,
                                                 Protocol::kCausal, causal);
    ASSERT_EQ(alone.size(), 1);
    EXPECT_EQ(alone[0], all[t - 500]) << t;
  }
}

// Each window y[o-L .. o-1] is decomposed followed by min(round(mirror x L), L - 1) samples of
// itself reversed, y[o-2], y[o-3], ...; the lags are the mean of the group series' values at the
// windows' own end over the distinct lengths min(L, o) of CausalOptions::WindowLengths, for full
// windows (sharing their noise EMDs) and the short ones at the record's start alike; mirror 0
// decomposes a window alone, and one window is that window's values.
TEST(DriftModel, CausalWindowsAreDecomposedWithTheirMirroredTailAndAveraged) {
  auto [log, model, causal] = MakeCausalCase(8);
  const Eigen::Index origin = 40, count = 60;  // origins 40-63 have short windows
  const std::vector<std::pair<int, double>> cases = {{1, 0.5}, {1, 0.0}, {1, 0.3},
                                                     {1, 1.0}, {3, 0.5}, {2, 0.0}};
  for (const auto& [windows, mirror] : cases) {
    causal.windows = windows;
    causal.mirror = mirror;
    const std::vector<Eigen::MatrixXd> lags =
        internal::CausalLags(model, log.rate, origin, count, causal, {.threads = 2});
    for (Eigen::Index o : {40, 63, 64, 99}) {
      std::vector<Eigen::Index> lengths;  // the distinct windows at o
      for (Eigen::Index full : causal.WindowLengths()) {
        const Eigen::Index length = std::min(o, full);
        if (lengths.empty() || lengths.back() != length) lengths.push_back(length);
      }
      std::vector<Eigen::MatrixXd> expected(lags.size(), Eigen::MatrixXd::Zero(1, model.lags));
      for (const Eigen::Index length : lengths) {
        // At most the window's samples but its end one: y[o-2] .. y[o-length].
        const Eigen::Index tail =
            std::min<Eigen::Index>(length - 1, std::llround(mirror * static_cast<double>(length)));
        ASSERT_EQ(causal.DecomposedLength(length), length + tail);
        Eigen::VectorXd window(length + tail);
        for (Eigen::Index i = 0; i < length; ++i) window[i] = log.rate[o - length + i];
        for (Eigen::Index j = 0; j < tail; ++j) window[length + j] = log.rate[o - 2 - j];
        decomposition::DecompositionOptions dopt = internal::DecompositionFor(model);
        dopt.ensemble_size = causal.ensemble_size;
        const Eigen::MatrixXd series = GroupSeries(model, decomposition::Decompose(window, dopt));
        for (size_t g = 0; g < lags.size(); ++g) {
          for (Eigen::Index k = 0; k < model.lags; ++k) {
            expected[g](0, k) += series(length - 1 - k, static_cast<Eigen::Index>(g));
          }
        }
      }
      for (size_t g = 0; g < lags.size(); ++g) {
        for (Eigen::Index k = 0; k < model.lags; ++k) {
          EXPECT_EQ(lags[g](o - origin, k), expected[g](0, k) / static_cast<double>(lengths.size()))
              << windows << " windows, mirror " << mirror << ", origin " << o << ", group " << g
              << ", lag " << k;
        }
      }
    }
  }
}

// n windows run from W down to W/2, evenly spaced in log, rounded, at least 16 samples (or W if
// shorter), each length once.
TEST(CausalOptions, WindowLengthsSpanOneOctaveDown) {
  const auto lengths = [](int window, int windows) {
    CausalOptions c;
    c.window = window;
    c.windows = windows;
    return c.WindowLengths();
  };
  using V = std::vector<Eigen::Index>;
  EXPECT_EQ(lengths(2896, 1), V({2896}));
  EXPECT_EQ(lengths(2896, 2), V({2896, 1448}));
  EXPECT_EQ(lengths(2896, 3), V({2896, 2048, 1448}));
  EXPECT_EQ(lengths(2896, 6), V({2896, 2521, 2195, 1911, 1663, 1448}));
  EXPECT_EQ(lengths(20, 3), V({20, 16}));  // 14 and 10 are raised to 16
  EXPECT_EQ(lengths(16, 16), V({16}));
}

// Ensemble 0 is the model's own (the fit's decomposition.ensemble_size), to the bit; another
// ensemble decomposes the windows differently.
TEST(DriftModel, CausalEnsembleZeroIsTheModelsOwn) {
  auto [log, model, causal] = MakeCausalCase(9);
  ASSERT_EQ(model.options.decomposition.ensemble_size, 10);
  causal.ensemble_size = 0;
  const Eigen::VectorXd own =
      PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal);
  causal.ensemble_size = 10;
  EXPECT_EQ(PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal),
            own);
  causal.ensemble_size = 20;
  EXPECT_NE(PredictOneStep(model, log.rate, Eigen::VectorXd(), 500, Protocol::kCausal, causal),
            own);
}

// The H-step prediction of y[t] uses samples before t - H + 1 only (causal protocol, with the
// decomposition of trailing windows and the recursion): changing samples from c on leaves every
// prediction up to y[c + H - 1] unchanged to the bit.
TEST(DriftModel, PredictAheadIgnoresSamplesAfterItsOrigin) {
  const Log log = MakeLog(900, 7);
  const DriftModel model =
      FitDriftModel(log.rate.head(600), Eigen::VectorXd(), Fast(Mode::kPredict, Method::kMsElm));
  CausalOptions causal;
  causal.window = 128;
  causal.mirror = 1.0;  // the longest tail: the window's every sample but its end, reversed
  const int horizon = 5;
  const Eigen::VectorXd base =
      PredictAhead(model, log.rate, Eigen::VectorXd(), 600, horizon, Protocol::kCausal, causal);
  Eigen::VectorXd changed = log.rate;
  changed.tail(150).array() += 5.0;  // samples 750.. change
  const Eigen::VectorXd after =
      PredictAhead(model, changed, Eigen::VectorXd(), 600, horizon, Protocol::kCausal, causal);
  // y[t] for t <= 754 starts at t - 4 <= 750, from samples up to 749.
  EXPECT_EQ(base.head(155), after.head(155));
  EXPECT_NE(base.segment(155, 5), after.segment(155, 5));
  const Eigen::VectorXd one =
      PredictAhead(model, log.rate, Eigen::VectorXd(), 600, 1, Protocol::kCausal, causal);
  EXPECT_NE(base, one);
}

// The causal windows cannot resolve slow IMFs: a note names a sub-model that sums them (not the
// noise group, whose energy is in its first IMFs, nor the residue's), and the window that would;
// a window's mirrored tail counts in the series decomposed.
TEST(DriftModel, CausalWindowNoteNamesSubModelsTheWindowsCannotFeed) {
  DriftModel model;
  model.options.method = Method::kMsElm;
  model.sub_models = {{"noise", {1, 2, 3}, false, nullptr},
                      {"mixed", {4, 5, 6, 7, 8, 9, 10, 11, 12}, false, nullptr},
                      {"drift", {13}, true, nullptr}};
  const auto note = [&model](int window, double mirror, int windows = 1) {
    CausalOptions causal;
    causal.window = window;
    causal.mirror = mirror;
    causal.windows = windows;
    return CausalWindowNote(model, causal);
  };
  std::string text = note(512, 0.0);
  EXPECT_NE(text.find("a 512-sample causal window resolves about 8 IMFs; sub-model 'mixed' "
                      "(IMFs 4-12) holds slower ones"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("a window of 8192 samples would resolve them"), std::string::npos) << text;
  EXPECT_EQ(note(8192, 0.0), "");
  // 512 + 256 mirrored samples: 768, still 8 IMFs; 5461 + 2731 = 8192 samples resolve IMF 12
  // (5460 + 2730 do not). The window named is the least that does, whatever the tail's rounding.
  text = note(512, 0.5);
  EXPECT_NE(text.find("a 512-sample causal window (768 samples with its mirrored tail) resolves "
                      "about 8 IMFs"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("a window of 5461 samples would resolve them"), std::string::npos) << text;
  EXPECT_EQ(note(5461, 0.5), "");
  EXPECT_NE(note(5460, 0.5), "");
  const std::vector<std::pair<int, double>> odd = {{127, 0.5}, {17, 0.5}, {300, 1.0}, {999, 0.3}};
  for (const auto& [window, mirror] : odd) {
    text = note(window, mirror);
    const std::string said = "a window of ";
    const size_t at = text.find(said);
    ASSERT_NE(at, std::string::npos) << text;
    const int named = std::stoi(text.substr(at + said.size()));
    EXPECT_EQ(note(named, mirror), "") << window << ", " << mirror << ": " << text;
    EXPECT_NE(note(named - 1, mirror), "") << window << ", " << mirror << ": " << text;
  }
  // Several windows: the shortest (W/2) decides, and the W named is the least whose shortest does.
  text = note(1024, 0.5, 3);
  EXPECT_NE(text.find("the shortest of the 3 causal windows (512 samples; 768 samples with its "
                      "mirrored tail) resolves about 8 IMFs"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("window = 10921, the longest of the windows, would resolve them"),
            std::string::npos)
      << text;
  EXPECT_EQ(note(10921, 0.5, 3), "");  // its shortest: 5460.5, rounded to 5461
  EXPECT_NE(note(10920, 0.5, 3), "");
  model.sub_models = {{"noise", {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13}, false, nullptr},
                      {"drift", {}, true, nullptr}};
  EXPECT_EQ(note(512, 0.5), "");  // the default grouping on a 1 Hz FOG log
  model.options.method = Method::kElm;
  model.sub_models = {{"signal", {}, true, nullptr}};
  EXPECT_EQ(note(16, 0.5), "");
}

TEST(DriftModel, CausalPredictionsIgnoreTheFuture) {
  const Log log = MakeLog(900, 2);
  for (Method method : {Method::kMsElm, Method::kEmdElm, Method::kElm}) {
    const DriftModel model =
        FitDriftModel(log.rate.head(600), Eigen::VectorXd(), Fast(Mode::kPredict, method));
    CausalOptions causal;
    causal.window = 128;
    const Eigen::VectorXd base =
        PredictOneStep(model, log.rate, Eigen::VectorXd(), 600, Protocol::kCausal, causal);
    Eigen::VectorXd changed = log.rate;
    changed.tail(150).array() += 5.0;  // samples 750.. change
    const Eigen::VectorXd after =
        PredictOneStep(model, changed, Eigen::VectorXd(), 600, Protocol::kCausal, causal);
    // Predictions for t <= 750 use samples up to 749 only: unchanged to the bit.
    EXPECT_EQ(base.head(151), after.head(151)) << ToString(method);
    EXPECT_NE(base.tail(10), after.tail(10)) << ToString(method);
    if (UsesDecomposition(method)) {
      // The paper protocol decomposes the whole record: the same change leaks into earlier
      // predictions, which is exactly the leakage the causal protocol removes.
      const Eigen::VectorXd paper =
          PredictOneStep(model, log.rate, Eigen::VectorXd(), 600, Protocol::kPaper);
      const Eigen::VectorXd paper_changed =
          PredictOneStep(model, changed, Eigen::VectorXd(), 600, Protocol::kPaper);
      EXPECT_NE(paper.head(150), paper_changed.head(150)) << ToString(method);
    }
  }
}

TEST(CausalOptions, ValidateNamesTheWindowMirrorWindowsAndEnsembleOutsideTheirRanges) {
  // The option error's message, "" when the options are accepted.
  auto refusal = [](const CausalOptions& c) -> std::string {
    try {
      c.Validate();
    } catch (const OptionError& e) {
      return e.what();
    }
    return "";
  };
  const CausalOptions defaults;
  EXPECT_EQ(refusal(defaults), "");
  // Each field at both ends of its range (accepted) and just past them (refused, naming it).
  const auto expect_range = [&refusal](auto field, const std::string& name, double lowest,
                                       double highest, std::initializer_list<double> values) {
    for (double value : values) {
      CausalOptions c;
      c.*field = static_cast<std::remove_reference_t<decltype(c.*field)>>(value);
      const bool allowed = value >= lowest && value <= highest;
      const std::string message = refusal(c);
      EXPECT_TRUE(allowed ? message.empty() : message.find(name + " = ") != std::string::npos)
          << name << " " << value << ": " << message;
    }
  };
  expect_range(&CausalOptions::window, "window", 16, 1000000, {16, 1000000, 15, 1000001});
  expect_range(&CausalOptions::mirror, "mirror", 0.0, 1.0, {0.0, 1.0, -0.01, 1.01, std::nan("")});
  expect_range(&CausalOptions::windows, "windows", 1, 16, {1, 16, 0, 17});
  // 0 = the model's own ensemble.
  expect_range(&CausalOptions::ensemble_size, "ensemble_size", 0, 100000, {0, 100000, -1, 100001});
}

}  // namespace
}  // namespace gyrodrift::drift
