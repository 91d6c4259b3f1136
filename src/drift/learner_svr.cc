// kSvr: epsilon-SVR with the Gaussian RBF kernel, trained by libsvm (Chang & Lin, ACM TIST 2,
// 2011; SMO with the WSS3 working-set selection of Fan, Chen & Lin, JMLR 6, 2005).
//
//   y_s(z) = sum_i coef_i exp(-gamma ||z - sv_i||^2) - rho,   z = standardised inputs
// Training sees at most svr_max_rows rows: row floor(k N / M) for k = 0..M-1 (evenly spaced
// in row order, so a time series keeps its whole span). The scalers come from all training
// rows. The expansion above is evaluated here, not by svm_predict, both right after training
// and after LoadLearner: one code path, so a saved model predicts the same bits, and no libsvm
// struct has to be rebuilt in memory.
// libsvm notes: without probability estimates, svm_train for EPSILON_SVR draws no random
// numbers (shrinking is deterministic). Its output goes through one global print hook, which
// is set once to a no-op; its maintainers do not promise thread safety (cjlin1/libsvm#167), so
// training runs under a process-wide mutex. Prediction does not touch libsvm and runs in
// parallel.
#include <svm.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

#include "drift/learner_kinds.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::drift::internal {
namespace {

constexpr double kCacheMb = 100.0;   // libsvm kernel cache
constexpr double kTolerance = 1e-3;  // libsvm's default stopping tolerance (KKT gap)
constexpr Eigen::Index kPredictBlock = 256;

std::mutex& LibsvmMutex() {
  static std::mutex mutex;
  return mutex;
}

void SilentPrint(const char*) {}

class SvrLearner final : public Learner {
 public:
  SvrLearner(Eigen::MatrixXd support_t, Eigen::VectorXd coefficients, double rho, double gamma,
             elm::Standardizer input_scaler, elm::Standardizer target_scaler)
      : support_t_(std::move(support_t)),
        coefficients_(std::move(coefficients)),
        rho_(rho),
        gamma_(gamma),
        input_scaler_(std::move(input_scaler)),
        target_scaler_(std::move(target_scaler)) {}

  LearnerKind kind() const override { return LearnerKind::kSvr; }
  int num_inputs() const override { return static_cast<int>(support_t_.rows()); }

  Eigen::VectorXd Predict(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    CheckPredictInput(kind(), num_inputs(), x);
    const Eigen::MatrixXd z = input_scaler_.Apply(x);
    const Eigen::Index n = x.rows();
    const Eigen::Index d = support_t_.rows();
    const Eigen::Index nsv = support_t_.cols();
    Eigen::VectorXd y(n);
    const int blocks = static_cast<int>((n + kPredictBlock - 1) / kPredictBlock);
    // Rows are independent, so the bits do not depend on the thread count.
    ParallelFor(blocks, std::min(ResolveThreads(threads_), std::max(blocks, 1)),
                [&](int block, int) {
                  const Eigen::Index r1 = std::min(n, (block + 1) * kPredictBlock);
                  for (Eigen::Index i = block * kPredictBlock; i < r1; ++i) {
                    double sum = 0.0;
                    for (Eigen::Index s = 0; s < nsv; ++s) {
                      const double* sv = support_t_.col(s).data();
                      double dist2 = 0.0;
                      for (Eigen::Index j = 0; j < d; ++j) {
                        const double diff = z(i, j) - sv[j];
                        dist2 += diff * diff;
                      }
                      sum += coefficients_[s] * std::exp(-gamma_ * dist2);
                    }
                    y[i] = (sum - rho_) * target_scaler_.scale[0] + target_scaler_.mean[0];
                  }
                });
    return y;
  }

