#include "gyrodrift/selection/kde.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unsupported/Eigen/FFT>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::selection {

namespace {

constexpr double kInvSqrt2Pi = 0.39894228040143267794;
// phi(8.5) / phi(0) = exp(-36.1) < 1e-15: the cut kernel differs from the exact one by less than
// double round-off of the largest weight.
constexpr double kKernelCutBandwidths = 8.5;

// Quantile of type 7 (linear interpolation between order statistics) of buf[0..n-1], selected
// within buf[from..n-1] (reordered): every value before `from` is at or below those after it,
// and `from` is at most the quantile's lower order statistic, whose index goes to *lower when
// asked. After one quantile, values past its lower order statistic hold the rest, so a larger
// quantile may start there and select among fewer values.
double Quantile(std::vector<double>& buf, size_t from, size_t n, double p,
                size_t* lower = nullptr) {
  const double pos = p * static_cast<double>(n - 1);
  const size_t lo = static_cast<size_t>(std::floor(pos));
  const double frac = pos - static_cast<double>(lo);
  std::nth_element(buf.begin() + static_cast<std::ptrdiff_t>(from),
                   buf.begin() + static_cast<std::ptrdiff_t>(lo),
                   buf.begin() + static_cast<std::ptrdiff_t>(n));
  if (lower != nullptr) *lower = lo;
  const double a = buf[lo];
  if (frac == 0.0 || lo + 1 >= n) return a;
  // The next order statistic is the minimum of the upper part after nth_element.
  const double b = *std::min_element(buf.begin() + static_cast<std::ptrdiff_t>(lo) + 1,
                                     buf.begin() + static_cast<std::ptrdiff_t>(n));
  return a + frac * (b - a);
}

size_t NextPowerOfTwo(size_t n) {
  size_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

}  // namespace

struct KdeWorkspace::Impl {
  std::vector<double> scratch;  // quantiles
  std::vector<double> bins;     // linear-binning weights, zero padded to the FFT length
  std::vector<double> kernel;   // sampled kernel, wrapped for circular convolution
  std::vector<double> conv;     // convolution output
  std::vector<std::complex<double>> bins_spectrum;
  std::vector<std::complex<double>> kernel_spectrum;
  Eigen::FFT<double> fft;
  Impl() { fft.SetFlag(Eigen::FFT<double>::HalfSpectrum); }
};

struct KdeAccess {
  static KdeWorkspace::Impl& Get(KdeWorkspace& w) { return *w.impl_; }
};

KdeWorkspace::KdeWorkspace() : impl_(std::make_unique<Impl>()) {}
KdeWorkspace::~KdeWorkspace() = default;
KdeWorkspace::KdeWorkspace(KdeWorkspace&&) noexcept = default;
KdeWorkspace& KdeWorkspace::operator=(KdeWorkspace&&) noexcept = default;

namespace {

constexpr gyrodrift::internal::EnumNames<KdeMethod, 2> kKdeMethods{{
    {KdeMethod::kBinnedFft, "binned-fft"},
    {KdeMethod::kDirect, "direct"},
}};

}  // namespace

std::string_view ToString(KdeMethod method) {
  return gyrodrift::internal::EnumName(method, kKdeMethods);
}

KdeMethod KdeMethodFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "method", kKdeMethods);
}

void KdeOptions::Validate() const {
  if (grid_points < 16 || grid_points > (1 << 24)) {
    ThrowOption("grid_points", std::to_string(grid_points), "an integer in [16, 16777216]");
  }
  if (max_grid_points < grid_points || max_grid_points > (1 << 24)) {
    ThrowOption("max_grid_points", std::to_string(max_grid_points),
                "an integer in [grid_points, 16777216]");
  }
  RequireInRange("points_per_bandwidth", points_per_bandwidth, 0.0, 100.0);
  RequirePositive("bandwidth_scale", bandwidth_scale);
  RequireInRange("padding_bandwidths", padding_bandwidths, 0.0, 20.0);
  if (method != KdeMethod::kBinnedFft && method != KdeMethod::kDirect) {
    ThrowOption("method", std::to_string(static_cast<int>(method)), "binned-fft or direct");
  }
}

Grid MakeGrid(double lo, double hi, double min_bandwidth, const KdeOptions& options) {
  Grid grid;
  grid.lo = lo;
  const double span = hi - lo;
  int points = options.grid_points;
  if (options.points_per_bandwidth > 0.0 && min_bandwidth > 0.0) {
    const double wanted_step = min_bandwidth / options.points_per_bandwidth;
    const double needed = std::ceil(span / wanted_step) + 1.0;
    if (needed > options.max_grid_points) {
      points = options.max_grid_points;
      grid.under_resolved = true;
    } else if (needed > points) {
      points = static_cast<int>(needed);
    }
  }
  grid.points = points;
  grid.step = span / (points - 1);
  return grid;
}

