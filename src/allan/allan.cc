#include "gyrodrift/allan/allan.h"
#include "gyrodrift/allan/edf.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <sstream>
#include <utility>

#include "allan/allan_steps.h"
#include "allan/kernels.h"
#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace gyrodrift::allan {
namespace {

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;
using gyrodrift::internal::EnumNames;

constexpr EnumNames<Deviation, 7> kDeviationNames{{
    {Deviation::kAdev, "adev"},
    {Deviation::kOadev, "oadev"},
    {Deviation::kMdev, "mdev"},
    {Deviation::kHdev, "hdev"},
    {Deviation::kOhdev, "ohdev"},
    {Deviation::kTdev, "tdev"},
    {Deviation::kTotdev, "totdev"},
}};
constexpr EnumNames<DataType, 2> kDataTypeNames{{
    {DataType::kRate, "rate"},
    {DataType::kAngle, "angle"},
}};
constexpr EnumNames<RateUnit, 3> kUnitNames{{
    {RateUnit::kDegPerHour, "dph"},
    {RateUnit::kDegPerSecond, "dps"},
    {RateUnit::kRadPerSecond, "rads"},
}};
constexpr EnumNames<TauGrid, 4> kGridNames{{
    {TauGrid::kAll, "all"},
    {TauGrid::kOctave, "octave"},
    {TauGrid::kDecade, "decade"},
    {TauGrid::kList, "list"},
}};

}  // namespace

namespace internal {

void InternalPhase(const double* data, Eigen::Index n, double mean, const AllanOptions& o,
                   double* x) {
  const double tau0 = o.tau0_s();
  if (o.data_type == DataType::kRate) {
    // Plain double running sum: with the mean removed the angle is a random walk, and its
    // accumulated rounding stays ~N eps relative to one step, far below what any tau resolves.
    double acc = 0.0, next = data[0];
    x[0] = 0.0;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double y = next;
      if (i + 1 < n) next = data[i + 1];
      acc += (y - mean) * tau0;
      x[i + 1] = acc;
    }
  } else {
    // Angle unit -> rate unit x s: degrees with deg/h become deg/h * s (x 3600).
    const double scale = o.units == RateUnit::kDegPerHour ? 3600.0 : 1.0;
    const double x0 = data[0];
    const double slope = n > 1 ? (data[n - 1] - x0) / static_cast<double>(n - 1) : 0.0;
    for (Eigen::Index i = 0; i < n; ++i)
      x[i] = (data[i] - (x0 + slope * static_cast<double>(i))) * scale;
  }
}

Eigen::Index PhaseLength(Eigen::Index n, const AllanOptions& o) {
  return o.data_type == DataType::kRate ? n + 1 : n;
}

int DifferenceOrder(Deviation d) {
  return (d == Deviation::kHdev || d == Deviation::kOhdev) ? 3 : 2;
}

int FirstIdentified(const std::vector<std::optional<int>>& alpha) {
  for (const std::optional<int>& a : alpha)
    if (a) return *a;
  return 0;
}

void SetInterval(const AllanOptions& options, const std::optional<int>& alpha,
                 Eigen::Index edf_phase_points, int& carried, AllanPoint& p) {
  if (!options.confidence_intervals) {
    p.edf = p.dev_lo = p.dev_hi = std::numeric_limits<double>::quiet_NaN();
    return;
  }
  if (options.forced_alpha) {
    p.alpha = *options.forced_alpha;
  } else if (alpha) {
    p.alpha = carried = *alpha;
    p.alpha_identified = true;
  } else {
    p.alpha = carried;
  }
  p.edf = EquivalentDof(options.deviation, p.alpha, p.m, edf_phase_points);
  ConfidenceInterval(p.dev, p.edf, options.confidence, &p.dev_lo, &p.dev_hi);
}

}  // namespace internal

namespace {

using internal::DifferenceOrder;
using internal::FirstIdentified;
using internal::InternalPhase;
using internal::PhaseLength;
using internal::SetInterval;

// Storage of the phase of a record handed by reference. Not zero-filled, and on Linux in 2 MiB
// pages when large: faulting in 4 KiB pages cost about 5 ns a sample here (more than the
// integration), 2 MiB pages about 1 ns, and the strided sweeps miss the TLB less.
struct FreeDeleter {
  void operator()(double* p) const { std::free(p); }
};
std::unique_ptr<double[], FreeDeleter> PhaseStorage(Eigen::Index n) {
  constexpr size_t kHugePage = size_t{2} << 20;
  const size_t bytes = static_cast<size_t>(n) * sizeof(double);
  if (bytes < 2 * kHugePage) {
    auto* p = static_cast<double*>(std::malloc(bytes));
    if (p == nullptr) throw std::bad_alloc();
    return std::unique_ptr<double[], FreeDeleter>(p);
  }
  const size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  auto* p = static_cast<double*>(std::aligned_alloc(kHugePage, rounded));
  if (p == nullptr) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
  madvise(p, rounded, MADV_HUGEPAGE);  // advice only: without it the pages are small
#endif
  return std::unique_ptr<double[], FreeDeleter>(p);
}

void CheckComputeInput(const Eigen::VectorXd& data, const AllanOptions& options,
                       const Execution& execution) {
  options.Validate();
  execution.Validate();
  RequireFiniteSignal("input", data, options.data_type == DataType::kRate ? 2 : 3);
}

AllanResult ComputeOnPhase(const double* x, Eigen::Index n_samples, const AllanOptions& options,
                           const Execution& execution);

}  // namespace