  Parameters Save() const override {
    Parameters p;
    PutCommon(kind(), seed_, rows_, train_rmse_, &p);
    p.arrays["support_vectors"] = support_t_.transpose();
    p.arrays["coefficients"] = coefficients_;
    PutScaler("input", input_scaler_, &p);
    PutScaler("target", target_scaler_, &p);
    p.scalars["rho"] = rho_;
    p.scalars["gamma"] = gamma_;
    p.scalars["c"] = c_;
    p.scalars["epsilon"] = epsilon_;
    p.scalars["rows_used"] = rows_used_;
    return p;
  }

  std::string Summary() const override {
    return "svr: " + std::to_string(num_inputs()) + " inputs, " +
           std::to_string(support_t_.cols()) + " support vectors from " +
           std::to_string(rows_used_) + " of " + std::to_string(rows_) + " rows, C " +
           FormatShort(c_) + " epsilon " + FormatShort(epsilon_) + " gamma " + FormatShort(gamma_) +
           ", train RMSE " + FormatShort(train_rmse_);
  }

  void SetInfo(double c, double epsilon, int rows_used, int threads, std::uint64_t seed) {
    c_ = c;
    epsilon_ = epsilon;
    rows_used_ = rows_used;
    threads_ = threads;
    seed_ = seed;
  }
  void SetTraining(int rows, double train_rmse) {
    rows_ = rows;
    train_rmse_ = train_rmse;
  }

 private:
  Eigen::MatrixXd support_t_;  // d x nSV: one support vector per column (contiguous)
  Eigen::VectorXd coefficients_;
  double rho_;
  double gamma_;
  elm::Standardizer input_scaler_;
  elm::Standardizer target_scaler_;
  double c_ = 0.0;
  double epsilon_ = 0.0;
  int rows_used_ = 0;
  int threads_ = 0;  // of Predict: the fit's (Execution::threads), 0 = every core when loaded
  std::uint64_t seed_ = 0;  // libsvm draws nothing; kept for uniform metadata
  int rows_ = 0;
  double train_rmse_ = 0.0;
};

struct ModelDeleter {
  void operator()(svm_model* model) const { svm_free_and_destroy_model(&model); }
};

}  // namespace

