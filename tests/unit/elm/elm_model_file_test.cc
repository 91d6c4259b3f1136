// The ELM inside a model file: the thread count a model was fitted with is not part of it (the
// saved model is the same text for 1 and 2 threads), files that still carry the old ELM
// "threads" option load, and a loaded ELM predicts the same bits as the fitted one.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "gyrodrift/common/error.h"
#include "gyrodrift/common/random.h"
#include "gyrodrift/drift/drift_model.h"
#include "gyrodrift/io/model_file.h"

namespace gyrodrift::elm {
namespace {

using nlohmann::json;

struct Log {
  Eigen::VectorXd rate, temperature;
};

Log MakeLog(Eigen::Index n, std::uint64_t seed) {
  Log log{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  Rng rng(seed, 0);
  for (Eigen::Index t = 0; t < n; ++t) {
    const double x = static_cast<double>(t) / static_cast<double>(n);
    log.temperature[t] = 20.0 + 15.0 * std::sin(9.0 * x);
    log.rate[t] = 0.01 * log.temperature[t] + 0.3 * std::sin(20.0 * x) + 0.02 * rng.Normal();
  }
  return log;
}

drift::DriftOptions ElmOptionsWithThreads(int threads) {
  drift::DriftOptions o;
  o.mode = drift::Mode::kPredict;
  o.method = drift::Method::kElm;
  o.learner.elm.hidden_units = 30;
  o.seed = 5;
  o.threads = threads;
  return o;
}

const io::ModelFileInfo kInfo{"rate_dph", "", "train.csv", ""};

std::string Reseal(json j) {
  j.erase("checksum");
  char hex[17];
  std::snprintf(hex, sizeof(hex), "%016llx",
                static_cast<unsigned long long>(
                    io::Fnv1a64(j.dump(-1, ' ', false, json::error_handler_t::replace))));
  j["checksum"] = std::string("fnv1a64:") + hex;
  return j.dump(1);
}

TEST(ElmModelFile, SavedElmDoesNotDependOnTheThreadCount) {
  const Log log = MakeLog(5000, 1);  // two row blocks, so two threads really split the work
  const drift::DriftModel m1 =
      drift::FitDriftModel(log.rate, log.temperature, ElmOptionsWithThreads(1));
  const drift::DriftModel m2 =
      drift::FitDriftModel(log.rate, log.temperature, ElmOptionsWithThreads(2));
  const json j1 = json::parse(io::RenderModelFile(m1, kInfo));
  const json j2 = json::parse(io::RenderModelFile(m2, kInfo));
  // The fitted model, learner parameters included, is the same text.
  EXPECT_EQ(j1["model"], j2["model"]);
  EXPECT_FALSE(j1["options"]["learner"]["elm"].contains("threads"));
  const json& learner = j1["model"]["sub_models"][0]["learner"];
  ASSERT_EQ(learner["kind"], "elm");
  EXPECT_EQ(learner["scalars"]["threads"], 0);
}

TEST(ElmModelFile, RoundTripPredictsTheSameBits) {
  const Log log = MakeLog(800, 2);
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, ElmOptionsWithThreads(0));
  const io::LoadedModel loaded = io::ParseModelFile(io::RenderModelFile(model, kInfo), "m.json");
  const Log test = MakeLog(300, 3);
  const Eigen::VectorXd a =
      drift::PredictOneStep(model, test.rate, Eigen::VectorXd(), 20, drift::Protocol::kPaper);
  const Eigen::VectorXd b = drift::PredictOneStep(loaded.model, test.rate, Eigen::VectorXd(), 20,
                                                  drift::Protocol::kPaper);
  ASSERT_TRUE(a.allFinite());
  EXPECT_EQ(a, b);  // bit for bit
}

TEST(ElmModelFile, OlderFilesWithTheElmThreadCountStillLoad) {
  const Log log = MakeLog(400, 4);
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, ElmOptionsWithThreads(0));
  json j = json::parse(io::RenderModelFile(model, kInfo));
  j["options"]["learner"]["elm"]["threads"] = 2;
  const io::LoadedModel loaded = io::ParseModelFile(Reseal(j), "m.json");
  EXPECT_EQ(loaded.model.options.learner.elm.threads, 0);
  j["options"]["learner"]["elm"]["threads"] = -3;
  try {
    io::ParseModelFile(Reseal(j), "m.json");
    ADD_FAILURE() << "a negative thread count was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("options.learner.elm.threads"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace gyrodrift::elm