std::string ToString(Deviation d) { return std::string(EnumName(d, kDeviationNames)); }
Deviation DeviationFromString(std::string_view s) {
  return EnumFromName(s, "dev", kDeviationNames);
}
std::string ToString(DataType t) { return std::string(EnumName(t, kDataTypeNames)); }
DataType DataTypeFromString(std::string_view s) { return EnumFromName(s, "type", kDataTypeNames); }
std::string ToString(RateUnit u) { return std::string(EnumName(u, kUnitNames)); }
RateUnit RateUnitFromString(std::string_view s) { return EnumFromName(s, "units", kUnitNames); }
std::string ToString(TauGrid g) { return std::string(EnumName(g, kGridNames)); }
TauGrid TauGridFromString(std::string_view s) { return EnumFromName(s, "taus", kGridNames); }

double ToDegPerHour(RateUnit u) {
  switch (u) {
    case RateUnit::kDegPerHour:
      return 1.0;
    case RateUnit::kDegPerSecond:
      return 3600.0;
    case RateUnit::kRadPerSecond:
      return 3600.0 * 180.0 / std::numbers::pi;
  }
  return 1.0;
}

std::string NoiseTypeName(int alpha) {
  switch (alpha) {
    case 2:
      return "white angle (quantization)";
    case 1:
      return "flicker angle";
    case 0:
      return "white rate (ARW)";
    case -1:
      return "flicker rate (bias instability)";
    case -2:
      return "random-walk rate (RRW)";
    case -3:
      return "flicker-walk rate";
    case -4:
      return "random-run rate (rate ramp)";
    default:
      return "unknown";
  }
}

void AllanOptions::Validate() const {
  RequirePositive("rate_hz", rate_hz);
  // Beyond 1 - 1e-12 the chi-square tails' quantiles lose their digits (at the last double
  // below 1 the lower bound was NaN).
  if (!(confidence > 0.0 && confidence <= 1.0 - 1e-12))
    ThrowOption("confidence", FormatValue(confidence), "in (0, 1 - 1e-12]");
  if (forced_alpha && (*forced_alpha < -4 || *forced_alpha > 2))
    ThrowOption("forced_alpha", std::to_string(*forced_alpha), "an integer in -4..2");
  if (forced_alpha && *forced_alpha + 2 * DifferenceOrder(deviation) <= 1)
    ThrowOption(
        "forced_alpha", std::to_string(*forced_alpha),
        "> " + std::to_string(1 - 2 * DifferenceOrder(deviation)) + " for " + ToString(deviation));
  if (grid == TauGrid::kList) {
    if (tau_list_s.empty()) ThrowOption("tau_list_s", "(empty)", "at least one tau for grid list");
    for (double t : tau_list_s) RequirePositive("tau_list_s", t);
  }
}

std::int64_t MaxAveragingFactor(Deviation d, Eigen::Index n_phase) {
  const std::int64_t n = n_phase;
  switch (d) {
    case Deviation::kAdev:
    case Deviation::kOadev:
    case Deviation::kTotdev:
      return (n - 1) / 2;
    case Deviation::kMdev:
    case Deviation::kTdev:
      return n / 3;
    case Deviation::kHdev:
    case Deviation::kOhdev:
      return (n - 1) / 3;
  }
  return 0;
}

std::int64_t TermCount(Deviation d, Eigen::Index n_phase, std::int64_t m) {
  const std::int64_t n = n_phase;
  switch (d) {
    case Deviation::kAdev:
      return (n - 1) / m - 1;
    case Deviation::kOadev:
      return n - 2 * m;
    case Deviation::kMdev:
    case Deviation::kTdev:
      return n - 3 * m + 1;
    case Deviation::kHdev:
      return (n - 1) / m - 2;
    case Deviation::kOhdev:
      return n - 3 * m;
    case Deviation::kTotdev:
      return n - 2;
  }
  return 0;
}

