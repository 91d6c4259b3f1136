#include "gyrodrift/simulation/winding.h"

#include <cmath>
#include <string>

#include "common/enum_names.h"
#include "gyrodrift/common/check.h"
#include "gyrodrift/common/error.h"

namespace gyrodrift::simulation {
namespace {

// Role of each layer in one pattern period: 'A' (first half), 'B' (second half).
std::string_view PatternRoles(WindingPattern pattern) {
  switch (pattern) {
    case WindingPattern::kQuadrupole:
      return "ABBA";
    case WindingPattern::kDipole:
      return "AB";
    case WindingPattern::kOctupole:
      return "ABBABAAB";
    case WindingPattern::kConventional:
    case WindingPattern::kSymmetric:
      return "C";
  }
  return "C";
}

}  // namespace

namespace {

// "helical" is read as conventional; conventional's name is the first entry's.
constexpr gyrodrift::internal::EnumNames<WindingPattern, 6> kPatterns{{
    {WindingPattern::kQuadrupole, "quadrupole"},
    {WindingPattern::kDipole, "dipole"},
    {WindingPattern::kOctupole, "octupole"},
    {WindingPattern::kConventional, "conventional"},
    {WindingPattern::kConventional, "helical"},
    {WindingPattern::kSymmetric, "symmetric"},
}};

}  // namespace

std::string_view ToString(WindingPattern pattern) {
  return gyrodrift::internal::EnumName(pattern, kPatterns);
}

WindingPattern WindingPatternFromString(std::string_view name) {
  return gyrodrift::internal::EnumFromName(name, "winding", kPatterns);
}

int PatternPeriod(WindingPattern pattern) { return static_cast<int>(PatternRoles(pattern).size()); }

int WindingMap::LayerAt(double z_m) const {
  for (int l = 0; l < layers(); ++l) {
    for (const auto& [a, b] : pieces[static_cast<size_t>(l)]) {
      if (z_m >= a && z_m <= b) return l;
    }
  }
  ThrowOption("z_m", FormatValue(z_m), "in [0, " + FormatValue(fibre_length_m) + "]");
}

namespace {

// The checked capacity of each layer (ones when none is given).
Eigen::VectorXd CheckedCapacity(WindingPattern pattern, int layers, double fibre_length_m,
                                double asymmetry, const Eigen::VectorXd& layer_capacity) {
  const int period = PatternPeriod(pattern);
  if (layers < 1 || layers > 100000 || layers % period != 0) {
    ThrowOption("coil.layers", std::to_string(layers),
                "in [1, 100000] and a multiple of " + std::to_string(period) + " for a " +
                    std::string(ToString(pattern)) + " winding");
  }
  RequirePositive("coil.fibre_length_m", fibre_length_m);
  if (!(std::abs(asymmetry) < 0.5)) {
    ThrowOption("coil.winding_asymmetry", FormatValue(asymmetry), "in (-0.5, 0.5)");
  }
  Eigen::VectorXd capacity =
      layer_capacity.size() == 0 ? Eigen::VectorXd::Ones(layers) : Eigen::VectorXd(layer_capacity);
  if (capacity.size() != layers) {
    throw UsageError("layer_capacity has " + std::to_string(capacity.size()) + " entries for " +
                     std::to_string(layers) + " layers");
  }
  for (int l = 0; l < layers; ++l) {
    if (!(capacity[l] > 0.0) || !std::isfinite(capacity[l])) {
      ThrowOption("layer_capacity[" + std::to_string(l) + "]", FormatValue(capacity[l]),
                  "a finite number > 0");
    }
  }
  return capacity;
}

// Conventional: the fibre from one end, layer after layer, each its share of the capacity.
void WindConventional(const Eigen::VectorXd& capacity, WindingMap& map) {
  const double length = map.fibre_length_m, total_capacity = capacity.sum();
  const int layers = static_cast<int>(capacity.size());
  double z = 0.0;
  for (int l = 0; l < layers; ++l) {
    const double end = l + 1 == layers ? length : z + length * capacity[l] / total_capacity;
    map.pieces[static_cast<size_t>(l)].push_back({z, end});
    z = end;
  }
}

// Symmetric: both halves from the midpoint together, each layer holding a piece of each.
void WindSymmetric(const Eigen::VectorXd& capacity, WindingMap& map) {
  const double length = map.fibre_length_m, total_capacity = capacity.sum();
  const int layers = static_cast<int>(capacity.size());
  const double mid = 0.5 * length;
  double s = 0.0;  // distance from the midpoint already wound
  for (int l = 0; l < layers; ++l) {
    const double next = l + 1 == layers ? mid : s + mid * capacity[l] / total_capacity;
    map.pieces[static_cast<size_t>(l)].push_back({mid - next, mid - s});
    map.pieces[static_cast<size_t>(l)].push_back({length - (mid - s), length - (mid - next)});
    s = next;
  }
}

// Dipole, quadrupole, octupole: layers take turns from the two halves by the pattern's roles,
// half A (towards z = 0) holding (1 + asymmetry) / 2 of the fibre.
void WindPattern(WindingPattern pattern, const Eigen::VectorXd& capacity, WindingMap& map) {
  const std::string_view roles = PatternRoles(pattern);
  const size_t period = roles.size();
  const double length = map.fibre_length_m;
  const int layers = static_cast<int>(capacity.size());
  const double length_a = 0.5 * (1.0 + map.asymmetry) * length;
  double capacity_a = 0.0, capacity_b = 0.0;
  int last_a = -1, last_b = -1;
  for (int l = 0; l < layers; ++l) {
    if (roles[static_cast<size_t>(l) % period] == 'A') {
      capacity_a += capacity[l];
      last_a = l;
    } else {
      capacity_b += capacity[l];
      last_b = l;
    }
  }
  double z_a = length_a, z_b = length_a;  // both halves start at the fibre midpoint
  for (int l = 0; l < layers; ++l) {
    if (roles[static_cast<size_t>(l) % period] == 'A') {
      const double start = l == last_a ? 0.0 : z_a - length_a * capacity[l] / capacity_a;
      map.pieces[static_cast<size_t>(l)].push_back({start, z_a});
      z_a = start;
    } else {
      const double end =
          l == last_b ? length : z_b + (length - length_a) * capacity[l] / capacity_b;
      map.pieces[static_cast<size_t>(l)].push_back({z_b, end});
      z_b = end;
    }
  }
}

}  // namespace

WindingMap BuildWinding(WindingPattern pattern, int layers, double fibre_length_m, double asymmetry,
                        const Eigen::VectorXd& layer_capacity) {
  const Eigen::VectorXd capacity =
      CheckedCapacity(pattern, layers, fibre_length_m, asymmetry, layer_capacity);
  const double length = fibre_length_m;
  WindingMap map;
  map.fibre_length_m = length;
  map.pattern = pattern;
  map.asymmetry = asymmetry;
  map.pieces.assign(static_cast<size_t>(layers), {});
  if (pattern == WindingPattern::kConventional) {
    WindConventional(capacity, map);
  } else if (pattern == WindingPattern::kSymmetric) {
    WindSymmetric(capacity, map);
  } else {
    WindPattern(pattern, capacity, map);
  }

  map.layer_length_m = Eigen::VectorXd::Zero(layers);
  map.shupe_weight_m2 = Eigen::VectorXd::Zero(layers);
  for (int l = 0; l < layers; ++l) {
    for (const auto& [a, b] : map.pieces[static_cast<size_t>(l)]) {
      map.layer_length_m[l] += b - a;
      map.shupe_weight_m2[l] += (b - a) * (length - a - b);
    }
  }
  return map;
}

double ShupeIntegral(const WindingMap& map,
                     const Eigen::Ref<const Eigen::VectorXd>& layer_rate_k_s) {
  if (layer_rate_k_s.size() != map.shupe_weight_m2.size()) {
    throw UsageError("layer rates: " + std::to_string(layer_rate_k_s.size()) + " values for " +
                     std::to_string(map.shupe_weight_m2.size()) + " layers");
  }
  return map.shupe_weight_m2.dot(layer_rate_k_s);
}

double ShupeConstants::Scale() const {
  return refractive_index * C() / (fibre_length_m * coil_diameter_m);
}

double ShupeConstants::LinearSpreadClosedForm(double spread_k_s) const {
  return refractive_index * fibre_length_m * C() * std::abs(spread_k_s) / (6.0 * coil_diameter_m);
}

}  // namespace gyrodrift::simulation
