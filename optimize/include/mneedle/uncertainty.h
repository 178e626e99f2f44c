#pragma once
// Uncertainty from tissue variability (docs/cli.md, "mneedle uncertainty"; docs/model.md,
// "Uncertainty"): scene values drawn from distributions, every sample evaluated as `screen`
// evaluates a design (the scene's first needle), and the spread of puncture depth, forces and
// margin with a one-at-a-time sensitivity ranking. Seeded runs are reproducible bit for bit at the
// same number of OpenBLAS threads per run: any --jobs > 1 (one each), or --jobs 1 with
// OPENBLAS_NUM_THREADS=1.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/base/units.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/plugin_host.h"

namespace mneedle {

enum class DistributionKind { Normal, LogNormal, Uniform };

/// A distribution of one scene value, SI. Normal: a = mean, b = standard deviation. LogNormal:
/// a = median, b = standard deviation of ln(value). Uniform: a = low, b = high.
struct Distribution {
  DistributionKind kind = DistributionKind::Uniform;
  double a = 0.0;
  double b = 1.0;
  Dimension dimension = Dimension::Dimensionless;
};

/// The p-quantile of `d`, 0 < p < 1 (boost::math's inverse CDFs).
double distribution_quantile(const Distribution& d, double p);

/// One varied scene value: where it is and what it is drawn from.
struct VariedValue {
  std::string path;  ///< "dermis.E", "fracture.critical_pressure", "needle.diameter", "a.b.c"
  Distribution distribution;
  std::string text;  ///< the --vary text as given
};

/// Parses "PATH=normal(MEAN,SD)", "PATH=lognormal(MEDIAN,CV%)" or "PATH=uniform(LOW,HIGH)", with
/// units on every dimensional value ("80kPa"; SD may be "20%" of the mean; CV is the coefficient
/// of variation of the value, σ_ln = sqrt(ln(1 + CV²))). InputError naming the text and the
/// problem.
VariedValue parse_varied_value(const std::string& spec);

/// `toml_text` (a scene) with each (path, SI value) set. A path is a layer's name then a key of
/// the layer or of its material ("dermis.E", "stratum_corneum.thickness"), "fracture.KEY" (the
/// tissue's fracture table), "needle.KEY" (the first needle's geometry), or a dotted path of the
/// file ("requirements.target_depth"). The value must already be in the scene (a misspelt path
/// is an error, not a new key) and of the distribution's dimension. InputError naming `source`,
/// the path and the problem.
std::string scene_with_values(const std::string& toml_text, const std::string& source,
                              const std::vector<std::pair<VariedValue, double>>& values);

struct UncertaintyOptions {
  int samples = 200;
  std::uint64_t seed = 1;
  bool latin_hypercube = false;  ///< else plain Monte Carlo
  int jobs = 1;
  std::string fidelity = "fast";  ///< as screen: fast | standard | fine
  std::string model = "auto";     ///< as screen: auto | analytic | axisymmetric | 3d
  std::optional<std::string> material;
  bool sensitivity = true;  ///< the one-at-a-time runs (2 per varied value)
};

/// One evaluated scene: the drawn values (SI, in the order of the inputs) and what came out.
struct UncertaintySample {
  std::vector<double> values;
  bool ok = false;
  std::string error;
  std::optional<double> puncture_depth_m;  ///< empty: no puncture up to the target depth
  double puncture_force_n = 0.0;
  bool puncture_at_first_contact = false;
  double puncture_objective_m = 0.0;  ///< DesignEvaluation::puncture_objective_m (continuous)
  double peak_force_n = 0.0;
  double margin = 0.0;  ///< capacity / peak force (infinite without force)
  bool passes = false;
};

/// 5 %, 50 % and 95 % percentiles of the samples that have the value (linear interpolation
/// between order statistics, numpy's default); count = how many had it.
struct Percentiles {
  std::size_t count = 0;
  double p5 = 0.0, p50 = 0.0, p95 = 0.0;
};
Percentiles percentiles(std::vector<double> values);

/// One varied value at its 5 % and 95 % quantiles, every other value as the scene has it.
struct Sensitivity {
  std::string path;
  UncertaintySample low, high;
  /// |puncture objective at 95 % − at 5 %|: a puncture depth difference when both ends are
  /// resolved punctures (both_resolved), else a difference of the objective (a first-step depth,
  /// or beyond the target depth a measure of how near the criterion came). Empty when either end
  /// could not be evaluated.
  std::optional<double> depth_effect_m;
  std::optional<double> peak_effect_n;  ///< |peak force at 95 % − at 5 %|
  bool both_resolved = false;
};

struct UncertaintyResult {
  std::vector<VariedValue> inputs;
  UncertaintySample nominal;  ///< the scene as written
  std::vector<UncertaintySample> samples;
  Percentiles puncture_depth_m, puncture_force_n, peak_force_n, margin;
  double punctured_fraction = 0.0;      ///< of the samples that ran; resolved punctures only
  double first_contact_fraction = 0.0;  ///< of the samples that ran: fired at the first step
  double pass_probability = 0.0;        ///< of the samples that ran
  /// binomial_standard_error(pass_probability, the samples that ran).
  double pass_probability_standard_error = 0.0;
  std::size_t failed = 0;                ///< samples that could not be evaluated (error rows)
  std::vector<Sensitivity> sensitivity;  ///< largest depth effect first, then peak force
};

/// Standard error of a share p of n independent samples: sqrt(p (1 - p) / n); 0 for n = 0.
double binomial_standard_error(double p, double n);

/// Runs the scene at its own values first (if that fails, its exception: InputError or
/// SolverError), then every sample (drawn in a fixed order from a 64-bit
/// Mersenne Twister seeded with options.seed, so the draws do not depend on jobs), and one at a
/// time at each input's 5 % and 95 % quantiles. A sample that fails is an error row, the others go
/// on; every sample failing is an InputError quoting the first. `on_sample` (optional) is called
/// for each finished evaluation, serialised: (done, total).
UncertaintyResult run_uncertainty(const std::filesystem::path& scene_file,
                                  const std::vector<VariedValue>& inputs,
                                  const PluginRegistry& registry, const UncertaintyOptions& options,
                                  const std::function<void(int, int)>& on_sample = {});

/// Evaluates one needle in one scene (the scene with a sample's values, or as written).
using SceneEvaluator = std::function<DesignEvaluation(const Scene&)>;

/// The same for any needle: `scene_text` is the scene (named `source` in messages) and
/// `evaluate` runs the needle in it; screen --uncertainty passes each design's needle. Must be
/// safe to call from several threads at once when options.jobs > 1.
UncertaintyResult run_uncertainty(const std::string& scene_text, const std::string& source,
                                  const std::vector<VariedValue>& inputs,
                                  const UncertaintyOptions& options, const SceneEvaluator& evaluate,
                                  const std::function<void(int, int)>& on_sample = {});

class MpiSession;

/// run_uncertainty over every rank of an MPI job (`uncertainty --mpi`; docs/performance.md,
/// "Screening on a cluster"): every rank draws the same samples, rank 0 deals the runs one at a
/// time to whichever thread of any rank asks, and rank 0 returns the same result as the serial
/// run, bit for bit (one OpenBLAS thread per run, as with jobs > 1); the other ranks return
/// nothing. Every rank must read the same scene with the same settings (checked). A failure
/// before the samples stops every rank: rank 0 throws it (or an InputError saying that another
/// rank could not start), a rank > 0 whose error rank 0 does not share throws it, the others
/// throw RankStopped. `on_sample` is called on rank 0 only.
std::optional<UncertaintyResult> run_uncertainty_mpi(
    const MpiSession& session, const std::filesystem::path& scene_file,
    const std::vector<VariedValue>& inputs, const PluginRegistry& registry,
    const UncertaintyOptions& options, const std::function<void(int, int)>& on_sample = {});

}  // namespace mneedle
