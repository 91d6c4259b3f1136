// The ELM inside a model file: the thread count a model was fitted with is not part of it (the
// saved model is the same text for 1 and 2 threads), files of format 5 and older that still carry
// thread counts load, and a loaded ELM predicts the same bits as the fitted one.
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

drift::DriftOptions ElmDriftOptions() {
  drift::DriftOptions o;
  o.mode = drift::Mode::kPredict;
  o.method = drift::Method::kElm;
  o.learner.elm.hidden_units = 30;
  o.seed = 5;
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
      drift::FitDriftModel(log.rate, log.temperature, ElmDriftOptions(), {}, {.threads = 1});
  const drift::DriftModel m2 =
      drift::FitDriftModel(log.rate, log.temperature, ElmDriftOptions(), {}, {.threads = 2});
  // The whole file, learner parameters included, is the same text.
  const std::string text = io::RenderModelFile(m1, kInfo);
  EXPECT_EQ(text, io::RenderModelFile(m2, kInfo));
  EXPECT_EQ(text.find("threads"), std::string::npos);
  const json j = json::parse(text);
  EXPECT_EQ(j["model"]["sub_models"][0]["learner"]["kind"], "elm");
}

TEST(ElmModelFile, RoundTripPredictsTheSameBits) {
  const Log log = MakeLog(800, 2);
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, ElmDriftOptions());
  const io::LoadedModel loaded = io::ParseModelFile(io::RenderModelFile(model, kInfo), "m.json");
  EXPECT_EQ(loaded.model.options, model.options);
  const Log test = MakeLog(300, 3);
  const Eigen::VectorXd a =
      drift::PredictOneStep(model, test.rate, Eigen::VectorXd(), 20, drift::Protocol::kPaper);
  const Eigen::VectorXd b = drift::PredictOneStep(loaded.model, test.rate, Eigen::VectorXd(), 20,
                                                  drift::Protocol::kPaper);
  ASSERT_TRUE(a.allFinite());
  EXPECT_EQ(a, b);  // bit for bit
}

// Format 5 and older stored thread counts (model_file.h): such a file loads, the counts checked
// and dropped; from format 6 on a thread count is an unknown field.
TEST(ElmModelFile, Format5FilesWithThreadCountsStillLoad) {
  const Log log = MakeLog(400, 4);
  const drift::DriftModel model =
      drift::FitDriftModel(log.rate, log.temperature, ElmDriftOptions());
  json j = json::parse(io::RenderModelFile(model, kInfo));
  json& o = j["options"];
  for (json* at : {&o, &o["decomposition"], &o["selection"], &o["selection"]["monte_carlo"],
                   &o["learner"], &o["learner"]["elm"]}) {
    (*at)["threads"] = 2;
  }
  j["model"]["sub_models"][0]["learner"]["scalars"]["threads"] = 2;
  j["format_version"] = 5;
  const io::LoadedModel loaded = io::ParseModelFile(Reseal(j), "m.json");
  EXPECT_EQ(loaded.model.options, model.options);
  const Log test = MakeLog(300, 5);
  EXPECT_EQ(drift::PredictOneStep(model, test.rate, Eigen::VectorXd(), 20, drift::Protocol::kPaper),
            drift::PredictOneStep(loaded.model, test.rate, Eigen::VectorXd(), 20,
                                  drift::Protocol::kPaper));
  j["options"]["learner"]["elm"]["threads"] = -3;
  try {
    io::ParseModelFile(Reseal(j), "m.json");
    ADD_FAILURE() << "a negative thread count was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("options.learner.elm.threads"), std::string::npos)
        << e.what();
  }
  j["options"]["learner"]["elm"]["threads"] = 2;
  j["format_version"] = io::kModelFormatVersion;
  try {
    io::ParseModelFile(Reseal(j), "m.json");
    ADD_FAILURE() << "a format-6 file with a thread count was accepted";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("threads' is not part of"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace gyrodrift::elm
