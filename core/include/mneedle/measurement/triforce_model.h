#pragma once
// Paper B's tri-force model of the axial force on a needle entering soft tissue,
//   F(z) = F_c(z) + F_s(z) + F_f(z)   (+ a Maxwell viscous branch for the speed dependence),
// with layered (piecewise) parameters, a hold and a retraction, and a lateral perturbation of
// the needle base. Every form, its units and its source are in docs/model.md, "Tri-force model
// (paper B)".
// z is the needle travel from contact along its axis (m); the angle is between the needle and
// the tissue surface (rad, pi/2 = perpendicular), paper B's convention.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mneedle {

/// Material parameters of one tissue layer.
struct TriforceLayer {
  double start_m = 0.0;           ///< travel from contact where the layer begins (0 for the first)
  double cut_max_N = 1.0;         ///< F_c,max: cutting force at saturation
  double cut_rate_per_m = 500.0;  ///< k: growth rate of the cutting force
  double stiffness_N = 1.0;       ///< K0: stiffness at zero compression (force per unit strain)
  double stiffening = 0.0;        ///< beta: exponential stiffening, K = K0 exp(beta eps)
  double normal_stress_per_m2 = 0.0;  ///< c: shaft normal stress per newton of stiffness force
};

struct TriforceParams {
  std::vector<TriforceLayer> layers{TriforceLayer{}};  ///< sorted by start_m, first at 0
  double friction_coefficient = 0.2;                   ///< mu, needle–tissue (paper B uses 0.2)
  double needle_radius_m = 0.6e-3;                     ///< r, 18 G needle
  double reference_length_m = 10e-3;                   ///< L: eps = z sin(angle) / L
  double viscosity_Ns = 0.0;       ///< eta: Maxwell branch, force per unit strain rate
  double relaxation_time_s = 1.0;  ///< lambda = eta/E of the Maxwell branch
};

struct ForceComponents {
  double cutting_N = 0.0;
  double stiffness_N = 0.0;
  double friction_N = 0.0;
  double viscous_N = 0.0;
  double total_N() const { return cutting_N + stiffness_N + friction_N + viscous_N; }
};

/// Conditions of one insertion.
struct InsertionConditions {
  double speed_m_per_s = 1e-3;
  double angle_rad = 1.5707963267948966;
  double perturbation_amplitude_m = 0.0;      ///< A of x(t) = A sin(2 pi f t)
  double perturbation_frequency_Hz = 1000.0;  ///< f (paper B: 1000 Hz)
};

/// Insertion to `max_depth_m`, hold, retraction to the surface at `retraction_speed_m_per_s`.
struct InsertionProtocol {
  InsertionConditions conditions;
  double max_depth_m = 10e-3;
  double hold_s = 0.0;
  double retraction_speed_m_per_s = 0.0;  ///< 0 = the insertion speed
  double time_step_s = 0.01;
  /// Work limit checked before any sample is made: paper C's 86 mm insertion at 1 mm/s in
  /// 0.01 s steps needs about 17 000 samples; the default leaves room for 60 times more (about
  /// 100 MB of samples; 20 million, the former default, held 1.9 GB).
  std::size_t max_samples = 1'000'000;
};

enum class InsertionPhase { Insertion, Hold, Retraction };

struct ProtocolSample {
  double time_s = 0.0;
  double depth_m = 0.0;
  InsertionPhase phase = InsertionPhase::Insertion;
  ForceComponents force;
};

/// eps = z sin(angle) / L (reconstruction of paper B's "compression from depth and angle").
double effective_strain(double depth_m, double angle_rad, double reference_length_m);

/// Friction reduction under a lateral vibration: Coulomb friction opposes the relative sliding
/// velocity, so its axial share is v / sqrt(v^2 + (2 pi f A cos 2 pi f t)^2).
double perturbation_friction_factor(double speed_m_per_s, double amplitude_m, double frequency_Hz,
                                    double time_s);

/// The same factor averaged over one vibration period (closed form with the complete elliptic
/// integral of the first kind); 1 without vibration, 0 for a vibrating needle at rest.
double mean_perturbation_friction_factor(double speed_m_per_s, double amplitude_m,
                                         double frequency_Hz);

/// The tri-force model for repeated evaluation. Throws InputError for invalid parameters.
class TriforceModel {
 public:
  explicit TriforceModel(TriforceParams params);

  const TriforceParams& params() const { return params_; }

  /// Rate-independent part F_c + F_s + F_f at travel z (friction not reduced by vibration).
  ForceComponents quasi_static(double depth_m, double angle_rad) const;

  /// Force during a constant-speed insertion from contact (Maxwell branch started at contact,
  /// friction reduced by the cycle-averaged vibration factor).
  ForceComponents loading(double depth_m, const InsertionConditions& conditions) const;

  /// Insertion, hold and retraction sampled every time_step_s.
  std::vector<ProtocolSample> simulate(const InsertionProtocol& protocol) const;

 private:
  double maxwell_steady_N(double speed_m_per_s, double angle_rad) const;

  TriforceParams params_;
};

/// The parameters as a flat list of (name, SI value) used by the fit, --fix and the JSON files:
/// Fc_max_N, kc_per_m, K0_N, beta, c_per_m2 per layer (layer i >= 2 adds start_m and the suffix
/// "_L<i>"), then mu, radius_m, ref_length_m, eta_Ns, lambda_s.
std::vector<std::pair<std::string, double>> named_parameters(const TriforceParams& params);

/// Sets one named parameter. Throws InputError naming `name` when it is unknown.
void set_parameter(TriforceParams& params, std::string_view name, double value);

/// Reads one named parameter. Throws InputError naming `name` when it is unknown.
double get_parameter(const TriforceParams& params, std::string_view name);

/// `angle_rad` when 0 < angle <= pi/2 (paper B's needle-to-surface angle, pi/2 perpendicular:
/// the model's sin(angle) is the depth's share along the surface normal, which is negative or
/// repeats beyond that range). InputError naming `option` otherwise.
double checked_insertion_angle(double angle_rad, std::string_view option);

}  // namespace mneedle
