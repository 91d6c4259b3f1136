// Winding map (fibre position z -> coil layer) and the Shupe rate error it produces.
//
// What it computes
//   The Shupe error (Shupe, Appl. Opt. 19(5) 1980; METHOD.md sec. 1, paper eq. 2-3 with the
//   rate dT/dt in the integrand):
//     Omega_S = n C / (L D) * integral_0^L dT/dt(z, t) (L - 2z) dz   [rad/s],
//     C = dn/dT + n alpha (thermo-optic coefficient plus the fibre's expansion), z along the fibre.
//   In the 1-D radial thermal model every layer has one temperature, so the integral is
//   sum_l w_l dT_l/dt with the layer weights w_l = sum over the fibre pieces [a, b] lying in layer
//   l of integral_a^b (L - 2z) dz = (b - a)(L - a - b)   [m^2].
//   Patterns (layers counted from the hub outwards; the fibre midpoint z = L_A is wound first):
//     quadrupole   ABBA ABBA ...: half A (z from L_A down to 0) and half B (z from L_A up to L)
//                  alternate so that pairs of equal distance from the midpoint sit in adjacent
//                  layers with alternating order (Frigo, Proc. SPIE 412, 1983).
//     dipole       ABAB ... (first-order cancellation only).
//     octupole     ABBABAAB ...
//     conventional one end to the other, layer after layer from the hub ("helical" winding):
//                  no symmetry, the worst case.
//     symmetric    every layer holds z and L - z in equal amounts: the ideal that cancels the
//                  Shupe term exactly (a reference for checks, not a real winding).
//   Asymmetry (A/B patterns only): half A holds L_A = (1 + asymmetry) L / 2 of the fibre and half
//   B the rest, so the points equally far from the midpoint no longer share a layer position;
//   the midpoint moves by asymmetry * L / 2. Each half fills its layers in proportion to their
//   capacity (fibre per layer; the simulator makes it proportional to the layer radius, i.e. the
//   same number of turns in every layer).
//   Closed-form check: a conventional coil whose rate varies linearly along the fibre,
//   dT/dt(z) = r0 + s z / L, gives integral = -s L^2 / 6, so |Omega_S| = n L C s / (6 D).
// Units: lengths in m, rates in K/s, Omega in rad/s.
// Cost: building the map is O(layers); ShupeIntegral is one dot product of length `layers`.
#pragma once

#include <Eigen/Core>
#include <string_view>
#include <utility>
#include <vector>

namespace gyrodrift::simulation {

enum class WindingPattern { kQuadrupole, kDipole, kOctupole, kConventional, kSymmetric };
std::string_view ToString(WindingPattern pattern);
// "quadrupole", "dipole", "octupole", "conventional" (also "helical"), "symmetric";
// throws UsageError.
WindingPattern WindingPatternFromString(std::string_view name);
// Layers per repeat of the pattern (ABBA: 4); the layer count must be a multiple of it.
int PatternPeriod(WindingPattern pattern);

struct WindingMap {
  double fibre_length_m = 0.0;
  WindingPattern pattern = WindingPattern::kQuadrupole;
  double asymmetry = 0.0;
  // Pieces of fibre [z_start, z_end] (z_start < z_end) held by each layer, hub outwards.
  std::vector<std::vector<std::pair<double, double>>> pieces;
  // Fibre length in each layer (m) and the Shupe weights w_l (m^2).
  Eigen::VectorXd layer_length_m;
  Eigen::VectorXd shupe_weight_m2;

  int layers() const { return static_cast<int>(pieces.size()); }
  // Layer holding fibre position z in [0, L] (the first one at a shared end point).
  int LayerAt(double z_m) const;
};

// Builds the map. layer_capacity (length `layers`, all > 0) is the relative amount of fibre each
// layer takes; empty means equal. asymmetry in (-0.5, 0.5). Throws UsageError for bad arguments
// (including a layer count that is not a multiple of the pattern period).
WindingMap BuildWinding(WindingPattern pattern, int layers, double fibre_length_m, double asymmetry,
                        const Eigen::VectorXd& layer_capacity = {});

// sum_l w_l dT_l/dt: the Shupe integral for layer temperature rates (K/s), in K m^2 / s.
double ShupeIntegral(const WindingMap& map,
                     const Eigen::Ref<const Eigen::VectorXd>& layer_rate_k_s);

// Optical constants of the Shupe scale factor.
struct ShupeConstants {
  double refractive_index = 1.468;  // n (effective group index of the fibre mode)
  double dn_dt_per_k = 1e-5;        // dn/dT, 1/K
  double expansion_per_k = 5.5e-7;  // alpha of silica, 1/K
  double fibre_length_m = 1000.0;   // L
  double coil_diameter_m = 0.1;     // D (mean)
  double C() const { return dn_dt_per_k + refractive_index * expansion_per_k; }
  // n C / (L D): rad/s per unit of the Shupe integral (K m^2 / s).
  double Scale() const;
  // |Omega_S| of a conventional coil with a rate spread of spread_k_s from one fibre end to the
  // other: n L C spread / (6 D), rad/s.
  double LinearSpreadClosedForm(double spread_k_s) const;
};

}  // namespace gyrodrift::simulation
