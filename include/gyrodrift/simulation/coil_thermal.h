// Heat flow into a fibre coil: the winding pack as a 1-D radial conduction problem.
//
// What it computes
//   The pack is an annulus r_in <= r <= r_out (per unit height; axial flow neglected), split into
//   equal-width rings, one per fibre layer. Finite volumes of the cylindrical heat equation
//     dT/dt = a (1/r) d/dr (r dT/dr),   a = k / (rho c_p)
//   with Robin (film) boundaries -k dT/dr = h (T - T_b) on both faces: the inner face sees the
//   case through the hub/spool (h_in), the outer face through the air gap and potting (h_out).
//   Time stepping is the theta scheme (backward Euler, theta = 1, L-stable: no ringing for steps
//   far above the cell time dr^2/a; Crank-Nicolson, theta = 1/2, second order but rings for large
//   steps). Each step is one tridiagonal (Thomas) solve whose factors are cached per step length.
//   LagStep is the exact solution of a first-order lag over a step with a linearly varying input;
//   the simulator uses it for the case (chamber -> case) and the temperature sensor.
// References: H. S. Carslaw, J. C. Jaeger, "Conduction of Heat in Solids", 2nd ed. (1959),
//   sec. 3.3 (slab step response) and 7.2 (steady radial flow); S. V. Patankar, "Numerical Heat
//   Transfer and Fluid Flow" (1980), ch. 4 (finite volumes, half-cell boundary resistance).
// Units: temperatures in degC (differences in K), radii in m, time in s, a in m^2/s, k in W/(m K),
//   h in W/(m^2 K).
// Cost: Step is O(cells) and allocates nothing; a change of step length refactorises in O(cells).
#pragma once

#include <Eigen/Core>
#include <string_view>

namespace gyrodrift::simulation {

enum class ThermalScheme { kBackwardEuler, kCrankNicolson };
std::string_view ToString(ThermalScheme scheme);               // "backward-euler", "crank-nicolson"
ThermalScheme ThermalSchemeFromString(std::string_view name);  // throws UsageError

// Thermal properties of the winding pack and its mounting. Defaults: navigation coil
// (docs/simulation.md, table "thermal").
struct ThermalParameters {
  // Effective diffusivity a of the fibre/adhesive pack, m^2/s, in [1e-8, 1e-5]. Default 1.5e-7
  // (METHOD.md sec. 1 gives 1e-7..3e-7 for coil packs).
  double diffusivity_m2_s = 1.5e-7;
  // Effective conductivity k of the pack, W/(m K), in [0.01, 50]. Default 0.25 (with a this means
  // rho c_p = 1.67 MJ/(m^3 K), typical of glass/acrylate/epoxy composites).
  double conductivity_w_mk = 0.25;
  // Film conductance case -> outer face, W/(m^2 K), in [0.01, 1e9]. Default 8 (still air gap and
  // potting; 1e9 is effectively a fixed-temperature face).
  double outer_conductance_w_m2k = 8.0;
  // Film conductance case -> inner face (through the hub), W/(m^2 K), in [0.01, 1e9]. Default 3.
  // h_in != h_out is what gives the pack a radial gradient, the source of the quadrupole residue.
  double inner_conductance_w_m2k = 3.0;
  // First-order time constant of the case following the chamber air, s, in [1, 1e6].
  // Default 1200 (20 min; a navigation IMU housing in forced chamber air).
  double case_time_constant_s = 1200.0;
  ThermalScheme scheme = ThermalScheme::kBackwardEuler;
  // Largest internal step of the conduction solver, s, in [1e-4, 3600]. Each output interval is
  // split into ceil(interval / max_step_s) equal steps. Default 0.25 s (about the 0.42 s cell time
  // dr^2/a of the navigation pack, so the layer rates are accurate to well under 1 %).
  double max_step_s = 0.25;

  void Validate() const;  // throws UsageError "<field> = <value>: must be <rule>"
};

// Exact state after `step_s` seconds of tau dx/dt = u - x, with u going linearly from u_old to
// u_new over the step.
double LagStep(double x, double u_old, double u_new, double step_s, double tau_s);

class RadialConduction {
 public:
  // Annulus inner_radius_m < outer_radius_m cut into `cells` >= 1 rings of equal width.
  // Throws UsageError for bad geometry or parameters.
  RadialConduction(double inner_radius_m, double outer_radius_m, int cells,
                   const ThermalParameters& params);

  void SetUniform(double temperature_c);
  void SetTemperatures(const Eigen::Ref<const Eigen::VectorXd>& temperature_c);
  // Advances `step_s` seconds; the boundary (case-side) temperatures go linearly from *_old to
  // *_new over the step. Backward Euler uses the new values, Crank-Nicolson the mean.
  void Step(double step_s, double inner_old_c, double inner_new_c, double outer_old_c,
            double outer_new_c);

  // Ring temperatures, inner to outer, degC.
  const Eigen::VectorXd& temperature_c() const { return t_; }
  // Volume-weighted mean temperature of the pack, degC.
  double MeanTemperature() const;
  // Ring centre radii (m) and volumes per unit height and radian (m^2, r * dr).
  const Eigen::VectorXd& cell_radius_m() const { return radius_; }
  const Eigen::VectorXd& cell_volume_m2() const { return volume_; }
  int cells() const { return static_cast<int>(t_.size()); }

  // Steady state with the inner face's fluid at inner_c and the outer face's at outer_c.
  Eigen::VectorXd SteadyState(double inner_c, double outer_c) const;
  // Under a steady ramp of both boundary temperatures, every ring settles to the ramp delayed by a
  // fixed time; this returns that delay for the volume-mean temperature, s. (For a thin pack it
  // tends to the lumped time constant rho c_p V / (h_in A_in + h_out A_out).)
  double RampLagSeconds() const;

 private:
  void Factorise(double step_s);
  // Solves (G + diag(shift)) x = rhs with the conduction matrix G (boundaries included).
  Eigen::VectorXd SolveSteady(const Eigen::VectorXd& rhs) const;

  double theta_;
  Eigen::VectorXd radius_, volume_;
  Eigen::VectorXd face_g_;  // face_g_[j]: conductance / (rho c_p) between rings j-1 and j, j >= 1
  double g_in_ = 0.0, g_out_ = 0.0;
  Eigen::VectorXd diag_g_;  // sum of the conductances touching each ring
  Eigen::VectorXd t_, rhs_;
  double factor_step_s_ = -1.0;
  Eigen::VectorXd lower_, upper_prime_, inverse_pivot_;  // Thomas factors of the step matrix
  Eigen::VectorXd volume_per_step_;
  double inverse_total_volume_ = 0.0;
};

}  // namespace gyrodrift::simulation