double SilvermanBandwidth(const Eigen::Ref<const Eigen::VectorXd>& x, KdeWorkspace* workspace) {
  const Eigen::Index n = x.size();
  if (n < 2) return 0.0;
  const double mean = x.mean();
  const double sd = std::sqrt((x.array() - mean).square().sum() / static_cast<double>(n - 1));
  if (!(sd > 0.0)) return 0.0;
  auto& buf = KdeAccess::Get(*workspace).scratch;
  const size_t count = static_cast<size_t>(n);
  if (buf.size() < count) buf.resize(count);
  for (Eigen::Index i = 0; i < n; ++i) buf[static_cast<size_t>(i)] = x[i];
  size_t q1_index = 0;
  const double q1 = Quantile(buf, 0, count, 0.25, &q1_index);
  const double q3 = Quantile(buf, q1_index, count, 0.75);
  const double iqr_sd = (q3 - q1) / 1.34;
  const double spread = iqr_sd > 0.0 ? std::min(sd, iqr_sd) : sd;
  return 0.9 * spread * std::pow(static_cast<double>(n), -0.2);
}

double SilvermanBandwidth(const Eigen::Ref<const Eigen::VectorXd>& x) {
  KdeWorkspace workspace;
  return SilvermanBandwidth(x, &workspace);
}

void EstimateDensity(const Eigen::Ref<const Eigen::VectorXd>& x, double shift, double scale,
                     double h, const Grid& grid, KdeMethod method, KdeWorkspace* workspace,
                     Eigen::Ref<Eigen::VectorXd> density) {
  const Eigen::Index n = x.size();
  const int m = grid.points;
  const double inv_scale = 1.0 / scale;
  const double inv_nh = 1.0 / (static_cast<double>(n) * h);

  if (method == KdeMethod::kDirect) {
    const double inv_h = 1.0 / h;
    for (int j = 0; j < m; ++j) {
      const double g = grid.At(j);
      double sum = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double u = ((x[i] - shift) * inv_scale - g) * inv_h;
        sum += std::exp(-0.5 * u * u);
      }
      density[j] = sum * kInvSqrt2Pi * inv_nh;
    }
    return;
  }

  auto& w = KdeAccess::Get(*workspace);
  const double ratio = h / grid.step;
  const size_t half =
      static_cast<size_t>(std::min<double>(m - 1, std::ceil(kKernelCutBandwidths * ratio)));
  const size_t p = NextPowerOfTwo(static_cast<size_t>(m) + half);
  w.bins.assign(p, 0.0);
  w.kernel.assign(p, 0.0);
  w.conv.resize(p);

  // Linear binning: a sample between g_j and g_j+1 gives weight (1 - t) to j and t to j + 1.
  // Samples outside the grid are dropped (grids from MakeGrid cover the data with padding).
  const double inv_step = 1.0 / grid.step;
  const double last = static_cast<double>(m - 1);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = ((x[i] - shift) * inv_scale - grid.lo) * inv_step;
    if (!(t >= 0.0 && t <= last)) continue;
    const double fl = std::floor(t);
    size_t j = static_cast<size_t>(fl);
    double frac = t - fl;
    if (j + 1 >= static_cast<size_t>(m)) {  // t == last
      j = static_cast<size_t>(m) - 2;
      frac = 1.0;
    }
    w.bins[j] += 1.0 - frac;
    w.bins[j + 1] += frac;
  }

  // Kernel weights at offsets -half..half, stored circularly (negative offsets at the end).
  const double inv_ratio = 1.0 / ratio;
  for (size_t l = 0; l <= half; ++l) {
    const double u = static_cast<double>(l) * inv_ratio;
    const double value = std::exp(-0.5 * u * u) * kInvSqrt2Pi * inv_nh;
    w.kernel[l] = value;
    if (l > 0) w.kernel[p - l] = value;
  }

  // p >= m + half, so the circular convolution equals the linear one on 0..m-1.
  w.bins_spectrum.resize(p / 2 + 1);
  w.kernel_spectrum.resize(p / 2 + 1);
  const auto np = static_cast<Eigen::Index>(p);
  w.fft.fwd(w.bins_spectrum.data(), w.bins.data(), np);
  w.fft.fwd(w.kernel_spectrum.data(), w.kernel.data(), np);
  for (size_t k = 0; k <= p / 2; ++k) w.bins_spectrum[k] *= w.kernel_spectrum[k];
  w.fft.inv(w.conv.data(), w.bins_spectrum.data(), np);
  // FFT round-off leaves values of order 1e-17 * peak where the density is zero; a density is
  // never negative.
  for (int j = 0; j < m; ++j) density[j] = std::max(0.0, w.conv[static_cast<size_t>(j)]);
}

Kde EstimateKde(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& options) {
  options.Validate();
  RequireFiniteSignal("x", x, 2);
  KdeWorkspace workspace;
  const double h = options.bandwidth_scale * SilvermanBandwidth(x, &workspace);
  if (!(h > 0.0)) throw DataError("x: constant sample, its density has no bandwidth");
  const double pad = options.padding_bandwidths * h;
  Kde kde;
  kde.bandwidth = h;
  kde.grid = MakeGrid(x.minCoeff() - pad, x.maxCoeff() + pad, h, options);
  kde.density.resize(kde.grid.points);
  EstimateDensity(x, 0.0, 1.0, h, kde.grid, options.method, &workspace, kde.density);
  return kde;
}

}  // namespace gyrodrift::selection
