// Private to the learner implementation: data checks, Parameters access with DataError
// messages, and one Fit/Load pair per learner kind (learner_<kind>.cc).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <string_view>

#include "gyrodrift/drift/learner.h"
#include "gyrodrift/elm/elm.h"

namespace gyrodrift::drift::internal {

// Largest number of monomials the polynomial learner accepts (its design matrix is N x terms
// and the QR costs N terms^2).
constexpr long kMaxPolyTerms = 5000;

// "%.4g", for one-line summaries.
std::string FormatShort(double value);

// Throws DataError "<what> row r column c is <v>: every value must be finite" (1-based).
void RequireFiniteRows(std::string_view what, const Eigen::Ref<const Eigen::MatrixXd>& m);

// Checks the rows given to Learner::Predict: the column count and finite values.
void CheckPredictInput(LearnerKind kind, int num_inputs,
                       const Eigen::Ref<const Eigen::MatrixXd>& x);

// Root mean square of a - b.
double Rmse(const Eigen::Ref<const Eigen::VectorXd>& a, const Eigen::Ref<const Eigen::VectorXd>& b);

// Named-field access to a Parameters with DataError messages that name the learner kind and
// the field. Array shape -1 means any size (at least 1).
class ParameterReader {
 public:
  ParameterReader(LearnerKind kind, const Parameters& parameters);
  const Eigen::MatrixXd& Array(const std::string& name, Eigen::Index rows, Eigen::Index cols,
                               bool allow_empty = false) const;
  double Scalar(const std::string& name) const;
  // A scalar that must be an integer in [lo, hi].
  long Integer(const std::string& name, long lo, long hi) const;
  const std::string& Text(const std::string& name) const;
  std::uint64_t Seed() const;  // texts["seed"], decimal
  // Learners saved before model format 6 kept the fit's thread count as the scalar "threads":
  // checked (an integer in [0, 1024]) if present, and dropped, since it changes no result.
  void DropLegacyThreads() const;
  [[noreturn]] void Fail(const std::string& what) const;

 private:
  LearnerKind kind_;
  const Parameters& parameters_;
};

// Scalers as arrays <prefix>_mean and <prefix>_scale (1 x columns).
void PutScaler(const std::string& prefix, const elm::Standardizer& scaler, Parameters* out);
elm::Standardizer GetScaler(const ParameterReader& reader, const std::string& prefix,
                            Eigen::Index columns);

// Fields every learner saves: kind, seed (text, exact for 64 bits), training rows and RMSE.
void PutCommon(LearnerKind kind, std::uint64_t seed, int rows, double train_rmse, Parameters* out);

// `threads` as Execution::threads (FitLearner has checked it).
std::unique_ptr<Learner> FitElm(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const LearnerOptions& options, int threads);
std::unique_ptr<Learner> LoadElm(const ParameterReader& reader);

std::unique_ptr<Learner> FitPoly(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                 const Eigen::Ref<const Eigen::VectorXd>& y,
                                 const LearnerOptions& options);
std::unique_ptr<Learner> LoadPoly(const ParameterReader& reader);

std::unique_ptr<Learner> FitSvr(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const LearnerOptions& options, int threads);
std::unique_ptr<Learner> LoadSvr(const ParameterReader& reader);

std::unique_ptr<Learner> FitBp(const Eigen::Ref<const Eigen::MatrixXd>& x,
                               const Eigen::Ref<const Eigen::VectorXd>& y,
                               const LearnerOptions& options);
std::unique_ptr<Learner> LoadBp(const ParameterReader& reader);

}  // namespace gyrodrift::drift::internal
