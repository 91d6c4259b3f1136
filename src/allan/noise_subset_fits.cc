// The least-squares fits of the IEEE 952 noise fit (noise_subset_fits.h).
#include "allan/noise_subset_fits.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <utility>

namespace gyrodrift::allan::internal {
namespace {

// Digamma and trigamma for x > 0: recurrence up to x >= 8, then the asymptotic series.
double Digamma(double x) {
  double shift = 0.0;
  for (; x < 8.0; x += 1.0) shift -= 1.0 / x;
  const double x2 = 1.0 / (x * x);
  return shift + std::log(x) - 0.5 / x -
         x2 * (1.0 / 12.0 - x2 * (1.0 / 120.0 - x2 * (1.0 / 252.0 - x2 / 240.0)));
}
double Trigamma(double x) {
  double shift = 0.0;
  for (; x < 8.0; x += 1.0) shift += 1.0 / (x * x);
  const double x2 = 1.0 / (x * x);
  return shift + 1.0 / x + 0.5 * x2 +
         x2 / x * (1.0 / 6.0 - x2 * (1.0 / 30.0 - x2 * (1.0 / 42.0 - x2 / 30.0)));
}

// Standardised residuals of the log fit at u = ln c of the active terms, into residual, and with
// kJacobian their Jacobian d residual / d u; returns the cost. A template, not a flag, so that the
// trial steps' evaluations compile without the Jacobian whatever the inliner decides.
template <bool kJacobian>
double EvaluateLog(const LogCurve& d, const std::vector<int>& active, const Eigen::VectorXd& u,
                   Eigen::VectorXd& residual, Eigen::MatrixXd* jacobian) {
  const Eigen::Index n = d.target.size();
  const auto k = static_cast<Eigen::Index>(active.size());
  const Eigen::VectorXd coef = u.array().exp();
  for (Eigen::Index r = 0; r < n; ++r) {
    double model = 0.0;
    for (Eigen::Index c = 0; c < k; ++c) model += coef[c] * d.columns(r, active[c]);
    residual[r] = (d.target[r] - std::log(model)) / d.sd[r];
    if constexpr (kJacobian)
      for (Eigen::Index c = 0; c < k; ++c)
        (*jacobian)(r, c) = coef[c] * d.columns(r, active[c]) / model / d.sd[r];
  }
  return residual.squaredNorm();
}

// Levenberg-Marquardt on u_j = ln c_j (so every coefficient stays positive) for the terms in
// `mask`, from `start`. A term whose optimum is zero drifts towards it (and is then removed by the
// selection, where it changes nothing).
SubsetFit FitLog(const LogCurve& d, unsigned mask, const std::array<double, kTerms>& start) {
  const std::vector<int> active = TermsOf(mask);
  const Eigen::Index n = d.target.size();
  const auto k = static_cast<Eigen::Index>(active.size());
  Eigen::VectorXd u(k);
  for (Eigen::Index c = 0; c < k; ++c) u[c] = std::log(start[static_cast<size_t>(active[c])]);
  SubsetFit fit;
  Eigen::VectorXd residual(n), trial_residual(n);
  Eigen::MatrixXd jacobian(n, k);
  double cost = EvaluateLog<true>(d, active, u, residual, &jacobian);
  if (!std::isfinite(cost)) return fit;
  double lambda = 1e-3;
  for (int iteration = 0; iteration < 200; ++iteration) {
    Eigen::MatrixXd damped = jacobian.transpose() * jacobian;
    damped.diagonal() *= 1.0 + lambda;
    const Eigen::VectorXd step = damped.ldlt().solve(jacobian.transpose() * residual);
    const Eigen::VectorXd trial = u + step;
    const double trial_cost = EvaluateLog<false>(d, active, trial, trial_residual, nullptr);
    if (std::isfinite(trial_cost) && trial_cost <= cost) {
      const bool converged =
          cost - trial_cost <= 1e-14 * (1.0 + cost) && step.cwiseAbs().maxCoeff() < 1e-9;
      u = trial;
      cost = EvaluateLog<true>(d, active, u, residual, &jacobian);
      lambda = std::max(lambda / 10.0, 1e-12);
      if (converged) break;
    } else {
      lambda *= 10.0;
      if (lambda > 1e12) break;
    }
  }
  fit.ok = true;
  fit.chi2 = cost;
  fit.jacobian = jacobian;
  for (Eigen::Index c = 0; c < k; ++c) fit.coef[static_cast<size_t>(active[c])] = std::exp(u[c]);
  return fit;
}

}  // namespace

// Exact non-negative least squares over a handful of columns: the NNLS optimum is the
// unconstrained optimum on its own support, so trying every support (at most 2^5) and keeping the
// best feasible one finds it without an iterative active-set method.
NnlsFit SolveNnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b, unsigned allowed) {
  NnlsFit best;
  best.chi2 = std::numeric_limits<double>::infinity();
  for (unsigned mask = 1; mask < (1u << kTerms); ++mask) {
    if ((mask & ~allowed) != 0) continue;
    std::vector<int> cols;
    for (int j = 0; j < kTerms; ++j)
      if (mask & (1u << j)) cols.push_back(j);
    if (static_cast<Eigen::Index>(cols.size()) > a.rows()) continue;
    Eigen::MatrixXd sub(a.rows(), static_cast<Eigen::Index>(cols.size()));
    Eigen::VectorXd scale(sub.cols());
    for (Eigen::Index c = 0; c < sub.cols(); ++c) {
      sub.col(c) = a.col(cols[static_cast<size_t>(c)]);
      scale[c] = sub.col(c).norm();
      if (scale[c] == 0.0) scale[c] = 1.0;
      sub.col(c) /= scale[c];  // equilibrate: tau^-2 and tau^2 columns differ by ~1e16
    }
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(sub);
    if (qr.rank() < sub.cols()) continue;
    Eigen::VectorXd x = qr.solve(b);
    if ((x.array() <= 0.0).any()) continue;
    const double chi2 = (sub * x - b).squaredNorm();
    if (chi2 < best.chi2) {
      best = NnlsFit{};
      best.chi2 = chi2;
      best.ok = true;
      best.active = cols;
      const Eigen::MatrixXd r = qr.matrixR()
                                    .topLeftCorner(sub.cols(), sub.cols())
                                    .template triangularView<Eigen::Upper>();
      // (A^T A)^-1 = P R^-1 R^-T P^T, then undo the equilibration.
      const Eigen::MatrixXd rinv =
          r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(sub.cols(), sub.cols()));
      const Eigen::MatrixXd perm = qr.colsPermutation();
      Eigen::MatrixXd cov = perm * rinv * rinv.transpose() * perm.transpose();
      for (Eigen::Index i = 0; i < cov.rows(); ++i)
        for (Eigen::Index j = 0; j < cov.cols(); ++j) cov(i, j) /= scale[i] * scale[j];
      best.cov = cov;
      for (size_t c = 0; c < cols.size(); ++c)
        best.coef[static_cast<size_t>(cols[c])] =
            x[static_cast<Eigen::Index>(c)] / scale[static_cast<Eigen::Index>(c)];
    }
  }
  return best;
}

