// Gaussian kernel density estimates on a uniform grid, for the PDF-similarity mode selection.
//
// Computes f(g) = 1/(n h) * sum_i phi((g - x_i) / h) at the points g of a uniform grid, with the
// Gaussian kernel phi and Silverman's rule-of-thumb bandwidth
//   h = 0.9 * min(sd, IQR / 1.34) * n^(-1/5)          (Silverman 1986, eq. 3.31)
// (sd alone when the IQR is zero).
// Two evaluations:
//   kBinnedFft  linear binning of the samples onto the grid (Jones & Lotwick 1984; Wand 1994,
//               J. Comput. Graph. Stat. 3(4)), then a linear convolution of the bin weights with
//               the sampled kernel through a zero-padded FFT (Eigen's unsupported FFT module,
//               kissfft backend). Cost O(n + P log P), P = next power of two >= grid + kernel
//               half-width; about 1 ms for n = 1e5 and a 512-point grid.
//               Error against the exact estimate, per grid point: at most
//               step^2 / (8 sqrt(2 pi) h^3) (linear-interpolation error of the kernel between two
//               grid points) plus FFT round-off; the kernel is cut at 8.5 h (weights < 1e-16).
//   kDirect     the exact sum, O(n * grid); the reference the binned estimate is tested against.
// Units: the grid has the units of the data, densities the inverse units.
#pragma once

#include <Eigen/Core>
#include <complex>
#include <memory>
#include <string_view>
#include <vector>

namespace gyrodrift::selection {

enum class KdeMethod {
  kBinnedFft,  // linear binning + FFT convolution (default)
  kDirect,     // exact O(n * grid) sum
};
std::string_view ToString(KdeMethod method);
KdeMethod KdeMethodFromString(std::string_view name);  // "binned-fft", "direct"; throws UsageError

struct KdeOptions {
  // Grid points, >= 16. METHOD.md section 4 uses 512. This is the minimum: see
  // points_per_bandwidth.
  int grid_points = 512;
  // The grid is refined (more points over the same span) until its step is at most
  // bandwidth / points_per_bandwidth for the narrowest density on it, so narrow IMF densities on
  // a grid spanning the whole signal are resolved. 0 disables the refinement. Range [0, 100].
  double points_per_bandwidth = 3.0;
  // Cap for the refinement, >= grid_points. Densities still narrower are flagged
  // (Grid::under_resolved).
  int max_grid_points = 1 << 16;
  // Multiplies Silverman's bandwidth, > 0 (1 = the rule of thumb itself).
  double bandwidth_scale = 1.0;
  // The grid extends this many bandwidths beyond the smallest and largest sample, [0, 20]; at 5 the
  // kernel mass left outside the grid is below 3e-7 of one sample's weight.
  double padding_bandwidths = 5.0;
  KdeMethod method = KdeMethod::kBinnedFft;

  void Validate() const;  // throws UsageError naming the field, value and allowed range
  bool operator==(const KdeOptions&) const = default;
};

// A uniform grid g_j = lo + j * step, j = 0..points-1.
struct Grid {
  double lo = 0.0;
  double step = 1.0;
  int points = 0;
  // The refinement hit max_grid_points before reaching points_per_bandwidth.
  bool under_resolved = false;
  double At(int j) const { return lo + j * step; }
  double hi() const { return At(points - 1); }
};

// Grid over [lo, hi] with at least options.grid_points points and, unless capped, a step of at
// most min_bandwidth / options.points_per_bandwidth. min_bandwidth > 0; hi > lo.
Grid MakeGrid(double lo, double hi, double min_bandwidth, const KdeOptions& options);

// Reusable buffers, FFT plans and a scratch copy for the bandwidth's quantiles: one per thread;
// repeated estimates of the same size then allocate nothing.
class KdeWorkspace {
 public:
  KdeWorkspace();
  ~KdeWorkspace();
  KdeWorkspace(KdeWorkspace&&) noexcept;
  KdeWorkspace& operator=(KdeWorkspace&&) noexcept;

 private:
  friend struct KdeAccess;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Silverman's bandwidth of x (before bandwidth_scale); 0 for a constant sample. x has >= 2
// finite samples (not checked here; the public entry points check).
double SilvermanBandwidth(const Eigen::Ref<const Eigen::VectorXd>& x, KdeWorkspace* workspace);
double SilvermanBandwidth(const Eigen::Ref<const Eigen::VectorXd>& x);

// Density of the affine image (x - shift) / scale of the sample, bandwidth h (in the units of the
// image), at the points of `grid` (also in the image's units), written to `density` (grid.points
// entries). shift = 0, scale = 1 gives the density of x itself; the affine form lets callers
// estimate centred or standardised samples without copying them. scale > 0, h > 0.
void EstimateDensity(const Eigen::Ref<const Eigen::VectorXd>& x, double shift, double scale,
                     double h, const Grid& grid, KdeMethod method, KdeWorkspace* workspace,
                     Eigen::Ref<Eigen::VectorXd> density);

// A density estimate together with its grid and bandwidth.
struct Kde {
  Grid grid;
  double bandwidth = 0.0;
  Eigen::VectorXd density;  // grid.points values
};

// KDE of x on its own grid: Silverman bandwidth times bandwidth_scale, grid padded by
// padding_bandwidths. Throws UsageError (bad options) or DataError (fewer than 2 samples, a
// non-finite sample, a constant sample).
Kde EstimateKde(const Eigen::Ref<const Eigen::VectorXd>& x, const KdeOptions& options = {});

}  // namespace gyrodrift::selection
