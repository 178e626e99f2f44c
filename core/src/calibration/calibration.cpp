#include "mneedle/calibration/calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/insertion/puncture.h"
#include "mneedle/insertion/surface_loads.h"
#include "mneedle/measurement/bounded_least_squares.h"

namespace mneedle {
namespace {

constexpr double kNeverFires = 1e300;    // a finite threshold no pre-puncture model reaches
constexpr double kFirstRung_m = 100e-6;  // the ladder's first horizon (insertion_planner.cpp)

void fail(const std::string& problem) {
  throw InputError("calibrate: " + problem);
}

// The recording from contact to its deepest point, depth below the undeformed surface.
struct Samples {
  std::vector<double> travel_m, depth_m, force_N;
  double contact_travel_m = 0.0;
};

Samples samples_from(const ForceCurve& measured, std::optional<double> contact_travel_m) {
  Samples s;
  if (contact_travel_m) {
    s.contact_travel_m = *contact_travel_m;
    double deepest = -std::numeric_limits<double>::infinity();
    for (double t : measured.depth_m) deepest = std::max(deepest, t);
    for (std::size_t i = 0; i < measured.depth_m.size(); ++i) {
      const double depth = measured.depth_m[i] - *contact_travel_m;
      if (depth >= 0.0) {
        s.travel_m.push_back(measured.depth_m[i]);
        s.depth_m.push_back(depth);
        s.force_N.push_back(measured.force_N[i]);
      }
      if (measured.depth_m[i] == deepest) break;  // the hold and the retraction are not insertion
    }
  } else {
    const LoadingBranch branch = extract_loading_branch(measured);
    s.contact_travel_m = branch.contact_travel_m;
    s.depth_m = branch.curve.depth_m;
    s.force_N = branch.curve.force_N;
    for (double d : s.depth_m) s.travel_m.push_back(d + branch.contact_travel_m);
  }
  return s;
}

struct PreCurve {
  std::vector<double> depth_m, force_N, criterion;
};

// One pre-puncture run for one rung of the horizon ladder (docs/model.md, "Pre-puncture
// horizon") with a threshold it never reaches, so every step carries the criterion's quantity
// and any threshold's crossing can be read off it on the same mesh run_insertion would use.
PreCurve pre_puncture_curve(Scene scene, const PreparedNeedle& needle, double depth_m,
                            const InsertionRunOptions& run_options) {
  scene.insertion.depth = depth_m;
  scene.requirements.target_depth.reset();
  scene.model.outputs = {Output::Puncture, Output::ForceCurve};
  TissueLayer& top = scene.tissue.layers.front();
  Fracture f = top.fracture.value_or(Fracture{});
  f.toughness = kNeverFires;
  f.critical_pressure = kNeverFires;
  top.fracture = f;
  InsertionRunOptions options = run_options;
  options.vtu_directory.clear();
  const InsertionRun run = run_insertion(scene, {needle}, options);
  PreCurve pre;
  for (const RunPoint& p : run.needles.front().curve) {
    if (p.stage != Stage::Pre || !(p.depth_m > 0.0)) continue;
    pre.depth_m.push_back(p.depth_m);
    pre.force_N.push_back(p.force_N);
    const CriterionSample c{p.depth_m, p.section_pressure_Pa, p.tip_stress_Pa,
                            p.energy_release_rate_J_per_m2};
    pre.criterion.push_back(criterion_value(options.criterion, c));
  }
  if (pre.depth_m.empty()) throw SolverError("calibrate: the pre-puncture run gave no steps");
  return pre;
}

struct Line {
  double slope = 0.0, intercept = 0.0;
};

Line least_squares_line(const std::vector<double>& x, const std::vector<double>& y) {
  const double n = static_cast<double>(x.size());
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sx += x[i];
    sy += y[i];
    sxx += x[i] * x[i];
    sxy += x[i] * y[i];
  }
  const double det = n * sxx - sx * sx;
  if (!(det > 0.0)) return {0.0, sy / n};
  return {(n * sxy - sx * sy) / det, (sy * sxx - sx * sxy) / det};
}

}  // namespace

