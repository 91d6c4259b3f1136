// kPoly: least squares on every monomial of the standardised inputs up to a total degree.
//
// With z = standardised inputs (d columns) and exponent rows e_k (sum_j e_kj <= degree),
//   y_s = sum_k c_k prod_j z_j^e_kj,   c = argmin ||Phi c - y_s||^2 + ridge ||c||^2,
// solved by column-pivoting Householder QR of [Phi; sqrt(ridge) I] (of Phi alone when
// ridge = 0), never the normal equations, whose condition number is the square of Phi's.
// Standardising first keeps the powers of order one, so Phi is far better conditioned than
// with raw temperatures in degrees C. Terms: C(d + degree, degree); cost O(N terms^2).
#include <Eigen/QR>
#include <cmath>
#include <utility>
#include <vector>

#include "drift/learner_kinds.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::drift::internal {
namespace {

// C(d + degree, degree), or kMaxPolyTerms + 1 once it exceeds the cap (no overflow).
long CountTerms(long d, int degree) {
  long count = 1;
  for (int k = 1; k <= degree; ++k) {
    count = count * (d + k) / k;  // exact: a product of k consecutive integers / k!
    if (count > kMaxPolyTerms) return kMaxPolyTerms + 1;
  }
  return count;
}

// Exponent rows in graded order: degree 0, then every degree-1 term, ... Within a degree,
// the exponents of the first input count down, so degree 1 lists z_1, z_2, ..., z_d.
Eigen::MatrixXi MakeExponents(int d, int degree) {
  std::vector<Eigen::RowVectorXi> rows;
  Eigen::RowVectorXi e = Eigen::RowVectorXi::Zero(d);
  // Distributes `left` over inputs j..d-1.
  auto fill = [&](auto&& self, int j, int left) -> void {
    if (j == d - 1) {
      e[j] = left;
      rows.push_back(e);
      return;
    }
    for (int k = left; k >= 0; --k) {
      e[j] = k;
      self(self, j + 1, left - k);
    }
    e[j] = 0;
  };
  for (int total = 0; total <= degree; ++total) fill(fill, 0, total);
  Eigen::MatrixXi out(static_cast<Eigen::Index>(rows.size()), d);
  for (size_t k = 0; k < rows.size(); ++k) out.row(static_cast<Eigen::Index>(k)) = rows[k];
  return out;
}

// Row of monomials of one standardised input row z. `powers` (d x (degree + 1)) is scratch.
// A template so that strided rows of column-major matrices are used in place (no copies).
template <class Z, class Out>
void Monomials(const Eigen::MatrixXi& exponents, const Z& z, Eigen::MatrixXd& powers, Out&& out) {
  const Eigen::Index d = exponents.cols();
  for (Eigen::Index j = 0; j < d; ++j) {
    powers(j, 0) = 1.0;
    for (Eigen::Index p = 1; p < powers.cols(); ++p) powers(j, p) = powers(j, p - 1) * z[j];
  }
  for (Eigen::Index k = 0; k < exponents.rows(); ++k) {
    double term = 1.0;
    for (Eigen::Index j = 0; j < d; ++j) term *= powers(j, exponents(k, j));
    out[k] = term;
  }
}

class PolyLearner final : public Learner {
 public:
  PolyLearner(int degree, Eigen::MatrixXi exponents, Eigen::VectorXd coefficients,
              elm::Standardizer input_scaler, elm::Standardizer target_scaler, double ridge,
              int rank, std::uint64_t seed)
      : degree_(degree),
        exponents_(std::move(exponents)),
        coefficients_(std::move(coefficients)),
        input_scaler_(std::move(input_scaler)),
        target_scaler_(std::move(target_scaler)),
        ridge_(ridge),
        rank_(rank),
        seed_(seed) {}

  LearnerKind kind() const override { return LearnerKind::kPoly; }
  int num_inputs() const override { return static_cast<int>(exponents_.cols()); }

  Eigen::VectorXd Predict(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    CheckPredictInput(kind(), num_inputs(), x);
    const Eigen::MatrixXd z = input_scaler_.Apply(x);
    Eigen::MatrixXd powers(num_inputs(), degree_ + 1);
    Eigen::RowVectorXd row(exponents_.rows());
    Eigen::VectorXd y(x.rows());
    for (Eigen::Index i = 0; i < x.rows(); ++i) {
      Monomials(exponents_, z.row(i), powers, row);
      y[i] = row.dot(coefficients_) * target_scaler_.scale[0] + target_scaler_.mean[0];
    }
    return y;
  }

  Parameters Save() const override {
    Parameters p;
    PutCommon(kind(), seed_, rows_, train_rmse_, &p);
    p.arrays["exponents"] = exponents_.cast<double>();
    p.arrays["coefficients"] = coefficients_;
    PutScaler("input", input_scaler_, &p);
    PutScaler("target", target_scaler_, &p);
    p.scalars["degree"] = degree_;
    p.scalars["ridge"] = ridge_;
    p.scalars["rank"] = rank_;
    return p;
  }