LogCurve MakeLogCurve(const Eigen::MatrixXd& columns, const Eigen::VectorXd& var,
                      const Eigen::VectorXd& edf) {
  const Eigen::Index n = var.size();
  LogCurve curve;
  curve.columns = columns;
  curve.target.resize(n);
  curve.sd.resize(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const double half = edf[r] / 2.0;
    curve.target[r] = std::log(var[r]) - (Digamma(half) - std::log(half));
    curve.sd[r] = std::sqrt(Trigamma(half));
  }
  return curve;
}

// Every subset of the five terms with fewer terms than points (n terms would pass through every
// point: a misfit of 0 that no test can weigh, so two points would "identify" two terms). Subsets
// are visited by size; each starts from the weighted non-negative fit in variance on its terms and
// from each one-term-smaller fit plus a little of the added term, and keeps the best, so a model
// never fits worse than the models nested in it.
SubsetFits FitAllSubsets(const LogCurve& d, const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                         const Eigen::VectorXd& var) {
  SubsetFits fits;
  const Eigen::Index n = d.target.size();
  for (int size = 1; size <= std::min<Eigen::Index>(kTerms, n - 1); ++size) {
    for (unsigned mask = 1; mask <= kAllTerms; ++mask) {
      if (Size(mask) != size) continue;
      // A term missing from a start begins at 1 % of the most it could be without exceeding the
      // curve anywhere.
      auto complete = [&](std::array<double, kTerms> coef) {
        for (const int j : TermsOf(mask)) {
          if (coef[static_cast<size_t>(j)] > 0.0) continue;
          double most = std::numeric_limits<double>::infinity();
          for (Eigen::Index r = 0; r < n; ++r) most = std::min(most, var[r] / d.columns(r, j));
          coef[static_cast<size_t>(j)] = 0.01 * most;
        }
        return coef;
      };
      std::vector<std::array<double, kTerms>> starts;
      const NnlsFit nnls = SolveNnls(a, b, mask);
      starts.push_back(complete(nnls.ok ? nnls.coef : std::array<double, kTerms>{}));
      for (const int j : TermsOf(mask)) {
        const SubsetFit& smaller = fits[mask & ~(1u << j)];
        if (smaller.ok) starts.push_back(complete(smaller.coef));
      }
      for (const auto& start : starts) {
        SubsetFit fit = FitLog(d, mask, start);
        if (fit.ok && fit.chi2 < fits[mask].chi2) fits[mask] = std::move(fit);
      }
    }
  }
  return fits;
}

}  // namespace gyrodrift::allan::internal
