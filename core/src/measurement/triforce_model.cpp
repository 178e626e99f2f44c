#include "mneedle/measurement/triforce_model.h"

#include <boost/math/special_functions/ellint_1.hpp>
#include <cmath>
#include <functional>
#include <numbers>

#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/base/units.h"

namespace mneedle {
namespace {

// G(eps) = K(eps) eps with K = K0 exp(beta eps).
double stiffness_law(const TriforceLayer& layer, double strain) {
  return layer.stiffness_N * strain * std::exp(layer.stiffening * strain);
}

// h(eps) = integral_0^eps e exp(beta e) de = (exp(beta eps)(beta eps - 1) + 1) / beta^2; the
// series avoids the cancellation when beta eps is small.
double stiffness_law_antiderivative(const TriforceLayer& layer, double strain) {
  const double b = layer.stiffening;
  const double x = b * strain;
  if (std::abs(x) < 1e-4) {
    const double e2 = strain * strain;
    return layer.stiffness_N * (e2 / 2.0 + b * e2 * strain / 3.0 + b * b * e2 * e2 / 8.0);
  }
  return layer.stiffness_N * (std::expm1(x) * (x - 1.0) + x) / (b * b);
}

void require(bool ok, std::string_view name, double value, std::string_view what) {
  if (!ok || !std::isfinite(value)) {
    throw InputError("tri-force parameters: " + std::string(name) + " = " + std::to_string(value) +
                     ": " + std::string(what));
  }
}

void validate(const TriforceParams& p) {
  if (p.layers.empty()) throw InputError("tri-force parameters: no layer");
  require(p.layers.front().start_m == 0.0, "start_m", p.layers.front().start_m,
          "the first layer must start at 0");
  for (std::size_t i = 0; i < p.layers.size(); ++i) {
    const auto& l = p.layers[i];
    if (i > 0) {
      require(l.start_m > p.layers[i - 1].start_m, "start_m", l.start_m,
              "layer starts must increase with depth");
    }
    require(l.cut_max_N >= 0.0, "Fc_max_N", l.cut_max_N, "must be >= 0");
    require(l.cut_rate_per_m >= 0.0, "kc_per_m", l.cut_rate_per_m, "must be >= 0");
    require(l.stiffness_N >= 0.0, "K0_N", l.stiffness_N, "must be >= 0");
    require(std::abs(l.stiffening) <= 50.0, "beta", l.stiffening, "must lie in [-50, 50]");
    require(l.normal_stress_per_m2 >= 0.0, "c_per_m2", l.normal_stress_per_m2, "must be >= 0");
  }
  require(p.friction_coefficient >= 0.0, "mu", p.friction_coefficient, "must be >= 0");
  require(p.needle_radius_m > 0.0, "radius_m", p.needle_radius_m, "must be > 0");
  require(p.reference_length_m > 0.0, "ref_length_m", p.reference_length_m, "must be > 0");
  require(p.viscosity_Ns >= 0.0, "eta_Ns", p.viscosity_Ns, "must be >= 0");
  require(p.relaxation_time_s > 0.0, "lambda_s", p.relaxation_time_s, "must be > 0");
}

using LayerField = double TriforceLayer::*;
struct LayerName {
  const char* name;
  LayerField field;
};
constexpr LayerName kLayerNames[] = {{"Fc_max_N", &TriforceLayer::cut_max_N},
                                     {"kc_per_m", &TriforceLayer::cut_rate_per_m},
                                     {"K0_N", &TriforceLayer::stiffness_N},
                                     {"beta", &TriforceLayer::stiffening},
                                     {"c_per_m2", &TriforceLayer::normal_stress_per_m2},
                                     {"start_m", &TriforceLayer::start_m}};

using GlobalField = double TriforceParams::*;
struct GlobalName {
  const char* name;
  GlobalField field;
};
constexpr GlobalName kGlobalNames[] = {{"mu", &TriforceParams::friction_coefficient},
                                       {"radius_m", &TriforceParams::needle_radius_m},
                                       {"ref_length_m", &TriforceParams::reference_length_m},
                                       {"eta_Ns", &TriforceParams::viscosity_Ns},
                                       {"lambda_s", &TriforceParams::relaxation_time_s}};

// Splits "K0_N_L2" into ("K0_N", 1); plain names are layer 0.
std::pair<std::string_view, std::size_t> split_layer(std::string_view name) {
  const auto pos = name.rfind("_L");
  if (pos == std::string_view::npos || pos + 2 >= name.size()) return {name, 0};
  std::size_t index = 0;
  for (char c : name.substr(pos + 2)) {
    if (c < '0' || c > '9') return {name, 0};
    index = index * 10 + static_cast<std::size_t>(c - '0');
  }
  if (index < 2) return {name, 0};
  return {name.substr(0, pos), index - 1};
}

double* locate(TriforceParams& p, std::string_view name) {
  for (const auto& g : kGlobalNames) {
    if (name == g.name) return &(p.*g.field);
  }
  const auto [base, layer] = split_layer(name);
  for (const auto& l : kLayerNames) {
    if (base != l.name || (layer == 0 && base == "start_m")) continue;
    if (layer >= p.layers.size()) p.layers.resize(layer + 1, p.layers.back());
    return &(p.layers[layer].*l.field);
  }
  throw InputError("tri-force parameters: unknown parameter '" + std::string(name) + "'");
}

}  // namespace

double effective_strain(double depth_m, double angle_rad, double reference_length_m) {
  return depth_m * std::sin(angle_rad) / reference_length_m;
}

double perturbation_friction_factor(double speed_m_per_s, double amplitude_m, double frequency_Hz,
                                    double time_s) {
  const double two_pi_f = 2.0 * std::numbers::pi * frequency_Hz;
  const double lateral = two_pi_f * amplitude_m * std::cos(two_pi_f * time_s);
  const double v = std::abs(speed_m_per_s);
  if (v == 0.0 && lateral == 0.0) return 1.0;
  return v / std::hypot(v, lateral);
}

double mean_perturbation_friction_factor(double speed_m_per_s, double amplitude_m,
                                         double frequency_Hz) {
  const double peak_lateral = 2.0 * std::numbers::pi * frequency_Hz * std::abs(amplitude_m);
  if (peak_lateral == 0.0) return 1.0;
  const double v = std::abs(speed_m_per_s);
  if (v == 0.0) return 0.0;
  // (1/2pi) int_0^2pi dphi / sqrt(1 + k^2 cos^2 phi) = (2/pi) K(k/sqrt(1+k^2)) / sqrt(1+k^2)
  const double k = peak_lateral / v;
  const double root = std::sqrt(1.0 + k * k);
  return 2.0 / std::numbers::pi * boost::math::ellint_1(k / root) / root;
}

TriforceModel::TriforceModel(TriforceParams params) : params_(std::move(params)) {
  validate(params_);
}

ForceComponents TriforceModel::quasi_static(double depth_m, double angle_rad) const {
  ForceComponents out;
  if (depth_m <= 0.0) return out;
  const double a = std::sin(angle_rad) / params_.reference_length_m;  // strain per metre
  const double shaft =
      2.0 * std::numbers::pi * params_.needle_radius_m * params_.friction_coefficient;
  double cut = 0.0, stiff = 0.0, friction = 0.0;
  for (std::size_t j = 0; j < params_.layers.size(); ++j) {
    const auto& layer = params_.layers[j];
    const double start = layer.start_m;
    const bool last = j + 1 == params_.layers.size();
    const double end = last ? depth_m : std::min(depth_m, params_.layers[j + 1].start_m);
    // Each layer continues from the force reached at its start: slopes change, forces don't jump.
    cut =
        layer.cut_max_N + (cut - layer.cut_max_N) * std::exp(-layer.cut_rate_per_m * (end - start));
    const double offset = stiff - stiffness_law(layer, a * start);
    stiff = offset + stiffness_law(layer, a * end);
    double integral = offset * (end - start);
    if (a > 0.0) {
      integral += (stiffness_law_antiderivative(layer, a * end) -
                   stiffness_law_antiderivative(layer, a * start)) /
                  a;
    }
    friction += shaft * layer.normal_stress_per_m2 * integral;
    if (end >= depth_m) break;
  }
  out.cutting_N = cut;
  out.stiffness_N = stiff;
  out.friction_N = friction;
  return out;
}

double TriforceModel::maxwell_steady_N(double speed_m_per_s, double angle_rad) const {
  return params_.viscosity_Ns * speed_m_per_s * std::sin(angle_rad) / params_.reference_length_m;
}

ForceComponents TriforceModel::loading(double depth_m, const InsertionConditions& c) const {
  auto out = quasi_static(depth_m, c.angle_rad);
  if (depth_m <= 0.0) return out;
  out.friction_N *= mean_perturbation_friction_factor(c.speed_m_per_s, c.perturbation_amplitude_m,
                                                      c.perturbation_frequency_Hz);
  if (c.speed_m_per_s > 0.0) {
    const double t = depth_m / c.speed_m_per_s;
    out.viscous_N = maxwell_steady_N(c.speed_m_per_s, c.angle_rad) *
                    -std::expm1(-t / params_.relaxation_time_s);
  }
  return out;
}

std::vector<ProtocolSample> TriforceModel::simulate(const InsertionProtocol& p) const {
  const auto& c = p.conditions;
  // Each value named with the one that is wrong (the command line's options have these names).
  const auto require = [](bool ok, const char* name, double value, Dimension d, const char* rule) {
    if (!ok)
      throw InputError(std::string("insertion protocol: ") + name + " " +
                       format_quantity(value, d) + ": must be " + rule);
  };
  require(c.speed_m_per_s > 0.0, "speed", c.speed_m_per_s, Dimension::Speed, "positive");
  require(p.max_depth_m > 0.0, "depth", p.max_depth_m, Dimension::Length, "positive");
  require(p.time_step_s > 0.0, "time step", p.time_step_s, Dimension::Time, "positive");
  require(p.hold_s >= 0.0, "hold", p.hold_s, Dimension::Time, "zero or positive");
  require(p.retraction_speed_m_per_s >= 0.0, "retraction speed", p.retraction_speed_m_per_s,
          Dimension::Speed, "positive (or 0 for the insertion speed)");
  const double lambda = params_.relaxation_time_s;
  const double back_speed =
      p.retraction_speed_m_per_s > 0.0 ? p.retraction_speed_m_per_s : c.speed_m_per_s;
  const double duration = p.max_depth_m / c.speed_m_per_s + p.hold_s + p.max_depth_m / back_speed;
  // Every step of the duration and the three phases' closing samples (each phase ends on its
  // exact time): 86 mm in and out at 1 mm/s in 0.05 s steps is 3 443.
  const double needed = std::ceil(duration / p.time_step_s * (1.0 - 1e-12)) + 3.0;
  if (!(needed <= static_cast<double>(p.max_samples)))
    throw InputError("insertion protocol: " + format_quantity(duration, Dimension::Time) +
                     " in steps of " + format_quantity(p.time_step_s, Dimension::Time) + " is " +
                     count_text(needed) + " samples, above the limit of " +
                     std::to_string(p.max_samples) + " (raise it with --max-samples)");
  std::vector<ProtocolSample> out;
  const double t_in = p.max_depth_m / c.speed_m_per_s;
  for (double t = 0.0;; t += p.time_step_s) {
    const double tt = std::min(t, t_in);
    out.push_back(
        {tt, c.speed_m_per_s * tt, InsertionPhase::Insertion, loading(c.speed_m_per_s * tt, c)});
    if (tt >= t_in) break;
  }
  const ForceComponents end = out.back().force;
  const double hold_friction = mean_perturbation_friction_factor(0.0, c.perturbation_amplitude_m,
                                                                 c.perturbation_frequency_Hz);
  double viscous = end.viscous_N;
  for (double tau = p.time_step_s; tau <= p.hold_s + 1e-12; tau += p.time_step_s) {
    // The needle stops: the elastic parts stay, the Maxwell branch relaxes.
    ForceComponents f = quasi_static(p.max_depth_m, c.angle_rad);
    f.friction_N *= hold_friction;
    f.viscous_N = end.viscous_N * std::exp(-tau / lambda);
    viscous = f.viscous_N;
    out.push_back({t_in + tau, p.max_depth_m, InsertionPhase::Hold, f});
  }
  const double t_out = t_in + (p.hold_s > 0.0 ? out.back().time_s - t_in : 0.0);
  const double reverse_steady = -maxwell_steady_N(back_speed, c.angle_rad);
  const double back_friction = mean_perturbation_friction_factor(
      back_speed, c.perturbation_amplitude_m, c.perturbation_frequency_Hz);
  const double t_back = p.max_depth_m / back_speed;
  for (double tau = p.time_step_s;; tau += p.time_step_s) {
    const double tt = std::min(tau, t_back);
    const double z = std::max(0.0, p.max_depth_m - back_speed * tt);
    // Withdrawing, the tip leaves the tissue ahead (no cutting, no tip stiffness) and the shaft
    // friction reverses over the length still inside.
    ForceComponents f;
    f.friction_N = -quasi_static(z, c.angle_rad).friction_N * back_friction;
    f.viscous_N = viscous * std::exp(-tt / lambda) + reverse_steady * -std::expm1(-tt / lambda);
    out.push_back({t_out + tt, z, InsertionPhase::Retraction, f});
    if (tt >= t_back) break;
  }
  return out;
}

std::vector<std::pair<std::string, double>> named_parameters(const TriforceParams& params) {
  std::vector<std::pair<std::string, double>> out;
  for (std::size_t i = 0; i < params.layers.size(); ++i) {
    const std::string suffix = i == 0 ? "" : "_L" + std::to_string(i + 1);
    for (const auto& l : kLayerNames) {
      if (i == 0 && std::string_view(l.name) == "start_m") continue;
      out.emplace_back(l.name + suffix, params.layers[i].*l.field);
    }
  }
  for (const auto& g : kGlobalNames) out.emplace_back(g.name, params.*g.field);
  return out;
}

void set_parameter(TriforceParams& params, std::string_view name, double value) {
  *locate(params, name) = value;
}

double get_parameter(const TriforceParams& params, std::string_view name) {
  TriforceParams copy = params;
  const auto [base, layer] = split_layer(name);
  if (layer >= params.layers.size() && base != name) {
    throw InputError("tri-force parameters: '" + std::string(name) + "': no layer " +
                     std::to_string(layer + 1));
  }
  return *locate(copy, name);
}

double checked_insertion_angle(double angle_rad, std::string_view option) {
  if (!(angle_rad > 0.0) || !(angle_rad <= std::numbers::pi / 2.0 * (1.0 + 1e-12)))
    throw InputError(std::string(option) + ": " + format_quantity(angle_rad, Dimension::Angle) +
                     " is outside (0, 90] deg (the needle-to-surface angle; 90 deg is "
                     "perpendicular)");
  return angle_rad;
}

}  // namespace mneedle
