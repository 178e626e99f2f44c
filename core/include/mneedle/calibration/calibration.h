#pragma once
// Fitting a scene's tissue constants to one measured insertion curve of one needle
// (`mneedle calibrate`, docs/model.md "Calibration"): the two-stage model's curve — the
// pre-puncture model until the criterion fires, the post-puncture distributed loads after —
// against the recording, by bounded least squares, with standard errors, correlations, the fit's
// RMSE and R², and a held-out check against a straight line. SI units throughout.

#include <optional>
#include <string>
#include <vector>

#include "mneedle/insertion/insertion_run.h"
#include "mneedle/measurement/curve_metrics.h"
#include "mneedle/measurement/force_curve.h"
#include "mneedle/scene/scene.h"

namespace mneedle {

enum class CalibratedConstant {
  scale,                 ///< a factor m on every layer's pressure scale q (S when q is derived)
  friction_coefficient,  ///< mu of the Coulomb shaft friction
  critical_pressure,     ///< P_c of the pressure criterion (top layer)
  toughness,             ///< Gamma of the energy criterion (top layer)
  /// a factor k on every layer's stiffness (E, or C10, C01 and K), fitted on the samples before
  /// the puncture: the pre-puncture force and the criterion's quantity scale with it exactly
  /// (docs/model.md, "Calibration")
  modulus,
};

/// "scale", "friction_coefficient", "critical_pressure", "toughness", "modulus"; InputError
/// otherwise.
CalibratedConstant calibrated_constant(const std::string& name);
std::string to_string(CalibratedConstant c);

struct CalibrationOptions {
  std::vector<CalibratedConstant> fit;
  /// Travel (the recording's depth column) at contact; empty: detected (force_curve.h).
  std::optional<double> contact_travel_m;
  /// Travel at the measured puncture. Given: the model is the post-puncture stage from there on
  /// and the pre-puncture part of the recording is not used (no finite elements run), unless
  /// `modulus` is fitted, which is fitted on that part. Empty: the full two-stage model (one
  /// pre-puncture run, the crossing taken on its steps).
  std::optional<double> puncture_travel_m;
  /// With a given puncture and `modulus`: travel where the force starts to fall at the puncture
  /// (the drop's peak; `--puncture-at detect` gives it). The samples from there to the puncture,
  /// the drop itself, are left out: neither stage models them.
  std::optional<double> drop_start_travel_m;
  /// Travel interval whose samples are fitted; the rest is held out and reported. Empty: all
  /// samples the model covers.
  std::optional<double> fit_from_travel_m, fit_to_travel_m;
  /// Samples the model is evaluated at, at most: beyond, every k-th is kept, evenly over the
  /// curve (each costs the post-puncture loads at its depth per evaluation).
  std::size_t max_samples = 1000;
  InsertionRunOptions run;  ///< fidelity and model of the pre-puncture run
};

struct CalibratedParameter {
  CalibratedConstant constant = CalibratedConstant::scale;
  double initial = 0.0;  ///< the scene's value (1 for scale)
  double value = 0.0;
  double standard_error = 0.0;  ///< infinity when the curve cannot fix it
  bool at_bound = false;        ///< the optimum sits on the search interval's end
};

struct Calibration {
  std::vector<CalibratedParameter> parameters;
  std::vector<std::vector<double>> correlation;
  CurveMetrics fit;                      ///< on the fitted samples
  std::optional<CurveMetrics> held_out;  ///< on the samples outside the fit interval
  /// A straight line fitted to the same samples, evaluated on the held-out ones: the baseline a
  /// model must beat to be worth its constants.
  std::optional<CurveMetrics> straight_line_held_out;
  double contact_travel_m = 0.0;
  std::optional<double> puncture_depth_m;  ///< the model's, below the surface (from contact)
  bool converged = false;
  int iterations = 0;
  // Every sample the model covers, in file order: depth from contact, measured, fitted model.
  std::vector<double> depth_m, measured_N, model_N;
  std::vector<bool> fitted;  ///< the sample lies in the fit interval
  /// The layer pressure scales after the fit (Pa), one per scene layer.
  std::vector<double> layer_pressure_scale_Pa;
  /// The factor on every layer's stiffness (1 unless `modulus` is fitted) and the layers' Young's
  /// moduli after the fit (Pa, the small-strain value for Mooney-Rivlin), one per scene layer.
  double modulus_factor = 1.0;
  std::vector<double> layer_youngs_modulus_Pa;
  double friction_coefficient = 0.0;
  std::optional<double> critical_pressure_Pa, toughness_J_per_m2;
};

/// Fits the chosen constants of `scene` (one needle, `needle` prepared from it) to `measured`.
/// Throws InputError for an empty or repeated `fit` list, critical_pressure together with
/// toughness (one curve fixes one), a constant the scene does not use (friction_coefficient
/// without Coulomb friction, a criterion constant with a given puncture or with the other
/// criterion), too few samples (`modulus`: fewer than two before the puncture), a modulus whose
/// puncture does not settle, and SolverError when the model cannot be evaluated.
Calibration calibrate(const Scene& scene, const PreparedNeedle& needle, const ForceCurve& measured,
                      const CalibrationOptions& options);

}  // namespace mneedle