std::vector<std::int64_t> AveragingFactors(const AllanOptions& o, Eigen::Index n_phase) {
  const std::int64_t max_m = MaxAveragingFactor(o.deviation, n_phase);
  std::vector<std::int64_t> ms;
  switch (o.grid) {
    case TauGrid::kAll:
      for (std::int64_t m = 1; m <= max_m; ++m) ms.push_back(m);
      break;
    case TauGrid::kOctave:
      for (std::int64_t m = 1; m <= max_m; m *= 2) ms.push_back(m);
      break;
    case TauGrid::kDecade:
      for (std::int64_t decade = 1; decade <= max_m; decade *= 10)
        for (std::int64_t f : {1, 2, 4})
          if (decade * f <= max_m) ms.push_back(decade * f);
      break;
    case TauGrid::kList:
      for (double tau : o.tau_list_s) {
        const double mf = std::max(1.0, std::round(tau * o.rate_hz));
        if (mf > static_cast<double>(max_m)) {
          throw DataError("tau " + FormatValue(tau) + " s needs averaging factor " +
                          FormatValue(mf) + " but " + ToString(o.deviation) + " of " +
                          std::to_string(n_phase) + " points allows at most " +
                          std::to_string(max_m) + " (tau " +
                          FormatValue(static_cast<double>(max_m) * o.tau0_s()) + " s)");
        }
        ms.push_back(static_cast<std::int64_t>(mf));
      }
      std::sort(ms.begin(), ms.end());
      ms.erase(std::unique(ms.begin(), ms.end()), ms.end());
      break;
  }
  return ms;
}

Eigen::VectorXd AllanResult::tau_s() const {
  Eigen::VectorXd v(static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) v[static_cast<Eigen::Index>(i)] = points[i].tau_s;
  return v;
}

Eigen::VectorXd AllanResult::dev() const {
  Eigen::VectorXd v(static_cast<Eigen::Index>(points.size()));
  for (size_t i = 0; i < points.size(); ++i) v[static_cast<Eigen::Index>(i)] = points[i].dev;
  return v;
}

std::string AllanResult::Summary() const {
  std::ostringstream s;
  s << ToString(options.deviation) << " of ";
  if (n_logged >= 0 && n_logged < n_samples) {
    s << n_logged << " logged " << ToString(options.data_type) << " samples";
  } else {
    s << n_samples << " " << ToString(options.data_type) << " samples";
  }
  s << " at " << FormatValue(options.rate_hz) << " Hz: " << points.size() << " taus";
  if (!points.empty()) {
    const auto it = std::min_element(points.begin(), points.end(),
                                     [](const auto& a, const auto& b) { return a.dev < b.dev; });
    s << " " << FormatValue(points.front().tau_s) << ".." << FormatValue(points.back().tau_s)
      << " s, min " << FormatValue(it->dev) << " " << ToString(options.units) << " at "
      << FormatValue(it->tau_s) << " s";
  }
  return s.str();
}

AllanResult Compute(const Eigen::VectorXd& data, const AllanOptions& options,
                    const Execution& execution) {
  CheckComputeInput(data, options, execution);
  const auto x = PhaseStorage(PhaseLength(data.size(), options));
  InternalPhase(data.data(), data.size(), data.mean(), options, x.get());
  return ComputeOnPhase(x.get(), data.size(), options, execution);
}

AllanResult Compute(Eigen::VectorXd&& data, const AllanOptions& options,
                    const Execution& execution) {
  CheckComputeInput(data, options, execution);
  const Eigen::Index n_samples = data.size();
  const double mean = data.mean();
  // Growing by one point reallocates in place (a large block is remapped, not copied).
  data.conservativeResize(PhaseLength(n_samples, options));
  InternalPhase(data.data(), n_samples, mean, options, data.data());
  Eigen::VectorXd x = std::move(data);  // released on return, whatever the caller does
  return ComputeOnPhase(x.data(), n_samples, options, execution);
}

