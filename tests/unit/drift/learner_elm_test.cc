// The ELM learner (learner_elm.cc), the adapter MS-ELM fits once per sub-series: it is elm::Fit
// with the learner's seed, its saved state is the whole ElmModel so a loaded learner predicts
// the same bits (every activation and solver, auto selection, C = inf), the seed reproduces for
// any thread count and other seeds differ, and Load checks what it reads.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gyrodrift/common/error.h"
#include "gyrodrift/drift/learner.h"
#include "gyrodrift/elm/elm.h"
#include "unit/drift/learner_fixtures.h"

namespace gyrodrift::drift {
namespace {

using fixtures::Data;
using fixtures::OptionsOf;
using fixtures::SameBits;
using fixtures::SineBowl;

TEST(LearnerElm, ElmUsesTheLearnerSeedAndAutoSelection) {
  const Data train = SineBowl(300, 0.05, 13);
  LearnerOptions o = OptionsOf(LearnerKind::kElm);
  o.seed = 21;
  o.elm.seed = 99;  // overridden by o.seed
  o.elm.hidden_units = 50;
  o.elm.selection = elm::Selection::kAuto;
  const auto learner = FitLearner(train.x, train.y, o);
  const Parameters p = learner->Save();
  EXPECT_EQ(p.texts.at("seed"), "21");
  EXPECT_EQ(p.texts.at("selection"), "auto");
  EXPECT_LE(p.scalars.at("hidden_units"), 50.0);
  EXPECT_NE(learner->Summary().find("auto"), std::string::npos);
  const Data test = SineBowl(100, 0.0, 14);
  EXPECT_LT(fixtures::Rmse(learner->Predict(test.x), test.truth), 0.1);
}

// The learner is elm::Fit on the same rows with options.elm and the learner's seed: the same
// weights, scalers and predictions to the bit.
TEST(LearnerElm, IsTheElmFitWithTheLearnerSeed) {
  const Data train = SineBowl(250, 0.05, 61);
  const Data test = SineBowl(80, 0.0, 62);
  LearnerOptions o = OptionsOf(LearnerKind::kElm);
  o.seed = 8;
  o.elm.hidden_units = 17;
  o.elm.activation = elm::Activation::kTanh;
  o.elm.ridge_c = 1e3;
  const auto learner = FitLearner(train.x, train.y, o);
  elm::ElmOptions direct = o.elm;
  direct.seed = 8;
  const elm::ElmFit fit = elm::Fit(train.x, train.y, direct);
  const Parameters p = learner->Save();
  EXPECT_TRUE(SameBits(p.arrays.at("input_weights"), fit.model.input_weights));
  EXPECT_TRUE(SameBits(p.arrays.at("biases"), fit.model.biases));
  EXPECT_TRUE(SameBits(p.arrays.at("output_weights"), fit.model.output_weights));
  EXPECT_TRUE(SameBits(p.arrays.at("input_mean"), fit.model.input_scaler.mean));
  EXPECT_TRUE(SameBits(p.arrays.at("target_scale"), fit.model.target_scaler.scale));
  EXPECT_TRUE(SameBits(learner->Predict(test.x), elm::Predict(fit.model, test.x).col(0)));
  EXPECT_EQ(p.scalars.at("train_rmse"), fit.report.train_rmse);
  EXPECT_EQ(p.texts.at("activation"), "tanh");
  EXPECT_EQ(p.scalars.at("ridge_c"), 1e3);
  EXPECT_EQ(p.scalars.at("train_rows"), 250.0);
}

// Every activation and both solvers, including C = inf with QR (saved as +inf) and an auto
// selection that keeps fewer units than its largest candidate: the loaded learner predicts the
// same bits, and its state saves back unchanged.
TEST(LearnerElm, SaveLoadRoundTripForEveryConfiguration) {
  const Data train = SineBowl(200, 0.05, 63);
  const Data test = SineBowl(60, 0.0, 64);
  std::vector<LearnerOptions> configurations;
  for (elm::Activation a :
       {elm::Activation::kSigmoid, elm::Activation::kTanh, elm::Activation::kSine,
        elm::Activation::kRbf, elm::Activation::kLinear}) {
    LearnerOptions o = OptionsOf(LearnerKind::kElm);
    o.elm.activation = a;
    configurations.push_back(o);
  }
  LearnerOptions qr = OptionsOf(LearnerKind::kElm);
  qr.elm.solver = elm::Solver::kQr;
  qr.elm.ridge_c = std::numeric_limits<double>::infinity();
  configurations.push_back(qr);
  LearnerOptions automatic = OptionsOf(LearnerKind::kElm);
  automatic.elm.hidden_units = 100;
  automatic.elm.selection = elm::Selection::kAuto;
  automatic.elm.hidden_unit_candidates = {5, 100};
  configurations.push_back(automatic);
  for (const LearnerOptions& o : configurations) {
    const std::string label = std::string(elm::ToString(o.elm.activation)) + " " +
                              std::string(elm::ToString(o.elm.solver)) + " " +
                              std::string(elm::ToString(o.elm.selection));
    const auto learner = FitLearner(train.x, train.y, o);
    const Parameters saved = learner->Save();
    const auto loaded = LoadLearner(LearnerKind::kElm, saved);
    EXPECT_TRUE(SameBits(learner->Predict(test.x), loaded->Predict(test.x))) << label;
    EXPECT_EQ(loaded->Summary(), learner->Summary()) << label;
    const Parameters again = loaded->Save();
    EXPECT_EQ(again.texts, saved.texts) << label;
    EXPECT_EQ(again.scalars, saved.scalars) << label;
    for (const auto& [name, a] : saved.arrays) {
      EXPECT_TRUE(SameBits(a, again.arrays.at(name))) << label << " " << name;
    }
    if (o.elm.selection == elm::Selection::kAuto) {
      EXPECT_EQ(static_cast<double>(saved.arrays.at("input_weights").cols()),
                saved.scalars.at("hidden_units"));
      EXPECT_TRUE(saved.scalars.at("hidden_units") == 5.0 ||
                  saved.scalars.at("hidden_units") == 100.0);
    }
    if (o.elm.solver == elm::Solver::kQr) {
      EXPECT_TRUE(std::isinf(saved.scalars.at("ridge_c"))) << label;
    }
  }
}

// Same seed: the same hidden units and output weights to the bit with 1 or 2 threads (6000 rows
// are two row blocks, so two threads really split the work); other seeds: other units.
TEST(LearnerElm, SeedReproducesForAnyThreadCountAndDifferentSeedsDiffer) {
  const Data train = SineBowl(6000, 0.05, 11);
  const Data test = SineBowl(100, 0.0, 12);
  LearnerOptions o = OptionsOf(LearnerKind::kElm);
  o.seed = 5;
  const auto a = FitLearner(train.x, train.y, o, {.threads = 2});
  const auto b = FitLearner(train.x, train.y, o, {.threads = 1});
  o.seed = 6;
  const auto c = FitLearner(train.x, train.y, o);
  const Parameters pa = a->Save(), pb = b->Save(), pc = c->Save();
  for (const char* name : {"input_weights", "biases", "output_weights"}) {
    EXPECT_TRUE(SameBits(pa.arrays.at(name), pb.arrays.at(name))) << name;
  }
  EXPECT_FALSE(SameBits(pa.arrays.at("input_weights"), pc.arrays.at("input_weights")));
  EXPECT_TRUE(SameBits(a->Predict(test.x), b->Predict(test.x)));
  EXPECT_GT((a->Predict(test.x) - c->Predict(test.x)).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(LearnerElm, LoadRejectsInconsistentParameters) {
  const Data train = SineBowl(80, 0.05, 65);
  const Parameters saved = FitLearner(train.x, train.y, OptionsOf(LearnerKind::kElm))->Save();
  EXPECT_NO_THROW(LoadLearner(LearnerKind::kElm, saved));
  Parameters units = saved;
  units.scalars["hidden_units"] = 19;  // input_weights has 20 columns
  EXPECT_THROW(LoadLearner(LearnerKind::kElm, units), DataError);
  for (const char* text : {"activation", "solver", "selection"}) {
    Parameters bad = saved;
    bad.texts[text] = "relu";
    EXPECT_THROW(LoadLearner(LearnerKind::kElm, bad), DataError) << text;
  }
  Parameters ridge = saved;
  ridge.scalars["ridge_c"] = 0.0;
  EXPECT_THROW(LoadLearner(LearnerKind::kElm, ridge), DataError);
  Parameters scale = saved;
  scale.arrays["input_scale"](0, 1) = 0.0;
  EXPECT_THROW(LoadLearner(LearnerKind::kElm, scale), DataError);
  Parameters threads = saved;
  threads.scalars["threads"] = 2000;  // a legacy thread count is checked before it is dropped
  EXPECT_THROW(LoadLearner(LearnerKind::kElm, threads), DataError);
}

}  // namespace
}  // namespace gyrodrift::drift
