// Allan deviations of a record with gaps (ComputeWithGaps, allan.h): the overlapping estimators
// over the cluster pairs whose samples are all logged.
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>
#include <vector>

#include "allan/allan_steps.h"
#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/edf.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"

namespace gyrodrift::allan {
namespace {

using internal::DifferenceOrder;
using internal::FirstIdentified;
using internal::PhaseLength;
using internal::SetInterval;

// First sample and length of the longest run of logged samples.
std::pair<Eigen::Index, Eigen::Index> LongestLoggedRun(const std::vector<bool>& logged) {
  Eigen::Index best_begin = 0, best = 0, begin = 0;
  for (Eigen::Index i = 0; i <= static_cast<Eigen::Index>(logged.size()); ++i) {
    if (i < static_cast<Eigen::Index>(logged.size()) && logged[static_cast<size_t>(i)]) continue;
    if (i - begin > best) {
      best = i - begin;
      best_begin = begin;
    }
    begin = i + 1;
  }
  return {best_begin, best};
}

void CheckGapInput(const Eigen::VectorXd& data, const std::vector<bool>& logged,
                   const AllanOptions& options, const Execution& execution) {
  options.Validate();
  execution.Validate();
  const Deviation dev = options.deviation;
  if (dev != Deviation::kOadev && dev != Deviation::kOhdev) {
    ThrowOption("deviation", ToString(dev),
                "oadev or ohdev for a record with gaps (the overlapping estimators skip the "
                "cluster pairs that hold a made-up sample)");
  }
  if (options.data_type != DataType::kRate) {
    ThrowOption("data_type", ToString(options.data_type),
                "rate for a record with gaps (a made-up rate sample spoils the spans over it)");
  }
  if (static_cast<Eigen::Index>(logged.size()) != data.size()) {
    throw DataError("the mask of logged samples has " + std::to_string(logged.size()) +
                    " flags for " + std::to_string(data.size()) + " samples: they must match");
  }
}

// The phase of a rate record whose unlogged samples are made up. The made-up values are never
// used: they become the logged mean, which adds nothing to the phase, so a NaN gap is as good as a
// filled one.
std::vector<double> PhaseWithGaps(const Eigen::VectorXd& data, const std::vector<bool>& logged,
                                  const AllanOptions& options) {
  Eigen::VectorXd kept(data.size());
  Eigen::Index count = 0;
  for (Eigen::Index i = 0; i < data.size(); ++i) {
    if (logged[static_cast<size_t>(i)]) kept[count++] = data[i];
  }
  RequireFiniteSignal("input (logged samples)", kept.head(count), 2);
  const double mean = kept.head(count).mean();
  Eigen::VectorXd y = data;
  for (Eigen::Index i = 0; i < y.size(); ++i) {
    if (!logged[static_cast<size_t>(i)]) y[i] = mean;
  }
  std::vector<double> x(static_cast<size_t>(PhaseLength(y.size(), options)));
  internal::InternalPhase(y.data(), y.size(), y.mean(), options, x.data());
  return x;
}

// The overlapping variance of each factor over the clean spans of the phase x only, into
// variance, and the number of its terms into terms (0: no clean span). made_up[k] counts the
// made-up samples among the first k, so the span of phase points i..i+d*m is clean when
// made_up[i + d*m] == made_up[i].
void CleanSpanVariances(const std::vector<double>& x, const std::vector<std::int64_t>& made_up,
                        const std::vector<std::int64_t>& ms, int order, double tau0, int threads,
                        std::vector<double>& variance, std::vector<std::int64_t>& terms) {
  const std::int64_t n = static_cast<std::int64_t>(x.size());
  ParallelFor(static_cast<int>(ms.size()), threads, [&](int k, int) {
    const std::int64_t m = ms[static_cast<size_t>(k)];
    double acc = 0.0;
    std::int64_t used = 0;
    const double* p = x.data();
    for (std::int64_t i = 0; i + order * m < n; ++i) {
      if (made_up[static_cast<size_t>(i + order * m)] != made_up[static_cast<size_t>(i)]) continue;
      const double d = order == 2 ? p[i + 2 * m] - 2.0 * p[i + m] + p[i]
                                  : p[i + 3 * m] - 3.0 * p[i + 2 * m] + 3.0 * p[i + m] - p[i];
      acc += d * d;
      ++used;
    }
    const double tau = static_cast<double>(m) * tau0;
    terms[static_cast<size_t>(k)] = used;
    if (used > 0) variance[static_cast<size_t>(k)] = acc / ((order == 2 ? 2.0 : 6.0) *
                                                            static_cast<double>(used) * tau * tau);
  });
}

}  // namespace

AllanResult ComputeWithGaps(const Eigen::VectorXd& data, const std::vector<bool>& logged,
                            const AllanOptions& options, const Execution& execution) {
  CheckGapInput(data, logged, options, execution);
  const Deviation dev = options.deviation;
  const std::vector<double> x = PhaseWithGaps(data, logged, options);
  const std::int64_t n = static_cast<std::int64_t>(x.size());
  std::vector<std::int64_t> made_up(static_cast<size_t>(n), 0);
  for (std::int64_t k = 1; k < n; ++k) {
    made_up[static_cast<size_t>(k)] =
        made_up[static_cast<size_t>(k - 1)] + (logged[static_cast<size_t>(k - 1)] ? 0 : 1);
  }
  const int order = DifferenceOrder(dev);
  const std::vector<std::int64_t> ms = AveragingFactors(options, n);
  const double tau0 = options.tau0_s();
  std::vector<double> variance(ms.size(), 0.0);
  std::vector<std::int64_t> terms(ms.size(), 0);
  CleanSpanVariances(x, made_up, ms, order, tau0, execution.threads, variance, terms);

  // Noise types from the longest logged run, at the factors that have terms.
  const auto [run_begin, run_length] = LongestLoggedRun(logged);
  const Eigen::Map<const Eigen::VectorXd> run_phase(x.data() + run_begin, run_length + 1);
  std::vector<std::optional<int>> alpha(ms.size());
  for (size_t k = 0; k < ms.size() && options.confidence_intervals && !options.forced_alpha; ++k)
    if (terms[k] != 0) alpha[k] = IdentifyAlpha(run_phase, ms[k], options.data_type, order);
  int carried = FirstIdentified(alpha);  // as Compute

  AllanResult result;
  result.options = options;
  result.n_samples = data.size();
  result.n_logged = std::count(logged.begin(), logged.end(), true);
  result.n_phase = n;
  for (size_t k = 0; k < ms.size(); ++k) {
    if (terms[k] == 0) {
      if (options.grid == TauGrid::kList) {
        throw DataError("tau " + FormatValue(static_cast<double>(ms[k]) * tau0) +
                        " s has no cluster pair of logged samples: " + ToString(dev) + " needs " +
                        std::to_string(order * ms[k]) + " logged samples in a row, the longest "
                        "run is " + std::to_string(run_length));
      }
      continue;
    }
    AllanPoint p;
    p.m = ms[k];
    p.tau_s = static_cast<double>(p.m) * tau0;
    p.dev = std::sqrt(std::max(0.0, variance[k]));
    p.n_terms = terms[k];
    SetInterval(options, alpha[k], static_cast<Eigen::Index>(p.n_terms + order * p.m), carried, p);
    result.points.push_back(p);
  }
  if (result.points.empty()) {
    throw DataError(ToString(dev) + " of a record with gaps: no tau has a cluster pair of logged "
                    "samples (" + std::to_string(order) + " logged samples in a row needed at the "
                    "shortest tau, the longest run is " + std::to_string(run_length) + ")");
  }
  return result;
}

}  // namespace gyrodrift::allan