namespace {

// Task boundaries over the factors (indices into ms, ending with ms.size()): OADEV's factors in
// contiguous runs of about equal work, one sweep each (a run per worker, two when several share
// the work, so the noise identification's worker can take the last), or one factor per task for
// the other estimators.
std::vector<int> TaskBoundaries(Deviation dev, const std::vector<std::int64_t>& ms, std::int64_t n,
                                int workers) {
  const int count = static_cast<int>(ms.size());
  std::vector<int> task_begin;
  if (dev == Deviation::kOadev) {
    const int runs = std::min(count, workers == 1 ? 1 : 2 * workers);
    double total = 0.0;
    for (std::int64_t m : ms) total += static_cast<double>(n - 2 * m);
    double done = 0.0;
    for (int k = 0; k < count; ++k) {
      if (done >= total * static_cast<double>(task_begin.size()) / runs) task_begin.push_back(k);
      done += static_cast<double>(n - 2 * ms[static_cast<size_t>(k)]);
    }
  } else {
    for (int k = 0; k < count; ++k) task_begin.push_back(k);
  }
  task_begin.push_back(count);
  return task_begin;
}

// The variances of factors ms[begin, end) of the phase x (n points) into variance[begin, end).
// `extended`: ExtendForTotdev's series for TOTDEV, else unused.
void EstimateVariances(Deviation dev, const double* x, std::int64_t n,
                       const std::vector<std::int64_t>& ms, int begin, int end, double tau0,
                       const std::vector<double>& extended, std::vector<double>& variance) {
  if (dev == Deviation::kOadev) {
    internal::OverlappingSecondDifferenceSums(x, n, ms.data() + begin, end - begin,
                                              variance.data() + begin);
  }
  for (int k = begin; k < end; ++k) {
    const std::int64_t m = ms[static_cast<size_t>(k)];
    const double tau = static_cast<double>(m) * tau0;
    double& v = variance[static_cast<size_t>(k)];
    switch (dev) {
      case Deviation::kOadev:
        v /= 2.0 * static_cast<double>(n - 2 * m) * tau * tau;
        break;
      case Deviation::kAdev:
        v = internal::AdevVariance(x, n, m, tau);
        break;
      case Deviation::kMdev:
      case Deviation::kTdev:
        v = internal::MdevVariance(x, n, m, tau);
        break;
      case Deviation::kHdev:
        v = internal::HdevVariance(x, n, m, tau);
        break;
      case Deviation::kOhdev:
        v = internal::OhdevVariance(x, n, m, tau);
        break;
      case Deviation::kTotdev:
        v = internal::TotdevVariance(extended, n, m, tau);
        break;
    }
  }
}

// Compute on the phase x (PhaseLength(n_samples) points) of n_samples checked samples.
AllanResult ComputeOnPhase(const double* x, Eigen::Index n_samples, const AllanOptions& options,
                           const Execution& execution) {
  AllanResult result;
  result.options = options;
  result.n_samples = n_samples;
  const std::int64_t n = PhaseLength(n_samples, options);
  result.n_phase = n;
  const Deviation dev = options.deviation;
  const std::vector<std::int64_t> ms = AveragingFactors(options, n);
  if (ms.empty()) {
    throw DataError(ToString(dev) + " needs at least " +
                    std::to_string(dev == Deviation::kHdev || dev == Deviation::kOhdev ? 4 : 3) +
                    " angle points (" + std::to_string(n) + " given)");
  }
  const double tau0 = options.tau0_s();
  std::vector<double> variance(ms.size());
  std::vector<std::optional<int>> alpha(ms.size());
  const std::vector<double> extended =
      dev == Deviation::kTotdev ? internal::ExtendForTotdev(x, n) : std::vector<double>{};

  // Tasks, handed out in order: the noise identification of every factor (two sweeps over the
  // phase, IdentifyAlphas), then the estimators' (TaskBoundaries).
  const bool want_alpha = options.confidence_intervals && !options.forced_alpha;
  const std::vector<int> task_begin = TaskBoundaries(dev, ms, n, ResolveThreads(execution.threads));
  const int first_run = want_alpha ? 1 : 0;
  const int tasks = first_run + static_cast<int>(task_begin.size()) - 1;
  ParallelFor(tasks, execution.threads, [&](int task, int) {
    if (task < first_run) {
      const Eigen::Map<const Eigen::VectorXd> xm(x, n);
      alpha = internal::IdentifyAlphas(xm, ms, options.data_type, DifferenceOrder(dev));
      return;
    }
    const size_t run = static_cast<size_t>(task - first_run);
    EstimateVariances(dev, x, n, ms, task_begin[run], task_begin[run + 1], tau0, extended,
                      variance);
  });

  int carried = FirstIdentified(alpha);
  result.points.resize(ms.size());
  for (size_t k = 0; k < ms.size(); ++k) {
    AllanPoint& p = result.points[k];
    p.m = ms[k];
    p.tau_s = static_cast<double>(p.m) * tau0;
    p.dev = std::sqrt(std::max(0.0, variance[k]));
    if (dev == Deviation::kTdev) p.dev *= p.tau_s / std::sqrt(3.0);
    p.n_terms = TermCount(dev, n, p.m);
    SetInterval(options, alpha[k], n, carried, p);
  }
  return result;
}

}  // namespace
}  // namespace gyrodrift::allan
