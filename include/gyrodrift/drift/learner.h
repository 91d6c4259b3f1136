// Regression learners behind one interface: the unit MS-ELM, EMD-ELM and the single-model
// baselines the field compares against are built from.
//
//   kElm   extreme learning machine (elm.h; Huang, Zhu & Siew 2006), ridge output weights
//   kPoly  polynomial least squares in the standardised inputs, all monomials up to `degree`
//          (degree 1 on lags is an AR model; on temperature and its rate the classic
//          thermal-drift polynomial), tiny ridge for conditioning, solved by QR
//   kSvr   epsilon-support-vector regression, RBF kernel (libsvm; Chang & Lin, ACM TIST 2011)
//   kBp    back-propagation multilayer perceptron (FANN; Nissen 2003), RPROP training
// Every learner standardises inputs and target on the training rows only and stores the
// scalers. A fitted learner exports itself as Parameters (named arrays, scalars and texts), so
// the io module writes any kind to a model file without knowing it, and LoadLearner rebuilds it
// with predictions identical to the bit.
// Single output: y is a vector. Units: predictions in the units of y. Fits run on the execution's
// threads (kElm, kSvr); no result depends on them, so a learner's Parameters do not hold them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "gyrodrift/common/execution.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::drift {

enum class LearnerKind { kElm, kPoly, kSvr, kBp };
std::string_view ToString(LearnerKind kind);
LearnerKind LearnerKindFromString(std::string_view name);  // "elm", "poly", "svr", "bp"

struct LearnerOptions {
  LearnerKind kind = LearnerKind::kElm;
  elm::ElmOptions elm;  // kElm (seed below overrides elm.seed)
  // kPoly: total degree in [1, 4]; ridge in [0, 1] on the standardised problem.
  int poly_degree = 2;
  double poly_ridge = 1e-10;
  // kSvr: C > 0, epsilon >= 0 (standardised target units), gamma > 0 or 0 for 1 / #inputs;
  // at most svr_max_rows training rows (evenly spaced) keep the O(N^2) kernel solver in check.
  double svr_c = 10.0;
  double svr_epsilon = 0.05;
  double svr_gamma = 0.0;
  int svr_max_rows = 4000;
  // kBp: hidden layer sizes (each in [1, 1000], 1 to 3 layers), RPROP epochs in [1, 100000],
  // stop early at this training MSE (standardised units).
  std::vector<int> bp_hidden{10};
  int bp_epochs = 300;
  double bp_desired_mse = 1e-4;
  std::uint64_t seed = 1;
  void Validate() const;  // throws UsageError "<field> = <value>: must be <rule>"
  bool operator==(const LearnerOptions&) const = default;
};

// A fitted learner's state, for model files.
struct Parameters {
  std::map<std::string, Eigen::MatrixXd> arrays;
  std::map<std::string, double> scalars;
  std::map<std::string, std::string> texts;
};

class Learner {
 public:
  virtual ~Learner() = default;
  virtual LearnerKind kind() const = 0;
  virtual int num_inputs() const = 0;
  // Predictions for the rows of x (N x num_inputs). Throws DataError on a wrong column count or
  // a non-finite value.
  virtual Eigen::VectorXd Predict(const Eigen::Ref<const Eigen::MatrixXd>& x) const = 0;
  virtual Parameters Save() const = 0;
  virtual std::string Summary() const = 0;  // one line: kind, size, training error
};

// Fits a learner of options.kind on rows x (N x d) and targets y (N) on execution.threads workers
// (its progress is not called; an SVR also predicts on them, a loaded one on every core). Throws
// UsageError (bad options or threads) or DataError (mismatched rows, too few rows, non-finite
// values).
std::unique_ptr<Learner> FitLearner(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                    const Eigen::Ref<const Eigen::VectorXd>& y,
                                    const LearnerOptions& options, const Execution& execution = {});

// Rebuilds a learner from Save()'s output. Throws DataError naming what is missing or malformed.
std::unique_ptr<Learner> LoadLearner(LearnerKind kind, const Parameters& parameters);

}  // namespace gyrodrift::drift
