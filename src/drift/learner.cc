#include "gyrodrift/drift/learner.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <utility>

#include "common/enum_names.h"
#include "drift/learner_kinds.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift {
namespace {

constexpr std::array<std::pair<LearnerKind, std::string_view>, 4> kKinds{{
    {LearnerKind::kElm, "elm"},
    {LearnerKind::kPoly, "poly"},
    {LearnerKind::kSvr, "svr"},
    {LearnerKind::kBp, "bp"},
}};

constexpr int kMaxBpLayers = 3;
constexpr int kMaxBpUnits = 1000;
constexpr int kMaxBpEpochs = 100000;
constexpr int kMaxSvrRows = 1000000;

void CheckTrainingData(const Eigen::Ref<const Eigen::MatrixXd>& x,
                       const Eigen::Ref<const Eigen::VectorXd>& y) {
  if (x.rows() != y.size()) {
    throw DataError("inputs have " + std::to_string(x.rows()) + " rows but targets have " +
                    std::to_string(y.size()) + ": the row counts must match");
  }
  if (x.rows() < 2) {
    throw DataError("training data has " + std::to_string(x.rows()) +
                    " rows: at least 2 are needed");
  }
  if (x.cols() < 1) throw DataError("inputs have no columns: at least 1 is needed");
  internal::RequireFiniteRows("inputs", x);
  internal::RequireFiniteRows("targets", y);
}

}  // namespace

std::string_view ToString(LearnerKind kind) { return gyrodrift::internal::EnumName(kind, kKinds); }

LearnerKind LearnerKindFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "learner", kKinds);
}

void LearnerOptions::Validate() const {
  elm::ElmOptions elm_options = elm;
  elm_options.seed = seed;
  ValidateNested("elm", [&] { elm_options.Validate(); });
  if (poly_degree < 1 || poly_degree > 4) {
    ThrowOption("poly_degree", std::to_string(poly_degree), "an integer in [1, 4]");
  }
  RequireInRange("poly_ridge", poly_ridge, 0.0, 1.0);
  RequirePositive("svr_c", svr_c);
  RequireNonNegative("svr_epsilon", svr_epsilon);
  if (!(svr_gamma >= 0.0) || !std::isfinite(svr_gamma)) {
    ThrowOption("svr_gamma", FormatValue(svr_gamma), "a finite number > 0, or 0 for 1 / #inputs");
  }
  if (svr_max_rows < 2 || svr_max_rows > kMaxSvrRows) {
    ThrowOption("svr_max_rows", std::to_string(svr_max_rows),
                "an integer in [2, " + std::to_string(kMaxSvrRows) + "]");
  }
  if (bp_hidden.empty() || bp_hidden.size() > static_cast<size_t>(kMaxBpLayers)) {
    ThrowOption("bp_hidden", std::to_string(bp_hidden.size()) + " layers",
                "1 to " + std::to_string(kMaxBpLayers) + " hidden layers");
  }
  for (int units : bp_hidden) {
    if (units < 1 || units > kMaxBpUnits) {
      ThrowOption("bp_hidden", std::to_string(units),
                  "layer sizes in [1, " + std::to_string(kMaxBpUnits) + "]");
    }
  }
  if (bp_epochs < 1 || bp_epochs > kMaxBpEpochs) {
    ThrowOption("bp_epochs", std::to_string(bp_epochs),
                "an integer in [1, " + std::to_string(kMaxBpEpochs) + "]");
  }
  RequireNonNegative("bp_desired_mse", bp_desired_mse);
}

std::unique_ptr<Learner> FitLearner(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                    const Eigen::Ref<const Eigen::VectorXd>& y,
                                    const LearnerOptions& options, const Execution& execution) {
  options.Validate();
  execution.Validate();
  CheckTrainingData(x, y);
  switch (options.kind) {
    case LearnerKind::kElm:
      return internal::FitElm(x, y, options, execution.threads);
    case LearnerKind::kPoly:
      return internal::FitPoly(x, y, options);
    case LearnerKind::kSvr:
      return internal::FitSvr(x, y, options, execution.threads);
    case LearnerKind::kBp:
      return internal::FitBp(x, y, options);
  }
  ThrowOption("kind", std::to_string(static_cast<int>(options.kind)), "elm, poly, svr or bp");
}

std::unique_ptr<Learner> LoadLearner(LearnerKind kind, const Parameters& parameters) {
  const internal::ParameterReader reader(kind, parameters);
  if (reader.Text("kind") != ToString(kind)) {
    reader.Fail("kind is '" + reader.Text("kind") + "', expected '" + std::string(ToString(kind)) +
                "'");
  }
  switch (kind) {
    case LearnerKind::kElm:
      return internal::LoadElm(reader);
    case LearnerKind::kPoly:
      return internal::LoadPoly(reader);
    case LearnerKind::kSvr:
      return internal::LoadSvr(reader);
    case LearnerKind::kBp:
      return internal::LoadBp(reader);
  }
  throw DataError("learner parameters: unknown learner kind " +
                  std::to_string(static_cast<int>(kind)));
}