CalibratedConstant calibrated_constant(const std::string& name) {
  if (name == "scale") return CalibratedConstant::scale;
  if (name == "friction_coefficient") return CalibratedConstant::friction_coefficient;
  if (name == "critical_pressure") return CalibratedConstant::critical_pressure;
  if (name == "toughness") return CalibratedConstant::toughness;
  if (name == "modulus") return CalibratedConstant::modulus;
  fail("--fit " + name +
       ": unknown constant (scale, friction_coefficient, critical_pressure, toughness, modulus)");
  return CalibratedConstant::scale;
}

std::string to_string(CalibratedConstant c) {
  switch (c) {
    case CalibratedConstant::scale:
      return "scale";
    case CalibratedConstant::friction_coefficient:
      return "friction_coefficient";
    case CalibratedConstant::critical_pressure:
      return "critical_pressure";
    case CalibratedConstant::toughness:
      return "toughness";
    case CalibratedConstant::modulus:
      return "modulus";
  }
  return "?";
}

Calibration calibrate(const Scene& scene, const PreparedNeedle& needle, const ForceCurve& measured,
                      const CalibrationOptions& options) {
  // ---- setup: what is fitted, and on which samples --------------------------------------------
  if (options.fit.empty()) fail("nothing to fit (--fit scale,friction_coefficient,...)");
  const std::set<CalibratedConstant> chosen(options.fit.begin(), options.fit.end());
  if (chosen.size() != options.fit.size()) fail("a constant is listed twice in --fit");
  const bool fits_pc = chosen.count(CalibratedConstant::critical_pressure) > 0;
  const bool fits_gamma = chosen.count(CalibratedConstant::toughness) > 0;
  const bool fits_modulus = chosen.count(CalibratedConstant::modulus) > 0;
  if (fits_pc && fits_gamma) {
    fail(
        "critical_pressure and toughness together: one curve has one puncture, which fixes "
        "one of them, not both");
  }
  if ((fits_pc || fits_gamma) && options.puncture_travel_m) {
    fail("a criterion constant cannot be fitted when the puncture is given (--puncture-at)");
  }
  const PunctureCriterion criterion = options.run.criterion;
  // The criterion is read off one pre-puncture run whose thresholds never fire; F_p would need
  // the tissue's own toughness, which that run replaces. Not supported rather than wrong.
  if (criterion == PunctureCriterion::Penetration && !options.puncture_travel_m) {
    fail(
        "the penetration criterion is not supported (use the pressure or energy criterion, or "
        "give the puncture with --puncture-at)");
  }
  // The cohesive crack softens the pre-puncture force itself: a run whose criterion never fires
  // is not the run that punctures.
  if (criterion == PunctureCriterion::Cohesive) {
    fail(
        "the cohesive criterion is not supported (its crack changes the force before the "
        "puncture; use the pressure or energy criterion)");
  }
  if (fits_pc && criterion != PunctureCriterion::Pressure) {
    fail("critical_pressure is the pressure criterion's; the run uses another criterion");
  }
  if (fits_gamma && criterion != PunctureCriterion::Energy) {
    fail("toughness is the energy criterion's; the run uses another criterion");
  }
  LoadConstants base = load_constants(scene);
  if (chosen.count(CalibratedConstant::friction_coefficient) &&
      base.friction != ShaftFriction::coulomb) {
    fail("friction_coefficient needs [loads] friction = \"coulomb\"");
  }
  if (chosen.count(CalibratedConstant::scale) && base.mode == LoadModelMode::paper_a_fig17) {
    fail(
        "scale cannot be fitted in mode paper_a_fig17 (its K is paper A's, E D / (4 H)); fit "
        "S by changing [loads] scale, or use mode distributed");
  }
  const std::vector<LayerPressure> base_q = layer_pressures(base);

  if (options.contact_travel_m && !measured.depth_m.empty()) {
    // Contact after the recorded travel leaves no sample; one long before it is caught below
    // (its samples lie deeper than the block).
    const double last = *std::max_element(measured.depth_m.begin(), measured.depth_m.end());
    if (*options.contact_travel_m >= last)
      fail("--contact-at " + format_quantity(*options.contact_travel_m, Dimension::Length) +
           ": at or after the end of the recorded travel of " + measured.source + " (" +
           format_quantity(last, Dimension::Length) + ")");
  }
  const Samples all = samples_from(measured, options.contact_travel_m);
  // A curve deeper than the scene's needle is long cannot be its insertion: the model has no
  // needle there and fits nothing (a liver curve to 43 mm with skin's 1 mm needle fitted no
  // constant, exit 0). A curve deeper than the block is fine: the tip leaves a thin sample.
  if (!all.depth_m.empty()) {
    const double deepest = *std::max_element(all.depth_m.begin(), all.depth_m.end());
    const BoundingBox box = bounding_box(needle.mesh);
    const double needle_length = box.max[2] - box.min[2];
    if (deepest >= needle_length)
      fail(measured.source + " reaches " + format_quantity(deepest, Dimension::Length) +
           " below its contact, past the scene's needle (" +
           format_quantity(needle_length, Dimension::Length) +
           " long): calibrate a scene of that insertion, or cut the curve");
  }
  std::optional<double> given_puncture_depth;
  if (options.puncture_travel_m) {
    given_puncture_depth = *options.puncture_travel_m - all.contact_travel_m;
    // A puncture at or above the surface is no puncture: the pre-puncture model has nothing to
    // cover and every sample would be fitted as post-puncture.
    if (!(*given_puncture_depth > 0.0)) {
      fail("--puncture-at " + format_quantity(*options.puncture_travel_m, Dimension::Length) +
           ": not below the surface; " + measured.source + " meets it at " +
           format_quantity(all.contact_travel_m, Dimension::Length) + " of travel");
    }
  }
  std::vector<std::size_t> used;  // samples the model covers
  for (std::size_t i = 0; i < all.depth_m.size(); ++i) {
    // Before a given puncture only the pre-puncture model, run for the modulus, covers them;
    // the drop itself (from where the force starts to fall) neither model does.
    if (given_puncture_depth && all.depth_m[i] < *given_puncture_depth) {
      if (!fits_modulus) continue;
      if (options.drop_start_travel_m && all.travel_m[i] >= *options.drop_start_travel_m) continue;
    }
    used.push_back(i);
  }
  // Each evaluation runs the post-puncture loads at every sample (about 7 ms each): a recording
  // of 10^5 samples took minutes per iteration. Every k-th is kept, evenly over the curve, so
  // that at most options.max_samples are modelled (a recording that fine is smooth at that
  // spacing; the liver curve's 140 are all kept).
  if (options.max_samples > 1 && used.size() > options.max_samples) {
    // The first, every stride-th and the last: at most max_samples with the last included.
    const std::size_t stride =
        (used.size() - 1 + options.max_samples - 2) / (options.max_samples - 1);
    std::vector<std::size_t> kept;
    for (std::size_t k = 0; k < used.size(); k += stride) kept.push_back(used[k]);
    if (kept.back() != used.back()) kept.push_back(used.back());
    used = std::move(kept);
  }
  if (used.size() < options.fit.size() + 2) {
    fail(measured.source + ": " + std::to_string(used.size()) + " samples for " +
         std::to_string(options.fit.size()) + " constants");
  }
  const auto in_fit = [&](std::size_t i) {
    const double t = all.travel_m[i];
    return (!options.fit_from_travel_m || t >= *options.fit_from_travel_m) &&
           (!options.fit_to_travel_m || t <= *options.fit_to_travel_m);
  };
  std::vector<std::size_t> fitted;
  for (std::size_t i : used) {
    if (in_fit(i)) fitted.push_back(i);
  }
  if (fitted.size() <= options.fit.size()) {
    fail(measured.source + ": " + std::to_string(fitted.size()) +
         " samples in the fit interval for " + std::to_string(options.fit.size()) + " constants");
  }

  // ---- the model: pre-puncture run once, post-puncture loads per evaluation
  // ---------------------- Rungs 100 um x 2^k up to the one covering the deepest sample, as
  // run_insertion climbs them: a threshold's puncture is read on the first rung that reaches it.
  std::vector<PreCurve> rungs;
  double scene_threshold = 0.0;
  if (!given_puncture_depth || fits_modulus) {
    double deepest = 0.0;
    for (std::size_t i : used) deepest = std::max(deepest, all.depth_m[i]);
    if (given_puncture_depth) deepest = *given_puncture_depth;
    for (double horizon = kFirstRung_m;; horizon *= 2.0) {
      const bool covers = horizon >= deepest * (1.0 - 1e-12);
      // A given puncture is read on the rung that covers it, as run_insertion would stop there;
      // the shallower rungs could only hold a crossing, and none is sought.
      if (covers || !given_puncture_depth)
        rungs.push_back(pre_puncture_curve(scene, needle, horizon, options.run));
      if (covers) break;
    }
    if (!given_puncture_depth && !fits_pc && !fits_gamma)
      scene_threshold = puncture_threshold(scene, criterion).threshold;
  }
  const PreCurve* last_rung = rungs.empty() ? nullptr : &rungs.back();

  struct Values {
    double scale = 1.0, mu = 0.0, modulus = 1.0;
  };
  // A layer's q follows its modulus when it is derived from it (docs/model.md, "Pressure
  // scale"): S E / (1 - nu^2), or paper A's Fig. 17 K = E D / (4 H).
  std::vector<bool> follows_modulus;
  for (const LoadLayer& layer : base.layers) {
    follows_modulus.push_back(base.mode == LoadModelMode::paper_a_fig17 ||
                              (!layer.pressure_scale_Pa && !base.stiffness_Pa));
  }
  // Where the model punctures and which pre-puncture curve it follows until then.
  struct Split {
    std::optional<double> depth;
    const PreCurve* pre = nullptr;
    /// The P_c this split stands for when P_c is fitted: the alpha load's cap (docs/model.md,
    /// "Wall pressure cap") follows it in every layer that reads the same fracture data.
    std::optional<double> critical_pressure;
  };
  // The criterion's quantity scales with the modulus factor k: it reaches a threshold T where the
  // unscaled run's reaches T / k.
  const auto split_for_threshold = [&](double threshold) {
    Split split{given_puncture_depth, last_rung, std::nullopt};
    for (const PreCurve& rung : rungs) {
      if (const auto crossing = first_crossing(rung.depth_m, rung.criterion, threshold)) {
        split = {crossing->depth_m, &rung, std::nullopt};
        break;
      }
    }
    return split;
  };
  const auto rung_for_depth = [&](double depth) {
    for (const PreCurve& rung : rungs) {
      if (rung.depth_m.back() >= depth * (1.0 - 1e-12)) return &rung;
    }
    return last_rung;
  };
  const auto model_at = [&](const Values& v, const Split& split,
                            const std::vector<std::size_t>& which) {
    LoadConstants c = base;
    c.friction_coefficient = v.mu;
    for (std::size_t j = 0; j < c.layers.size(); ++j) {
      c.layers[j].pressure_scale_Pa =
          v.scale * base_q[j].pressure_scale_Pa * (follows_modulus[j] ? v.modulus : 1.0);
      c.layers[j].pressure_scale_source = "calibrate";
      c.layers[j].youngs_modulus_Pa *= v.modulus;
    }
    if (c.layers.empty()) c.stiffness_Pa = *base.stiffness_Pa * v.scale;
    if (split.critical_pressure) {
      const std::optional<double> old =
          base.layers.empty() ? std::nullopt : base.layers.front().critical_pressure_Pa;
      for (LoadLayer& layer : c.layers) {
        if (!old || layer.critical_pressure_Pa == old) {
          layer.critical_pressure_Pa = *split.critical_pressure;
        }
      }
    }
    const SurfaceLoadModel post(needle.mesh, c);
    std::vector<double> out;
    for (std::size_t i : which) {
      const double z = all.depth_m[i];
      const bool after = split.depth && z >= *split.depth;
      out.push_back(after ? post.at(z).force_N
                          : v.modulus * interpolate_at(split.pre->depth_m, split.pre->force_N, z));
    }
    return out;
  };

  // The constants a derivative can move (scale, mu); the criterion's constant only decides
  // between which two samples the model punctures, so it is searched over those gaps.
  std::vector<std::size_t> smooth;  // indices into options.fit
  std::vector<ParameterBound> bounds;
  std::vector<double> x0;
  for (std::size_t j = 0; j < options.fit.size(); ++j) {
    if (options.fit[j] == CalibratedConstant::scale) {
      smooth.push_back(j);
      bounds.push_back({1e-4, 1e4, true});
      x0.push_back(1.0);
    } else if (options.fit[j] == CalibratedConstant::friction_coefficient) {
      smooth.push_back(j);
      // Needle-tissue friction coefficients are reported from about 0.05 to 0.5 (paper B: 0.2);
      // 1 bounds them with room to spare.
      bounds.push_back({0.0, 1.0, false});
      x0.push_back(std::clamp(base.friction_coefficient, 0.01, 0.99));
    }
  }
  // The modulus factor is fitted in closed form on the samples before the puncture (below), so
  // it is not one of the least-squares unknowns: the split and the factor are settled first.
  double modulus = 1.0;
  const auto values_of = [&](const std::vector<double>& x) {
    Values v{1.0, base.friction_coefficient, modulus};
    for (std::size_t k = 0; k < smooth.size(); ++k) {
      if (options.fit[smooth[k]] == CalibratedConstant::scale) v.scale = x[k];
      if (options.fit[smooth[k]] == CalibratedConstant::friction_coefficient) v.mu = x[k];
    }
    return v;
  };
  // The samples the least-squares constants are fitted on: all fitted ones, or with the modulus
  // (fitted in closed form before the split) those from the split on, so that the misfit
  // before it does not enter their errors.
  const auto smooth_samples = [&](const Split& split) {
    if (!fits_modulus) return fitted;
    std::vector<std::size_t> after;
    for (std::size_t i : fitted) {
      if (split.depth && all.depth_m[i] >= *split.depth) after.push_back(i);
    }
    return after;
  };
  const auto enough_after = [&](const Split& split) {
    return smooth.empty() || smooth_samples(split).size() > smooth.size();
  };
  const auto residuals_for = [&](const Split& split) -> ResidualVector {
    return [&, split, which = smooth_samples(split)](const std::vector<double>& x) {
      const std::vector<double> model = model_at(values_of(x), split, which);
      std::vector<double> r(model.size());
      for (std::size_t k = 0; k < which.size(); ++k) r[k] = all.force_N[which[k]] - model[k];
      return r;
    };
  };
  const auto cost_of = [](const std::vector<double>& r) {
    double sum = 0.0;
    for (double v : r) sum += v * v;
    return sum;
  };
  // F = k g(d) on the fitted samples before the split, g the unscaled pre-puncture force: the
  // least-squares k = sum g F / sum g^2, its standard error sqrt(s^2 / sum g^2) with
  // s^2 = RSS / (n - 1).
  struct ModulusFit {
    double value = 1.0, standard_error = 0.0, rss = 0.0;
    std::size_t samples = 0;
    std::string problem;  ///< why the samples fix no modulus; empty when they do
  };
  const auto try_modulus = [&](const Split& split) {
    ModulusFit m;
    double gg = 0.0, gf = 0.0;
    std::vector<std::pair<double, double>> pairs;
    for (std::size_t i : fitted) {
      const double z = all.depth_m[i];
      if (split.depth && z >= *split.depth) continue;
      const double g = interpolate_at(split.pre->depth_m, split.pre->force_N, z);
      pairs.push_back({g, all.force_N[i]});
      gg += g * g;
      gf += g * all.force_N[i];
    }
    if (pairs.size() < 2) {
      m.problem = std::to_string(pairs.size()) +
                  " fitted samples before the puncture; the modulus needs at least 2";
      return m;
    }
    if (!(gg > 0.0) || !(gf > 0.0)) {
      m.problem = "the samples before the puncture do not fix a positive modulus";
      return m;
    }
    m.value = gf / gg;
    m.samples = pairs.size();
    double rss = 0.0;
    for (const auto& [g, f] : pairs) rss += (f - m.value * g) * (f - m.value * g);
    m.rss = rss;
    m.standard_error = std::sqrt(rss / static_cast<double>(pairs.size() - 1) / gg);
    return m;
  };
  const auto fit_modulus = [&](const Split& split) {
    ModulusFit m = try_modulus(split);
    if (!m.problem.empty()) fail(measured.source + ": " + m.problem);
    return m;
  };
  std::vector<double> fitted_depths;  // sorted, each once
  for (std::size_t i : fitted) fitted_depths.push_back(all.depth_m[i]);
  std::sort(fitted_depths.begin(), fitted_depths.end());
  fitted_depths.erase(std::unique(fitted_depths.begin(), fitted_depths.end()), fitted_depths.end());
  // How many of those depths lie before the split.
  const auto depths_before = [&](const Split& split) -> std::size_t {
    if (!split.depth) return fitted_depths.size();
    return static_cast<std::size_t>(
        std::lower_bound(fitted_depths.begin(), fitted_depths.end(), *split.depth) -
        fitted_depths.begin());
  };
  ModulusFit modulus_fit;

  // ---- solve
  // -------------------------------------------------------------------------------------
  Split best_split;
  BoundedFit fit;
  std::optional<double> threshold, threshold_error;
  if (!fits_pc && !fits_gamma) {
    best_split =
        given_puncture_depth
            ? Split{given_puncture_depth,
                    fits_modulus ? rung_for_depth(*given_puncture_depth) : nullptr, std::nullopt}
            : split_for_threshold(scene_threshold);
    if (fits_modulus && given_puncture_depth) {
      modulus_fit = fit_modulus(best_split);
    } else if (fits_modulus) {
      // With the scene's threshold the puncture moves with k, and k with the samples before
      // the puncture. The first n fitted depths, n = 2, 3, ..., each give a k; the first n whose
      // k puts the puncture right after them is the shallowest puncture consistent with its own
      // modulus. (Samples after a puncture can fit a deeper one too: a post-puncture force
      // below the pre-puncture curve lowers k and so deepens the crossing.) Each try is a
      // closed-form fit on the runs already made.
      bool settled = false;
      for (std::size_t n = 2; n <= fitted_depths.size() && !settled; ++n) {
        const std::optional<double> end =
            n < fitted_depths.size()
                ? std::optional<double>(0.5 * (fitted_depths[n - 1] + fitted_depths[n]))
                : std::nullopt;
        const ModulusFit first =
            try_modulus({end, end ? rung_for_depth(*end) : last_rung, std::nullopt});
        if (!first.problem.empty()) continue;
        const Split split = split_for_threshold(scene_threshold / first.value);
        if (depths_before(split) != n) continue;
        // Refitted on the rung the crossing lies on (the same samples; a rung boundary between
        // the gap's middle and the crossing changes the curve, not the samples).
        modulus_fit = fit_modulus(split);
        best_split = split_for_threshold(scene_threshold / modulus_fit.value);
        if (depths_before(best_split) != n) {
          best_split = split;
          modulus_fit = first;
        }
        settled = true;
      }
      if (!settled) {
        fail(measured.source +
             ": no puncture is consistent with the modulus of the samples before it; give the "
             "measured puncture with --puncture-at, or fit the criterion's constant with it");
      }
    }
    modulus = modulus_fit.value;
    if (!enough_after(best_split)) {
      fail(measured.source + ": " + std::to_string(smooth_samples(best_split).size()) +
           " fitted samples after the puncture for the post-puncture constants");
    }
    if (!smooth.empty()) fit = fit_bounded(residuals_for(best_split), x0, bounds, {});
  } else {
    // Gaps between consecutive fitted depths that the pre-puncture run covers; the puncture in
    // the middle of a gap stands for the whole gap (the residuals are the same anywhere in it).
    std::vector<double> depths;
    for (std::size_t i : fitted) depths.push_back(all.depth_m[i]);
    std::sort(depths.begin(), depths.end());
    depths.erase(std::unique(depths.begin(), depths.end()), depths.end());
    std::vector<std::pair<double, double>> gaps;
    for (std::size_t k = 0; k + 1 < depths.size(); ++k) {
      if (depths[k + 1] <= last_rung->depth_m.back()) gaps.push_back({depths[k], depths[k + 1]});
    }
    if (gaps.empty()) fail("no two fitted samples lie within the pre-puncture run's depth");
    const auto gap_cost = [&](std::size_t g, std::vector<double>& x, int starts) {
      const double d = 0.5 * (gaps[g].first + gaps[g].second);
      const PreCurve* rung = rung_for_depth(d);
      Split split{d, rung, std::nullopt};
      double pre_cost = 0.0;  // the misfit before the split, which the modulus alone fits
      if (fits_modulus) {
        // A puncture with too few samples before it to fix the modulus is no candidate.
        const ModulusFit m = try_modulus(split);
        if (!m.problem.empty()) return std::numeric_limits<double>::infinity();
        modulus = m.value;
        pre_cost = m.rss;
        if (!enough_after(split)) return std::numeric_limits<double>::infinity();
      }
      if (fits_pc) {
        split.critical_pressure = modulus * interpolate_at(rung->depth_m, rung->criterion, d);
      }
      if (smooth.empty()) return pre_cost + cost_of(residuals_for(split)(x));
      BoundedFitOptions o;
      o.starts = starts;
      o.max_iterations = 60;
      const BoundedFit f = fit_bounded(residuals_for(split), x, bounds, o);
      x = f.x;
      return pre_cost + f.cost;
    };
    // Every gap when there are few, else every k-th and then the neighbours of the best.
    const std::size_t stride = std::max<std::size_t>(1, (gaps.size() + 39) / 40);
    std::size_t best_gap = 0;
    double best_cost = std::numeric_limits<double>::infinity();
    std::vector<double> x_start = x0;
    const auto consider = [&](std::size_t g) {
      std::vector<double> x = x_start;
      const double c = gap_cost(g, x, 1);
      if (c < best_cost) {
        best_cost = c;
        best_gap = g;
        x_start = x;
      }
    };
    for (std::size_t g = 0; g < gaps.size(); g += stride) consider(g);
    if (stride > 1) {
      const std::size_t centre = best_gap;
      for (std::size_t g = centre > stride ? centre - stride : 0;
           g < std::min(gaps.size(), centre + stride + 1); ++g) {
        consider(g);
      }
    }
    const double d = 0.5 * (gaps[best_gap].first + gaps[best_gap].second);
    best_split = {d, rung_for_depth(d), std::nullopt};
    if (fits_modulus) {
      modulus_fit = fit_modulus(best_split);
      modulus = modulus_fit.value;
      if (!enough_after(best_split)) {
        fail(measured.source +
             ": no candidate puncture leaves the modulus two samples before it "
             "and the post-puncture constants enough after it");
      }
    }
    if (fits_pc) {
      best_split.critical_pressure =
          modulus * interpolate_at(best_split.pre->depth_m, best_split.pre->criterion, d);
    }
    if (!smooth.empty()) fit = fit_bounded(residuals_for(best_split), x_start, bounds, {});
    const PreCurve& rung = *best_split.pre;
    const double lo = modulus * interpolate_at(rung.depth_m, rung.criterion, gaps[best_gap].first);
    const double hi = modulus * interpolate_at(rung.depth_m, rung.criterion, gaps[best_gap].second);
    threshold = modulus * interpolate_at(rung.depth_m, rung.criterion, d);
    // Anywhere in the gap fits as well: a uniform spread over it.
    threshold_error = std::abs(hi - lo) / std::sqrt(12.0);
    if (fits_modulus) {
      // threshold = k P(d): k's own error adds (P(d) and k independent).
      const double unscaled = *threshold / modulus;
      threshold_error = std::hypot(*threshold_error, unscaled * modulus_fit.standard_error);
    }
  }

  // ---- output
  // ------------------------------------------------------------------------------------
  Calibration out;
  out.contact_travel_m = all.contact_travel_m;
  out.converged = smooth.empty() || fit.converged;
  out.iterations = fit.iterations;
  const std::size_t p = options.fit.size();
  out.correlation.assign(p, std::vector<double>(p, 0.0));
  for (std::size_t j = 0; j < p; ++j) out.correlation[j][j] = 1.0;
  for (std::size_t a = 0; a < smooth.size(); ++a) {
    for (std::size_t b = 0; b < smooth.size(); ++b) {
      out.correlation[smooth[a]][smooth[b]] = fit.correlation[a][b];
    }
  }
  for (std::size_t j = 0; j < p; ++j) {
    CalibratedParameter param;
    param.constant = options.fit[j];
    const auto k = std::find(smooth.begin(), smooth.end(), j);
    if (k != smooth.end()) {
      const auto n = static_cast<std::size_t>(k - smooth.begin());
      param.initial = x0[n];
      param.value = fit.x[n];
      param.standard_error = fit.standard_error[n];
      param.at_bound = fit.at_bound[n];
      if (param.constant == CalibratedConstant::scale) param.initial = 1.0;
    } else if (param.constant == CalibratedConstant::modulus) {
      param.initial = 1.0;
      param.value = modulus_fit.value;
      param.standard_error = modulus_fit.standard_error;
    } else {
      const auto own = scene.tissue.layers.front().fracture;
      param.initial = own ? (fits_pc ? own->critical_pressure : own->toughness) : 0.0;
      param.value = *threshold;
      param.standard_error = *threshold_error;
    }
    out.parameters.push_back(param);
  }
  // The modulus's error in the constants that depend on it. A threshold is k times the
  // criterion's value (above). Where every layer's q is derived from its modulus the samples
  // after the puncture fix only the product of the scale and k: the scale's error given k
  // gains k's relative error, and the two are anticorrelated. (mu's error stays the one given
  // k: mu q also enters as a product, with the scale's own error already in it.)
  if (fits_modulus) {
    const auto index_of = [&](CalibratedConstant c) -> std::optional<std::size_t> {
      for (std::size_t j = 0; j < p; ++j) {
        if (options.fit[j] == c) return j;
      }
      return std::nullopt;
    };
    const std::size_t km = *index_of(CalibratedConstant::modulus);
    const CalibratedParameter& mod = out.parameters[km];
    const double relative_k = mod.standard_error / mod.value;
    const auto couple = [&](std::size_t j, double covariance) {
      const double sd = out.parameters[j].standard_error;
      if (!(sd > 0.0) || !std::isfinite(sd) || !(mod.standard_error > 0.0)) return;
      out.correlation[j][km] = out.correlation[km][j] = covariance / (sd * mod.standard_error);
    };
    for (CalibratedConstant c :
         {CalibratedConstant::critical_pressure, CalibratedConstant::toughness}) {
      if (const auto j = index_of(c)) {
        couple(*j, out.parameters[*j].value / mod.value * mod.standard_error * mod.standard_error);
      }
    }
    const bool all_follow =
        !follows_modulus.empty() &&
        std::all_of(follows_modulus.begin(), follows_modulus.end(), [](bool f) { return f; });
    if (const auto j = index_of(CalibratedConstant::scale); j && all_follow) {
      CalibratedParameter& scale = out.parameters[*j];
      scale.standard_error = std::hypot(scale.standard_error, scale.value * relative_k);
      couple(*j, -scale.value * relative_k * mod.standard_error);
    }
  }
  const Values best = values_of(smooth.empty() ? std::vector<double>{} : fit.x);
  out.puncture_depth_m = best_split.depth;
  const std::vector<double> model = model_at(best, best_split, used);
  std::vector<double> fit_measured, fit_model, fit_depth, out_measured, out_model, out_depth;
  for (std::size_t k = 0; k < used.size(); ++k) {
    const std::size_t i = used[k];
    out.depth_m.push_back(all.depth_m[i]);
    out.measured_N.push_back(all.force_N[i]);
    out.model_N.push_back(model[k]);
    out.fitted.push_back(in_fit(i));
    auto& m = in_fit(i) ? fit_measured : out_measured;
    auto& p = in_fit(i) ? fit_model : out_model;
    auto& d = in_fit(i) ? fit_depth : out_depth;
    m.push_back(all.force_N[i]);
    p.push_back(model[k]);
    d.push_back(all.depth_m[i]);
  }
  out.fit = compare_curves(fit_measured, fit_model);
  if (!out_measured.empty()) {
    out.held_out = compare_curves(out_measured, out_model);
    const Line line = least_squares_line(fit_depth, fit_measured);
    std::vector<double> line_model;
    for (double z : out_depth) line_model.push_back(line.intercept + line.slope * z);
    out.straight_line_held_out = compare_curves(out_measured, line_model);
  }
  for (std::size_t j = 0; j < base_q.size(); ++j) {
    const bool follows = j < follows_modulus.size() && follows_modulus[j];
    out.layer_pressure_scale_Pa.push_back(best.scale * base_q[j].pressure_scale_Pa *
                                          (follows ? best.modulus : 1.0));
  }
  out.modulus_factor = best.modulus;
  for (const TissueLayer& layer : scene.tissue.layers)
    out.layer_youngs_modulus_Pa.push_back(best.modulus * layer.material.youngs_modulus);
  out.friction_coefficient = best.mu;
  if (fits_pc) out.critical_pressure_Pa = threshold;
  if (fits_gamma) out.toughness_J_per_m2 = threshold;
  return out;
}

}  // namespace mneedle