  std::string Summary() const override {
    std::string s = "poly: " + std::to_string(num_inputs()) + " inputs, degree " +
                    std::to_string(degree_) + ", " + std::to_string(exponents_.rows()) + " terms";
    if (rank_ < exponents_.rows()) s += " (rank " + std::to_string(rank_) + ")";
    return s + ", ridge " + FormatShort(ridge_) + ", " + std::to_string(rows_) +
           " rows, train RMSE " + FormatShort(train_rmse_);
  }

  void SetTraining(int rows, double train_rmse) {
    rows_ = rows;
    train_rmse_ = train_rmse;
  }

 private:
  int degree_;
  Eigen::MatrixXi exponents_;     // terms x d
  Eigen::VectorXd coefficients_;  // terms, standardised target units
  elm::Standardizer input_scaler_;
  elm::Standardizer target_scaler_;
  double ridge_;
  int rank_;
  std::uint64_t seed_;  // unused by the fit; kept so every learner's metadata has one
  int rows_ = 0;
  double train_rmse_ = 0.0;
};

}  // namespace

std::unique_ptr<Learner> FitPoly(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                 const Eigen::Ref<const Eigen::VectorXd>& y,
                                 const LearnerOptions& options) {
  const int d = static_cast<int>(x.cols());
  const int degree = options.poly_degree;
  const long terms = CountTerms(d, degree);
  if (terms > kMaxPolyTerms) {
    ThrowOption("poly_degree", std::to_string(degree),
                "small enough that " + std::to_string(d) + " inputs give at most " +
                    std::to_string(kMaxPolyTerms) + " monomials (C(d + degree, degree))");
  }
  const Eigen::Index n = x.rows();
  Eigen::MatrixXi exponents = MakeExponents(d, degree);
  elm::Standardizer input_scaler = elm::FitStandardizer(x, true);
  elm::Standardizer target_scaler = elm::FitStandardizer(y, true);
  const Eigen::MatrixXd z = input_scaler.Apply(x);
  const Eigen::VectorXd ys = target_scaler.Apply(y);

  const double ridge = options.poly_ridge;
  const Eigen::Index m = exponents.rows();
  Eigen::MatrixXd phi(ridge > 0.0 ? n + m : n, m);
  Eigen::MatrixXd powers(d, degree + 1);
  for (Eigen::Index i = 0; i < n; ++i) Monomials(exponents, z.row(i), powers, phi.row(i));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(phi.rows());
  rhs.head(n) = ys;
  if (ridge > 0.0) {
    phi.bottomRows(m).setZero();
    phi.bottomRows(m).diagonal().setConstant(std::sqrt(ridge));
  }
  Eigen::ColPivHouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(phi);
  Eigen::VectorXd coefficients = qr.solve(rhs);
  const int rank = static_cast<int>(qr.rank());

  auto learner = std::make_unique<PolyLearner>(degree, std::move(exponents),
                                               std::move(coefficients), std::move(input_scaler),
                                               std::move(target_scaler), ridge, rank, options.seed);
  learner->SetTraining(static_cast<int>(n), Rmse(learner->Predict(x), y));
  return learner;
}

std::unique_ptr<Learner> LoadPoly(const ParameterReader& reader) {
  const int degree = static_cast<int>(reader.Integer("degree", 1, 4));
  const Eigen::MatrixXd& exponents_d = reader.Array("exponents", -1, -1);
  const Eigen::Index d = exponents_d.cols();
  if (exponents_d.rows() != CountTerms(d, degree)) {
    reader.Fail("exponents has " + std::to_string(exponents_d.rows()) + " rows, expected C(" +
                std::to_string(d) + " + " + std::to_string(degree) + ", " + std::to_string(degree) +
                ") = " + std::to_string(CountTerms(d, degree)));
  }
  const Eigen::MatrixXi expected = MakeExponents(static_cast<int>(d), degree);
  if (!(exponents_d.array() == expected.cast<double>().array()).all()) {
    reader.Fail("exponents are not every monomial of degree <= " + std::to_string(degree) +
                " in graded order");
  }
  Eigen::VectorXd coefficients = reader.Array("coefficients", expected.rows(), 1);
  elm::Standardizer input_scaler = GetScaler(reader, "input", d);
  elm::Standardizer target_scaler = GetScaler(reader, "target", 1);
  const double ridge = reader.Scalar("ridge");
  if (!(ridge >= 0.0 && ridge <= 1.0))
    reader.Fail("ridge = " + FormatShort(ridge) + " not in [0, 1]");
  const int rank = static_cast<int>(reader.Integer("rank", 0, expected.rows()));
  auto learner = std::make_unique<PolyLearner>(degree, expected, std::move(coefficients),
                                               std::move(input_scaler), std::move(target_scaler),
                                               ridge, rank, reader.Seed());
  learner->SetTraining(static_cast<int>(reader.Integer("train_rows", 0, 2147483647L)),
                       reader.Scalar("train_rmse"));
  return learner;
}

}  // namespace gyrodrift::drift::internal