std::unique_ptr<Learner> FitSvr(const Eigen::Ref<const Eigen::MatrixXd>& x,
                                const Eigen::Ref<const Eigen::VectorXd>& y,
                                const LearnerOptions& options, int threads) {
  const Eigen::Index n = x.rows();
  const Eigen::Index d = x.cols();
  elm::Standardizer input_scaler = elm::FitStandardizer(x, true);
  elm::Standardizer target_scaler = elm::FitStandardizer(y, true);
  const Eigen::MatrixXd z = input_scaler.Apply(x);
  const Eigen::VectorXd ys = target_scaler.Apply(y);

  const Eigen::Index used = std::min<Eigen::Index>(n, options.svr_max_rows);
  // Dense libsvm rows: d (index, value) nodes plus the index -1 terminator.
  std::vector<svm_node> nodes(static_cast<size_t>(used * (d + 1)));
  std::vector<svm_node*> rows(static_cast<size_t>(used));
  std::vector<double> targets(static_cast<size_t>(used));
  for (Eigen::Index k = 0; k < used; ++k) {
    const Eigen::Index i = used == n ? k : (k * n) / used;
    svm_node* row = &nodes[static_cast<size_t>(k * (d + 1))];
    for (Eigen::Index j = 0; j < d; ++j) row[j] = svm_node{static_cast<int>(j + 1), z(i, j)};
    row[d] = svm_node{-1, 0.0};
    rows[static_cast<size_t>(k)] = row;
    targets[static_cast<size_t>(k)] = ys[i];
  }
  svm_problem problem{static_cast<int>(used), targets.data(), rows.data()};

  svm_parameter param{};
  param.svm_type = EPSILON_SVR;
  param.kernel_type = RBF;
  param.degree = 3;
  param.gamma = options.svr_gamma > 0.0 ? options.svr_gamma : 1.0 / static_cast<double>(d);
  param.coef0 = 0.0;
  param.cache_size = kCacheMb;
  param.eps = kTolerance;
  param.C = options.svr_c;
  param.nr_weight = 0;
  param.weight_label = nullptr;
  param.weight = nullptr;
  param.nu = 0.5;
  param.p = options.svr_epsilon;
  param.shrinking = 1;
  param.probability = 0;

  Eigen::MatrixXd support_t;
  Eigen::VectorXd coefficients;
  double rho = 0.0;
  {
    std::lock_guard<std::mutex> lock(LibsvmMutex());
    svm_set_print_string_function(&SilentPrint);
    if (const char* message = svm_check_parameter(&problem, &param)) {
      throw UsageError(std::string("svr: libsvm rejects the parameters: ") + message);
    }
    std::unique_ptr<svm_model, ModelDeleter> model(svm_train(&problem, &param));
    if (!model) throw DataError("svr: libsvm training failed");
    const int nsv = model->l;
    support_t = Eigen::MatrixXd::Zero(d, nsv);
    coefficients.resize(nsv);
    for (int s = 0; s < nsv; ++s) {
      // libsvm's sparse rows skip zeros in general; ours are dense, but read them as sparse.
      for (const svm_node* node = model->SV[s]; node->index != -1; ++node) {
        if (node->index >= 1 && node->index <= d) support_t(node->index - 1, s) = node->value;
      }
      coefficients[s] = model->sv_coef[0][s];
    }
    rho = model->rho[0];
  }
  if (!coefficients.allFinite() || !std::isfinite(rho)) {
    throw DataError("svr: libsvm returned a non-finite coefficient or offset");
  }

  auto learner =
      std::make_unique<SvrLearner>(std::move(support_t), std::move(coefficients), rho, param.gamma,
                                   std::move(input_scaler), std::move(target_scaler));
  learner->SetInfo(options.svr_c, options.svr_epsilon, static_cast<int>(used), threads,
                   options.seed);
  learner->SetTraining(static_cast<int>(n), Rmse(learner->Predict(x), y));
  return learner;
}

std::unique_ptr<Learner> LoadSvr(const ParameterReader& reader) {
  // A target that stays within epsilon of its mean needs no support vector at all.
  const Eigen::Index d = reader.Array("input_mean", 1, -1).cols();
  // A model file may not keep the column count of an empty array: 0 x anything is accepted.
  const bool none = reader.Array("support_vectors", -1, -1, true).rows() == 0;
  const Eigen::MatrixXd support =
      none ? Eigen::MatrixXd(0, d) : reader.Array("support_vectors", -1, d);
  Eigen::VectorXd coefficients =
      none ? Eigen::VectorXd(0) : Eigen::VectorXd(reader.Array("coefficients", support.rows(), 1));
  if (none && reader.Array("coefficients", -1, -1, true).size() != 0) {
    reader.Fail("coefficients are given but there are no support vectors");
  }
  elm::Standardizer input_scaler = GetScaler(reader, "input", d);
  elm::Standardizer target_scaler = GetScaler(reader, "target", 1);
  const double rho = reader.Scalar("rho");
  const double gamma = reader.Scalar("gamma");
  if (!std::isfinite(rho)) reader.Fail("rho is not finite");
  if (!(gamma > 0.0) || !std::isfinite(gamma)) reader.Fail("gamma is not a finite number > 0");
  auto learner =
      std::make_unique<SvrLearner>(support.transpose(), std::move(coefficients), rho, gamma,
                                   std::move(input_scaler), std::move(target_scaler));
  reader.DropLegacyThreads();
  learner->SetInfo(reader.Scalar("c"), reader.Scalar("epsilon"),
                   static_cast<int>(reader.Integer("rows_used", 1, 2147483647L)), 0, reader.Seed());
  learner->SetTraining(static_cast<int>(reader.Integer("train_rows", 0, 2147483647L)),
                       reader.Scalar("train_rmse"));
  return learner;
}

}  // namespace gyrodrift::drift::internal
