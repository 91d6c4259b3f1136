// SelectModes in named steps: the checks, the KDE of x and of every IMF on one common grid, the
// distances D_k and G_k, then the curves and boundary rules of the chosen criterion
// (pdf_similarity.cc, criteria.cc) and the groups. Also the criterion and group names, and
// DecomposeAndSelect.
#include "gyrodrift/selection/selection.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <utility>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"
#include "gyrodrift/common/parallel.h"
#include "gyrodrift/decomposition/energy_band.h"
#include "selection/criteria.h"
#include "selection/density_scratch.h"

namespace gyrodrift::selection {

namespace {

constexpr std::array<std::pair<Criterion, std::string_view>, 3> kCriteria{{
    {Criterion::kPdfSimilarity, "pdf"},
    {Criterion::kKomaty, "komaty"},
    {Criterion::kEnergyModel, "energy"},
}};
constexpr std::array<std::pair<GroupKind, std::string_view>, 3> kKinds{{
    {GroupKind::kNoise, "noise"},
    {GroupKind::kMixed, "mixed"},
    {GroupKind::kDrift, "drift"},
}};

using gyrodrift::internal::EnumFromName;
using gyrodrift::internal::EnumName;
using internal::AppendNote;

// "1-4" or "5" or "" for a list of consecutive indices.
std::string Range(const std::vector<int>& imfs) {
  if (imfs.empty()) return "";
  if (imfs.size() == 1) return std::to_string(imfs.front());
  return std::to_string(imfs.front()) + "-" + std::to_string(imfs.back());
}

}  // namespace

std::string_view ToString(Criterion criterion) { return EnumName(criterion, kCriteria); }
Criterion CriterionFromString(std::string_view name) {
  return EnumFromName(name, "criterion", kCriteria);
}
std::string_view ToString(GroupKind kind) { return EnumName(kind, kKinds); }
GroupKind GroupKindFromString(std::string_view name) { return EnumFromName(name, "group", kKinds); }

void SelectionOptions::Validate() const {
  if (criterion != Criterion::kPdfSimilarity && criterion != Criterion::kKomaty &&
      criterion != Criterion::kEnergyModel) {
    ThrowOption("criterion", std::to_string(static_cast<int>(criterion)), "pdf, komaty or energy");
  }
  if (ToString(distance) == "?") {
    ThrowOption("distance", std::to_string(static_cast<int>(distance)),
                "l2, l1, hellinger, jensen-shannon or bhattacharyya");
  }
  ValidateNested("kde", [&] { kde.Validate(); });
  ValidateNested("monte_carlo", [&] { monte_carlo.Validate(); });
  decomposition::ValidateBandConfidence(band_confidence);
}

const ModeGroup* SelectionResult::Group(GroupKind kind) const {
  for (const auto& g : groups) {
    if (g.kind == kind) return &g;
  }
  return nullptr;
}

std::string SelectionResult::Summary() const {
  std::string s = std::string(ToString(criterion)) + "/" + std::string(ToString(distance)) +
                  ": K=" + std::to_string(num_imfs) + " k*=" + std::to_string(k_star);
  if (criterion == Criterion::kPdfSimilarity) {
    s += " k_N=" + std::to_string(k_noise) +
         " (level R=" + std::to_string(noise_level_realisations) +
         " seed=" + std::to_string(noise_level_seed) + ")";
  }
  if (criterion == Criterion::kEnergyModel) {
    s += " band exit=" + std::to_string(energy_signal_start);
  }
  for (const auto& g : groups) {
    s += " " + std::string(ToString(g.kind)) + "{" + Range(g.imfs);
    if (g.has_residue) s += g.imfs.empty() ? "r" : "+r";
    s += "}";
  }
  s += " grid=" + std::to_string(grid_points);
  if (grid_under_resolved) s += " (under-resolved)";
  if (!note.empty()) s += "; " + note;
  return s;
}

SelectionResult SelectModes(const Eigen::Ref<const Eigen::VectorXd>& x,
                            const decomposition::Decomposition& decomposition,
                            const SelectionOptions& options, const Execution& execution) {
  return SelectModes(x, decomposition.imfs, decomposition.residue, options, execution);
}

GroupedDecomposition DecomposeAndSelect(
    const Eigen::Ref<const Eigen::VectorXd>& x,
    const decomposition::DecompositionOptions& decomposition_options, SelectionOptions options,
    decomposition::DecompositionContext context) {
  NoiseLevelCollector white_noise(static_cast<int>(x.size()), options.monte_carlo, options.kde,
                                  options.distance);
  if (options.criterion == Criterion::kPdfSimilarity && !options.noise_level) {
    white_noise.Attach(decomposition_options, &context);
  }
  GroupedDecomposition out;
  out.decomposition = decomposition::Decompose(x, decomposition_options, context);
  if (out.decomposition.num_imfs() == 0) return out;
  if (!options.noise_level) options.noise_level = white_noise.Level();
  out.selection = SelectModes(x, out.decomposition, options, context.execution);
  return out;
}

namespace {

// The caller's mistakes: bad options or threads, a short or non-finite signal, a decomposition
// that does not match it, a supplied level of another length.
void CheckInputs(const Eigen::Ref<const Eigen::VectorXd>& x,
                 const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                 const Eigen::Ref<const Eigen::VectorXd>& residue, const SelectionOptions& options,
                 const Execution& execution) {
  options.Validate();
  execution.Validate();
  RequireFiniteSignal("x", x, 16);
  const Eigen::Index n = x.size();
  if (imfs.cols() < 1) throw DataError("imfs: the decomposition has no IMF, nothing to select");
  if (imfs.rows() != n) {
    throw DataError("imfs: " + std::to_string(imfs.rows()) + " rows for a signal of " +
                    std::to_string(n) + " samples");
  }
  if (residue.size() != n) {
    throw DataError("residue: " + std::to_string(residue.size()) + " samples for a signal of " +
                    std::to_string(n));
  }
  if (!imfs.allFinite()) throw DataError("imfs: non-finite value");
  if (!residue.allFinite()) throw DataError("residue: non-finite value");
  if (options.criterion == Criterion::kPdfSimilarity && options.noise_level &&
      options.noise_level->length != n) {
    ThrowOption("noise_level", "length " + std::to_string(options.noise_level->length),
                "a level computed for the signal's length " + std::to_string(n));
  }
}

// max_t |x - (sum_k imf_k + residue)| / max_t |x|: reported, not enforced (EEMD is not
// complete).
double ReconstructionError(const Eigen::Ref<const Eigen::VectorXd>& x,
                           const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                           const Eigen::Ref<const Eigen::VectorXd>& residue) {
  Eigen::VectorXd sum = residue;
  for (Eigen::Index k = 0; k < imfs.cols(); ++k) sum += imfs.col(k);
  const double scale = x.cwiseAbs().maxCoeff();
  const double err = (x - sum).cwiseAbs().maxCoeff();
  return scale > 0.0 ? err / scale : err;
}

// Silverman bandwidths of every IMF (index k - 1), on the workers' scratch.
std::vector<double> ImfBandwidths(const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                                  const KdeOptions& kde, std::vector<internal::Scratch>& scratch) {
  const int k_count = static_cast<int>(imfs.cols());
  std::vector<double> h(static_cast<size_t>(k_count));
  ParallelFor(k_count, static_cast<int>(scratch.size()), [&](int k, int w) {
    h[static_cast<size_t>(k)] =
        kde.bandwidth_scale * SilvermanBandwidth(imfs.col(k), &scratch[static_cast<size_t>(w)].kde);
  });
  return h;
}

// One common grid over the (shifted) signal and every IMF, padded by each density's own
// bandwidths, resolving the narrowest density (docs/selection.md section 1).
Grid CommonGrid(const Eigen::Ref<const Eigen::VectorXd>& x, double shift, double h_x,
                const Eigen::Ref<const Eigen::MatrixXd>& imfs, const std::vector<double>& h,
                const KdeOptions& kde) {
  double lo = x.minCoeff() - shift - kde.padding_bandwidths * h_x;
  double hi = x.maxCoeff() - shift + kde.padding_bandwidths * h_x;
  double h_min = h_x;
  for (Eigen::Index k = 0; k < imfs.cols(); ++k) {
    const double hk = h[static_cast<size_t>(k)];
    lo = std::min(lo, imfs.col(k).minCoeff() - kde.padding_bandwidths * hk);
    hi = std::max(hi, imfs.col(k).maxCoeff() + kde.padding_bandwidths * hk);
    if (hk > 0.0) h_min = std::min(h_min, hk);
  }
  return MakeGrid(lo, hi, h_min, kde);
}

// The curves every criterion starts from: D_k (the signal's density against IMF k's on the common
// grid) and G_k (IMF k's standardised density against N(0, 1)), with the grid diagnostics.
void DensityCurves(const Eigen::Ref<const Eigen::VectorXd>& x,
                   const Eigen::Ref<const Eigen::MatrixXd>& imfs, const SelectionOptions& options,
                   const Execution& execution, SelectionResult* result) {
  const KdeOptions& kde = options.kde;
  const int k_count = static_cast<int>(imfs.cols());
  const int workers = std::min(ResolveThreads(execution.threads), k_count + 1);
  std::vector<internal::Scratch> scratch(static_cast<size_t>(workers));
  // The bandwidth of x is the same centred or not.
  const double h_x = kde.bandwidth_scale * SilvermanBandwidth(x, &scratch[0].kde);
  if (!(h_x > 0.0)) throw DataError("x: constant signal, nothing to select");
  result->signal_bandwidth = h_x;
  const std::vector<double> h = ImfBandwidths(imfs, kde, scratch);
  const double shift = options.center_signal ? x.mean() : 0.0;
  const Grid grid = CommonGrid(x, shift, h_x, imfs, h, kde);
  result->grid_points = grid.points;
  result->grid_under_resolved = grid.under_resolved;

  Eigen::VectorXd pdf_x(grid.points);
  EstimateDensity(x, shift, 1.0, h_x, grid, kde.method, &scratch[0].kde, pdf_x);
  result->pdf_distance.assign(static_cast<size_t>(k_count), 0.0);
  result->self_distance.assign(static_cast<size_t>(k_count), 0.0);
  ParallelFor(k_count, workers, [&](int k, int w) {
    internal::Scratch& s = scratch[static_cast<size_t>(w)];
    // A constant IMF (zero bandwidth) is a spike: give it one grid step of bandwidth.
    double hk = h[static_cast<size_t>(k)];
    if (!(hk > 0.0)) hk = grid.step;
    s.common.resize(grid.points);
    EstimateDensity(imfs.col(k), 0.0, 1.0, hk, grid, kde.method, &s.kde, s.common);
    result->pdf_distance[static_cast<size_t>(k)] =
        Distance(options.distance, pdf_x, s.common, grid.step);
    result->self_distance[static_cast<size_t>(k)] =
        internal::SelfSimilarity(imfs.col(k), kde, options.distance, &s);
  });
  if (std::any_of(h.begin(), h.end(), [](double hk) { return !(hk > 0.0); })) {
    AppendNote(&result->note, "constant IMF (density given one grid step)");
  }
}

// k_noise and mixed_end by the chosen criterion's rule (criteria.h).
void Boundaries(int length, const SelectionOptions& options, const Execution& execution,
                SelectionResult* result) {
  switch (options.criterion) {
    case Criterion::kPdfSimilarity:
      internal::PdfSimilarityBoundaries(length, options, execution, result);
      break;
    case Criterion::kKomaty:
      internal::KomatyBoundaries(result);
      break;
    case Criterion::kEnergyModel:
      internal::EnergyModelBoundaries(result);
      break;
  }
  if (result->mixed_end == result->num_imfs) {
    AppendNote(&result->note, "drift group is the residue alone");
  }
}

// Groups: noise 1..k_noise, mixed k_noise+1..mixed_end, drift mixed_end+1..K + residue; empty
// groups dropped, each series summed in increasing k, the residue last.
void FormGroups(const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                const Eigen::Ref<const Eigen::VectorXd>& residue, SelectionResult* result) {
  auto make_group = [&](GroupKind kind, int first, int last, bool with_residue) {
    ModeGroup g;
    g.kind = kind;
    g.has_residue = with_residue;
    g.series = Eigen::VectorXd::Zero(imfs.rows());
    for (int k = first; k <= last; ++k) {
      g.imfs.push_back(k);
      g.series += imfs.col(k - 1);
    }
    if (with_residue) g.series += residue;
    return g;
  };
  if (result->k_noise >= 1) {
    result->groups.push_back(make_group(GroupKind::kNoise, 1, result->k_noise, false));
  }
  if (result->mixed_end > result->k_noise) {
    result->groups.push_back(
        make_group(GroupKind::kMixed, result->k_noise + 1, result->mixed_end, false));
  }
  result->groups.push_back(
      make_group(GroupKind::kDrift, result->mixed_end + 1, result->num_imfs, true));
}

}  // namespace

SelectionResult SelectModes(const Eigen::Ref<const Eigen::VectorXd>& x,
                            const Eigen::Ref<const Eigen::MatrixXd>& imfs,
                            const Eigen::Ref<const Eigen::VectorXd>& residue,
                            const SelectionOptions& options, const Execution& execution) {
  CheckInputs(x, imfs, residue, options, execution);
  SelectionResult result;
  result.criterion = options.criterion;
  result.distance = options.distance;
  result.length = static_cast<int>(x.size());
  result.num_imfs = static_cast<int>(imfs.cols());
  result.reconstruction_error = ReconstructionError(x, imfs, residue);
  DensityCurves(x, imfs, options, execution, &result);
  result.k_star = internal::KStar(result.pdf_distance);
  internal::EnergyCurve(imfs, options.band_confidence, &result);
  Boundaries(result.length, options, execution, &result);
  FormGroups(imfs, residue, &result);
  return result;
}

}  // namespace gyrodrift::selection