namespace internal {

std::string FormatShort(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.4g", value);
  return buffer;
}

void RequireFiniteRows(std::string_view what, const Eigen::Ref<const Eigen::MatrixXd>& m) {
  if (m.allFinite()) return;
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) {
      if (!std::isfinite(m(i, j))) {
        std::string where = std::string(what) + " row " + std::to_string(i + 1);
        if (m.cols() > 1) where += " column " + std::to_string(j + 1);
        throw DataError(where + " is " + FormatValue(m(i, j)) + ": every value must be finite");
      }
    }
  }
}

void CheckPredictInput(LearnerKind kind, int num_inputs,
                       const Eigen::Ref<const Eigen::MatrixXd>& x) {
  if (x.cols() != num_inputs) {
    throw DataError("inputs have " + std::to_string(x.cols()) + " columns but the " +
                    std::string(ToString(kind)) + " learner has " + std::to_string(num_inputs) +
                    " inputs");
  }
  RequireFiniteRows("inputs", x);
}

double Rmse(const Eigen::Ref<const Eigen::VectorXd>& a,
            const Eigen::Ref<const Eigen::VectorXd>& b) {
  if (a.size() == 0) return 0.0;
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(a.size()));
}

ParameterReader::ParameterReader(LearnerKind kind, const Parameters& parameters)
    : kind_(kind), parameters_(parameters) {}

void ParameterReader::Fail(const std::string& what) const {
  throw DataError("learner parameters (" + std::string(ToString(kind_)) + "): " + what);
}

const Eigen::MatrixXd& ParameterReader::Array(const std::string& name, Eigen::Index rows,
                                              Eigen::Index cols, bool allow_empty) const {
  const auto it = parameters_.arrays.find(name);
  if (it == parameters_.arrays.end()) Fail("array '" + name + "' is missing");
  const Eigen::MatrixXd& a = it->second;
  auto dim = [](Eigen::Index n) { return n < 0 ? std::string("n") : std::to_string(n); };
  if ((rows >= 0 && a.rows() != rows) || (cols >= 0 && a.cols() != cols) ||
      (a.size() == 0 && !allow_empty)) {
    Fail("array '" + name + "' is " + std::to_string(a.rows()) + " x " + std::to_string(a.cols()) +
         ", expected " + dim(rows) + " x " + dim(cols) + (allow_empty ? "" : " (non-empty)"));
  }
  if (!a.allFinite()) Fail("array '" + name + "' has a value that is not finite");
  return a;
}

double ParameterReader::Scalar(const std::string& name) const {
  const auto it = parameters_.scalars.find(name);
  if (it == parameters_.scalars.end()) Fail("scalar '" + name + "' is missing");
  return it->second;
}

long ParameterReader::Integer(const std::string& name, long lo, long hi) const {
  const double v = Scalar(name);
  if (!(v >= static_cast<double>(lo) && v <= static_cast<double>(hi)) || v != std::floor(v)) {
    Fail("scalar '" + name + "' = " + FormatValue(v) + " is not an integer in [" +
         std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
  return static_cast<long>(v);
}

const std::string& ParameterReader::Text(const std::string& name) const {
  const auto it = parameters_.texts.find(name);
  if (it == parameters_.texts.end()) Fail("text '" + name + "' is missing");
  return it->second;
}

void ParameterReader::DropLegacyThreads() const {
  if (parameters_.scalars.count("threads") != 0) Integer("threads", 0, 1024);
}

std::uint64_t ParameterReader::Seed() const {
  const std::string& text = Text("seed");
  std::uint64_t seed = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), seed);
  if (ec != std::errc() || end != text.data() + text.size() || text.empty()) {
    Fail("seed '" + text + "' is not a decimal 64-bit unsigned integer");
  }
  return seed;
}

void PutScaler(const std::string& prefix, const elm::Standardizer& scaler, Parameters* out) {
  out->arrays[prefix + "_mean"] = scaler.mean;
  out->arrays[prefix + "_scale"] = scaler.scale;
}

elm::Standardizer GetScaler(const ParameterReader& reader, const std::string& prefix,
                            Eigen::Index columns) {
  elm::Standardizer s;
  s.mean = reader.Array(prefix + "_mean", 1, columns);
  s.scale = reader.Array(prefix + "_scale", 1, columns);
  if (!(s.scale.array() > 0.0).all()) reader.Fail(prefix + "_scale has an entry <= 0");
  return s;
}

void PutCommon(LearnerKind kind, std::uint64_t seed, int rows, double train_rmse, Parameters* out) {
  out->texts["kind"] = std::string(ToString(kind));
  out->texts["seed"] = std::to_string(seed);
  out->scalars["train_rows"] = rows;
  out->scalars["train_rmse"] = train_rmse;
}

}  // namespace internal
}  // namespace gyrodrift::drift
