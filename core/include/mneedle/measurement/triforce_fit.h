#pragma once
// Least-squares identification of the tri-force model from measured loading branches:
// Levenberg–Marquardt in a bounded (logistic) parameterisation, several starts, standard errors
// from the Jacobian, joint fits of several curves with shared material parameters and one
// contact offset per curve.

#include <map>
#include <string>
#include <vector>

#include "mneedle/measurement/curve_metrics.h"
#include "mneedle/measurement/triforce_model.h"

namespace mneedle {

/// One measured loading branch (travel from the detected contact) and its conditions.
struct FitCurve {
  std::string name;
  std::vector<double> depth_m;
  std::vector<double> force_N;
  InsertionConditions conditions;
};

struct TriforceFitOptions {
  /// Start values, and the values of every parameter that is not fitted.
  TriforceParams initial;
  /// Names fitted (see named_parameters); empty = Fc_max_N, kc_per_m, K0_N, beta, c_per_m2 of
  /// every layer.
  std::vector<std::string> free;
  /// Held at the given SI value and removed from the fitted set (`--fix p=v`).
  std::map<std::string, double> fixed;
  /// One contact offset per curve: the model sees travel - offset.
  bool fit_offsets = true;
  /// Bound of |offset|; 0 = a quarter of the deepest travel.
  double max_offset_m = 0.0;
  int starts = 8;
  int max_iterations = 200;
  /// Long recordings are thinned evenly to this many samples for the fit (metrics use all).
  std::size_t max_samples_per_curve = 400;
};

struct FitParameter {
  std::string name;
  double value = 0.0;
  double standard_error = 0.0;  ///< infinity when not identifiable from the data; 0 when fixed
  bool fitted = false;
};

struct CurveFit {
  std::string name;
  double offset_m = 0.0;
  double offset_standard_error_m = 0.0;
  CurveMetrics metrics;
};

struct TriforceFit {
  TriforceParams params;
  std::vector<FitParameter> parameters;  ///< every named parameter, fitted or not
  std::vector<CurveFit> curves;
  double residual_sd_N = 0.0;  ///< sqrt(SSE / (n - p)) over the fitted samples
  std::size_t samples = 0;     ///< samples used in the fit
  int iterations = 0;          ///< of the best start
  int starts = 0;
  bool converged = false;
};

/// Fits the model to all curves jointly. Throws InputError for an unknown or doubly given
/// parameter name, for curves without samples or with more parameters than samples, and
/// SolverError when no start gives a finite residual.
TriforceFit fit_triforce(const std::vector<FitCurve>& curves, const TriforceFitOptions& options);

/// The model's loading force at each sample of `curve`, the curve's travel shifted by offset_m.
std::vector<double> predict_loading(const TriforceModel& model, const FitCurve& curve,
                                    double offset_m);

}  // namespace mneedle
