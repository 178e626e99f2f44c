#include "mneedle/uncertainty.h"

#include <toml++/toml.h>

#include <algorithm>
#include <atomic>
#include <boost/math/distributions/lognormal.hpp>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/uniform.hpp>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <thread>

#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/text.h"
#include "mneedle/blas_threads.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/design_source.h"
#include "mneedle/screening_mpi.h"
#include "mpi_dealer.h"

namespace mneedle {
namespace {

// Bounds on the work one command line can ask for (docs/cli.md, "mneedle uncertainty").
constexpr int kMaxSamples = 100000;
constexpr std::size_t kMaxInputs = 64;

[[noreturn]] void bad_spec(const std::string& spec, const std::string& problem) {
  throw InputError("--vary '" + spec + "': " + problem);
}

// "20%" -> 0.2; nothing when the text is not a percentage.
std::optional<double> percentage(const std::string& text) {
  if (text.empty() || text.back() != '%') return std::nullopt;
  const std::string number = std::string(trim(text.substr(0, text.size() - 1)));
  char* end = nullptr;
  const double v = std::strtod(number.c_str(), &end);
  if (number.empty() || end != number.c_str() + number.size() || !std::isfinite(v))
    return std::nullopt;
  return v / 100.0;
}

// A 64-bit draw as a double in (0, 1): never 0 or 1, where inverse CDFs are infinite.
double open_unit(std::uint64_t bits) {
  // 52 bits plus a half: exact in a double, so never rounds up to 1.
  return (static_cast<double>(bits >> 12) + 0.5) * 0x1.0p-52;
}

toml::node* find_in(toml::table& table, const std::string& dotted) {
  toml::node* node = &table;
  std::size_t start = 0;
  while (node != nullptr && start <= dotted.size()) {
    const std::size_t dot = dotted.find('.', start);
    const std::string key = dotted.substr(start, dot == std::string::npos ? dot : dot - start);
    toml::table* t = node->as_table();
    node = t ? t->get(key) : nullptr;
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return node;
}

// Where `path` lives in the scene's TOML (see scene_with_values), or nullptr.
toml::node* locate(toml::table& root, const std::string& path) {
  const auto dot = path.find('.');
  if (dot == std::string::npos) return nullptr;
  const std::string head = path.substr(0, dot);
  const std::string key = path.substr(dot + 1);
  if (auto* layers = root.at_path("tissue.layers").as_array()) {
    for (auto& layer : *layers) {
      auto* t = layer.as_table();
      if (t == nullptr || t->get("name") == nullptr ||
          t->get("name")->value_or(std::string()) != head)
        continue;
      if (toml::node* n = find_in(*t, key)) return n;  // a key, or fracture.KEY of its own
      if (auto* material = t->get("material"); material && material->as_table())
        if (toml::node* n = material->as_table()->get(key)) return n;
      return nullptr;
    }
  }
  if (head == "fracture") return find_in(root, "tissue.fracture." + key);
  if (head == "needle") {
    auto* needles = root.get("needles") ? root.get("needles")->as_array() : nullptr;
    if (needles == nullptr || needles->empty() || !(*needles)[0].as_table()) return nullptr;
    auto* geometry = (*needles)[0].as_table()->get("geometry");
    return geometry && geometry->as_table() ? geometry->as_table()->get(key) : nullptr;
  }
  return find_in(root, path);
}

std::string exact_text(double value_si, Dimension d) {
  char text[64];
  std::snprintf(text, sizeof text, "%.17g", value_si);
  const std::string unit(si_unit(d));
  return unit.empty() ? std::string(text) : std::string(text) + " " + unit;
}

}  // namespace

double distribution_quantile(const Distribution& d, double p) {
  switch (d.kind) {
    case DistributionKind::Normal:
      return boost::math::quantile(boost::math::normal_distribution<double>(d.a, d.b), p);
    case DistributionKind::LogNormal:
      return boost::math::quantile(boost::math::lognormal_distribution<double>(std::log(d.a), d.b),
                                   p);
    case DistributionKind::Uniform:
      return boost::math::quantile(boost::math::uniform_distribution<double>(d.a, d.b), p);
  }
  return d.a;
}

VariedValue parse_varied_value(const std::string& spec) {
  VariedValue v;
  v.text = spec;
  const auto eq = spec.find('=');
  if (eq == std::string::npos) bad_spec(spec, "expected PATH=DISTRIBUTION(A,B)");
  v.path = std::string(trim(spec.substr(0, eq)));
  if (v.path.empty() || v.path.find('.') == std::string::npos)
    bad_spec(spec, "the path must name a layer and a key, e.g. dermis.E");
  const std::string rest = std::string(trim(spec.substr(eq + 1)));
  const auto open = rest.find('(');
  if (open == std::string::npos || rest.back() != ')')
    bad_spec(spec, "expected normal(MEAN,SD), lognormal(MEDIAN,CV%) or uniform(LOW,HIGH)");
  const std::string kind = std::string(trim(rest.substr(0, open)));
  const std::string inner = rest.substr(open + 1, rest.size() - open - 2);
  const auto comma = inner.find(',');
  if (comma == std::string::npos || inner.find(',', comma + 1) != std::string::npos)
    bad_spec(spec, "a distribution takes two values");
  const std::string first = std::string(trim(inner.substr(0, comma)));
  const std::string second = std::string(trim(inner.substr(comma + 1)));
  if (kind != "normal" && kind != "lognormal" && kind != "uniform")
    bad_spec(spec, "unknown distribution '" + kind + "' (normal, lognormal, uniform)");
  const auto relative = percentage(second);
  if (kind == "lognormal" && !relative)
    bad_spec(spec, "lognormal(MEDIAN,CV%) takes its spread as a percentage");
  if (kind == "uniform" && relative)
    bad_spec(spec, "uniform(LOW,HIGH) takes two values with units");
  // The dimension is that of whichever value has a unit ("0" has none and fits any).
  Quantity a{}, b_given{};
  try {
    a = parse_quantity(first);
    if (!relative) b_given = parse_quantity(second);
  } catch (const InputError& e) {
    bad_spec(spec, e.what());
  }
  const Dimension dimension =
      a.dimension != Dimension::Dimensionless || relative ? a.dimension : b_given.dimension;
  v.distribution.dimension = dimension;
  double b = 0.0;
  try {
    v.distribution.a = quantity_in(a, dimension, v.path);
    if (!relative) b = quantity_in(b_given, dimension, v.path);
  } catch (const InputError& e) {
    bad_spec(spec, e.what());
  }
  if (kind == "normal") {
    v.distribution.kind = DistributionKind::Normal;
    v.distribution.b = relative ? *relative * std::abs(v.distribution.a) : b;
    if (!(v.distribution.b > 0.0))
      bad_spec(spec, relative ? "the standard deviation must be > 0 (a percentage of a zero mean "
                                "is 0: give it with units)"
                              : "the standard deviation must be > 0");
  } else if (kind == "lognormal") {
    v.distribution.kind = DistributionKind::LogNormal;
    if (!(v.distribution.a > 0.0)) bad_spec(spec, "a lognormal median must be > 0");
    if (!(*relative > 0.0)) bad_spec(spec, "the coefficient of variation must be > 0");
    v.distribution.b = std::sqrt(std::log1p(*relative * *relative));
  } else if (kind == "uniform") {
    v.distribution.kind = DistributionKind::Uniform;
    v.distribution.b = b;
    if (!(b > v.distribution.a)) bad_spec(spec, "uniform needs LOW < HIGH");
  }
  return v;
}

std::string scene_with_values(const std::string& toml_text, const std::string& source,
                              const std::vector<std::pair<VariedValue, double>>& values) {
  toml::table root;
  try {
    root = toml::parse(toml_text, std::string_view(source));
  } catch (const toml::parse_error& e) {
    throw InputError(source + ": " + std::string(e.description()));
  }
  std::vector<const toml::node*> seen;
  for (const auto& [varied, value] : values) {
    toml::node* node = locate(root, varied.path);
    const std::string where = source + ": --vary " + varied.path;
    if (node == nullptr)
      throw InputError(where +
                       ": no such value in the scene (a layer name and one of its keys or its "
                       "material's, fracture.KEY, needle.KEY or a dotted path; write the value "
                       "into the scene first)");
    if (std::find(seen.begin(), seen.end(), node) != seen.end())
      throw InputError(where + ": the same value is varied twice (another --vary names it)");
    seen.push_back(node);
    const Dimension d = varied.distribution.dimension;
    if (auto* text = node->as_string()) {
      Quantity written{};
      try {
        written = parse_quantity(text->get());
      } catch (const InputError&) {
        throw InputError(where + ": the scene's value \"" + text->get() +
                         "\" is not a number or a quantity");
      }
      if (!dimensions_compatible(d, written.dimension))
        throw InputError(where + ": the scene's value \"" + text->get() + "\" is a " +
                         std::string(dimension_name(written.dimension)) +
                         ", the distribution's a " + std::string(dimension_name(d)));
      *text = exact_text(value, written.dimension);
    } else if (node->is_number()) {
      if (d != Dimension::Dimensionless)
        throw InputError(where + ": the scene's value is a plain number, the distribution's a " +
                         std::string(dimension_name(d)));
      auto* f = node->as_floating_point();
      if (f == nullptr)  // an integer cannot hold a drawn real value
        throw InputError(where + ": the scene's value is an integer; write it as a real number");
      *f = value;
    } else {
      throw InputError(where + ": not a number or a quantity");
    }
  }
  std::ostringstream text;
  text << root << "\n";
  return text.str();
}

Percentiles percentiles(std::vector<double> values) {
  Percentiles p;
  p.count = values.size();
  if (values.empty()) return p;
  std::sort(values.begin(), values.end());
  const auto at = [&](double q) {
    const double h = q * static_cast<double>(values.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(h));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (h - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  p.p5 = at(0.05);
  p.p50 = at(0.5);
  p.p95 = at(0.95);
  return p;
}

namespace {

// The scene's own first needle, built again in each sampled scene (a varied needle.KEY moves it).
SceneEvaluator scene_needle_evaluator(const PluginRegistry& registry,
                                      const UncertaintyOptions& options,
                                      const std::string& source) {
  const fe::Fidelity fidelity = parse_fidelity(options.fidelity);
  const PreModel model = parse_pre_model(options.model);
  return [&registry, fidelity, model, source, material = options.material](const Scene& scene) {
    if (scene.needles.empty()) throw InputError(source + ": the scene has no needle to evaluate");
    const NeedleSource needle = needle_from_scene(registry, scene.needles.front(),
                                                  scene_needle_where(scene, scene.needles.front()));
    EvaluationOptions o;
    o.fidelity = fidelity;
    o.model = model;
    o.symmetry = needle_symmetry(registry, needle, source);
    return evaluate_design(needle.mesh, scene, design_material(scene, material), o);
  };
}

// Runs tasks 0 … runs − 1 of `run` into `done`, calling `on_done` (serialised) as each finishes;
// false on an MPI rank other than 0, which has no results.
using RunAll =
    std::function<bool(std::size_t runs, const std::function<UncertaintySample(std::size_t)>& run,
                       std::vector<UncertaintySample>& done, const std::function<void()>& on_done)>;

// Called by every process after the scene as written ran (or failed: `failure`): rethrows the
// failure, or under MPI stops every rank when any failed (each error said once).
using Settle = std::function<void(const std::exception_ptr& failure)>;

void settle_alone(const std::exception_ptr& failure) {
  if (failure) std::rethrow_exception(failure);
}

// The runs on `jobs` threads of this process.
RunAll threads_run_all(int requested_jobs) {
  return
      [requested_jobs](std::size_t runs, const std::function<UncertaintySample(std::size_t)>& run,
                       std::vector<UncertaintySample>& done, const std::function<void()>& on_done) {
        std::atomic<std::size_t> next{0};
        std::mutex report;
        const auto worker = [&] {
          for (std::size_t r = next++; r < runs; r = next++) {
            done[r] = run(r);
            std::lock_guard<std::mutex> lock(report);
            on_done();
          }
        };
        const int jobs = std::max(1, std::min<int>(requested_jobs, static_cast<int>(runs)));
        std::vector<std::thread> pool;
        for (int t = 1; t < jobs; ++t) pool.emplace_back(worker);
        worker();
        for (auto& t : pool) t.join();
        return true;
      };
}

std::optional<UncertaintyResult> uncertainty_core(
    const std::string& text, const std::string& source, const std::vector<VariedValue>& inputs,
    const UncertaintyOptions& options, const SceneEvaluator& evaluate_scene,
    const std::function<void(int, int)>& on_sample, const RunAll& run_all, const Settle& settle);

}  // namespace

UncertaintyResult run_uncertainty(const std::filesystem::path& scene_file,
                                  const std::vector<VariedValue>& inputs,
                                  const PluginRegistry& registry, const UncertaintyOptions& options,
                                  const std::function<void(int, int)>& on_sample) {
  const std::string source = scene_file.string();
  return run_uncertainty(read_input_file(scene_file), source, inputs, options,
                         scene_needle_evaluator(registry, options, source), on_sample);
}

UncertaintyResult run_uncertainty(const std::string& text, const std::string& source,
                                  const std::vector<VariedValue>& inputs,
                                  const UncertaintyOptions& options,
                                  const SceneEvaluator& evaluate_scene,
                                  const std::function<void(int, int)>& on_sample) {
  // As in screen: one OpenBLAS thread per job, so that jobs share the cores and each run's
  // arithmetic does not depend on how many run beside it; held from the nominal run on, as under
  // MPI, so that every run of the command is at the same thread count.
  std::optional<BlasThreadLimit> blas;
  if (options.jobs > 1) blas.emplace(1);
  return *uncertainty_core(text, source, inputs, options, evaluate_scene, on_sample,
                           threads_run_all(options.jobs), settle_alone);
}

namespace {

std::optional<UncertaintyResult> uncertainty_core(
    const std::string& text, const std::string& source, const std::vector<VariedValue>& inputs,
    const UncertaintyOptions& options, const SceneEvaluator& evaluate_scene,
    const std::function<void(int, int)>& on_sample, const RunAll& run_all, const Settle& settle) {
  // A scene with drawn values is the file re-serialised (keys sorted, comments gone): its
  // messages must not point at lines of the file.
  const std::string drawn_source = source + " (with drawn values)";

  UncertaintyResult result;
  result.inputs = inputs;
  using Edit = std::vector<std::pair<VariedValue, double>>;
  // Evaluates the scene with `set` (none: as written); throws what the evaluation throws.
  const auto evaluate_or_throw = [&](const Edit& set) {
    UncertaintySample s;
    for (const auto& entry : set) s.values.push_back(entry.second);
    const Scene scene = set.empty()
                            ? parse_scene(text, source)
                            : parse_scene(scene_with_values(text, source, set), drawn_source);
    const DesignEvaluation e = evaluate_scene(scene);
    s.ok = true;
    if (e.puncture) {
      s.puncture_depth_m = e.puncture->depth_m;
      s.puncture_force_n = e.puncture->force_N;
      s.puncture_at_first_contact = e.puncture->at_first_contact;
    }
    s.puncture_objective_m = e.puncture_objective_m;
    s.peak_force_n = e.peak_force_n;
    s.margin = e.margin;  // +inf without force: the safest case, not an error
    s.passes = e.passes;
    // As in screen: no NaN or Inf may reach a percentile or the output.
    for (const double v : {s.puncture_depth_m.value_or(0.0), s.puncture_force_n,
                           s.puncture_objective_m, s.peak_force_n})
      if (!std::isfinite(v)) throw SolverError("non-finite result (not used)");
    if (std::isnan(s.margin)) throw SolverError("non-finite margin (not used)");
    return s;
  };
  const auto evaluate = [&](const Edit& set) {
    try {
      return evaluate_or_throw(set);
    } catch (const std::exception& e) {
      UncertaintySample s;
      for (const auto& entry : set) s.values.push_back(entry.second);
      s.error = e.what();
      return s;
    }
  };
  // The scene as written first, alone: if it cannot run, nothing else is worth running, and its
  // error keeps its kind (input or solver).
  std::exception_ptr failure;
  try {
    if (inputs.empty()) throw InputError("uncertainty: nothing to vary (give --vary PATH=DIST)");
    if (inputs.size() > kMaxInputs)
      throw InputError("uncertainty: " + std::to_string(inputs.size()) +
                       " --vary values (at most " + std::to_string(kMaxInputs) + ")");
    if (options.samples < 1 || options.samples > kMaxSamples)
      throw InputError("uncertainty: --samples " + std::to_string(options.samples) +
                       " (from 1 to " + std::to_string(kMaxSamples) + ")");
    // Every value is checked against the scene once, before any run: a misspelt path, a wrong
    // unit or the same value twice fails here.
    Edit medians;
    for (const auto& v : inputs)
      medians.emplace_back(v, distribution_quantile(v.distribution, 0.5));
    parse_scene(scene_with_values(text, source, medians), drawn_source);
    result.nominal = evaluate_or_throw({});
  } catch (...) {
    failure = std::current_exception();
  }
  settle(failure);

  // The draws, in a fixed order and before any run: sample i, value k takes the (i K + k)-th draw
  // (Monte Carlo), or a point of stratum perm_k(i) (Latin hypercube). Plain numbers only: the
  // scene edit of a sample is built when it runs.
  const auto n = static_cast<std::size_t>(options.samples);
  const std::size_t K = inputs.size();
  std::mt19937_64 random(options.seed);
  std::vector<double> draws(n * K);
  if (options.latin_hypercube) {
    for (std::size_t k = 0; k < K; ++k) {
      std::vector<std::size_t> stratum(n);
      for (std::size_t i = 0; i < n; ++i) stratum[i] = i;
      for (std::size_t i = n; i > 1; --i) {  // Fisher-Yates, spelt out: std::shuffle may differ
        const auto j =
            std::min(static_cast<std::size_t>(open_unit(random()) * static_cast<double>(i)), i - 1);
        std::swap(stratum[i - 1], stratum[j]);
      }
      for (std::size_t i = 0; i < n; ++i) {
        const double u =
            (static_cast<double>(stratum[i]) + open_unit(random())) / static_cast<double>(n);
        draws[i * K + k] = distribution_quantile(inputs[k].distribution, u);
      }
    }
  } else {
    for (std::size_t i = 0; i < n * K; ++i)
      draws[i] = distribution_quantile(inputs[i % K].distribution, open_unit(random()));
  }
  // Runs 0 … n−1: the samples; then, one at a time, each value at its 5 % and 95 % quantiles with
  // every other value as the scene has it.
  const std::size_t runs = n + (options.sensitivity ? 2 * K : 0);
  const auto edit_of = [&](std::size_t r) {
    Edit set;
    if (r < n) {
      for (std::size_t k = 0; k < K; ++k) set.emplace_back(inputs[k], draws[r * K + k]);
    } else {
      const std::size_t k = (r - n) / 2;
      const double q = (r - n) % 2 == 0 ? 0.05 : 0.95;
      set.emplace_back(inputs[k], distribution_quantile(inputs[k].distribution, q));
    }
    return set;
  };

  std::vector<UncertaintySample> done(runs);
  int finished = 0;
  const auto on_done = [&] {
    ++finished;
    if (on_sample) on_sample(finished, static_cast<int>(runs));
  };
  if (!run_all(
          runs, [&](std::size_t r) { return evaluate(edit_of(r)); }, done, on_done))
    return std::nullopt;  // an MPI rank other than 0: rank 0 has the results

  result.samples.assign(done.begin(), done.begin() + static_cast<std::ptrdiff_t>(n));
  std::vector<double> depth, force, peak, margin;
  std::size_t ran = 0, punctured = 0, passed = 0, first_contact = 0;
  const UncertaintySample* first_failure = nullptr;
  for (const auto& s : result.samples) {
    if (!s.ok) {
      ++result.failed;
      if (first_failure == nullptr) first_failure = &s;
      continue;
    }
    ++ran;
    peak.push_back(s.peak_force_n);
    if (std::isfinite(s.margin)) margin.push_back(s.margin);  // +inf (no force) left out
    passed += s.passes ? 1 : 0;
    first_contact += s.puncture_at_first_contact ? 1 : 0;
    // A depth that is only the first step's says nothing of the tissue: not in the spread.
    if (s.puncture_depth_m && !s.puncture_at_first_contact) {
      ++punctured;
      depth.push_back(*s.puncture_depth_m);
      force.push_back(s.puncture_force_n);
    }
  }
  if (ran == 0)
    throw InputError("uncertainty: none of the " + std::to_string(n) +
                     " samples could be evaluated; the first: " + first_failure->error);
  result.puncture_depth_m = percentiles(depth);
  result.puncture_force_n = percentiles(force);
  result.peak_force_n = percentiles(peak);
  result.margin = percentiles(margin);
  const auto share = [&](std::size_t count) {
    return static_cast<double>(count) / static_cast<double>(ran);
  };
  result.punctured_fraction = share(punctured);
  result.first_contact_fraction = share(first_contact);
  result.pass_probability = share(passed);
  result.pass_probability_standard_error =
      binomial_standard_error(result.pass_probability, static_cast<double>(ran));
  if (options.sensitivity) {
    for (std::size_t k = 0; k < K; ++k) {
      Sensitivity s;
      s.path = inputs[k].path;
      s.low = done[n + 2 * k];
      s.high = done[n + 2 * k + 1];
      if (s.low.ok && s.high.ok) {
        // Two runs that agree to round-off (a value the input cannot move, reached along other
        // paths: 3e-12 relative measured on a skin cylinder's peak force with the strength
        // varied) are no effect, and printed they read as one. 1e-9 lies far above that and far
        // below any effect worth a line.
        const auto effect = [](double a, double b) {
          const double d = std::abs(a - b);
          return d <= 1e-9 * std::max(std::abs(a), std::abs(b)) ? 0.0 : d;
        };
        s.depth_effect_m = effect(s.high.puncture_objective_m, s.low.puncture_objective_m);
        s.peak_effect_n = effect(s.high.peak_force_n, s.low.peak_force_n);
        const auto resolved = [](const UncertaintySample& x) {
          return x.puncture_depth_m.has_value() && !x.puncture_at_first_contact;
        };
        s.both_resolved = resolved(s.low) && resolved(s.high);
      }
      result.sensitivity.push_back(std::move(s));
    }
    // Measured effects first (largest depth effect, then force); an input whose 5 % or 95 % run
    // failed has none and comes last.
    std::stable_sort(result.sensitivity.begin(), result.sensitivity.end(),
                     [](const Sensitivity& a, const Sensitivity& b) {
                       if (a.depth_effect_m.has_value() != b.depth_effect_m.has_value())
                         return a.depth_effect_m.has_value();
                       if (!a.depth_effect_m) return false;
                       if (*a.depth_effect_m != *b.depth_effect_m)
                         return *a.depth_effect_m > *b.depth_effect_m;
                       return *a.peak_effect_n > *b.peak_effect_n;
                     });
  }
  return result;
}

}  // namespace

namespace {

// A run's result as the text one rank sends another: every number as JSON writes it (the
// shortest text that reads back to the same double, so the result arrives bit for bit); an
// infinite margin (no force) as null.
std::string sample_text(const UncertaintySample& s) {
  return nlohmann::json{
      {"values", s.values},
      {"ok", s.ok},
      {"error", s.error},
      {"depth", s.puncture_depth_m ? nlohmann::json(*s.puncture_depth_m) : nlohmann::json()},
      {"force", s.puncture_force_n},
      {"first_contact", s.puncture_at_first_contact},
      {"objective", s.puncture_objective_m},
      {"peak", s.peak_force_n},
      {"margin", s.margin == INFINITY ? nlohmann::json() : nlohmann::json(s.margin)},
      {"passes", s.passes}}
      // An error message may hold a path that is not UTF-8: replaced, never a throw.
      .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

UncertaintySample sample_from_text(const std::string& text) {
  const auto j = nlohmann::json::parse(text);
  UncertaintySample s;
  s.values = j.at("values").get<std::vector<double>>();
  s.ok = j.at("ok").get<bool>();
  s.error = j.at("error").get<std::string>();
  if (!j.at("depth").is_null()) s.puncture_depth_m = j.at("depth").get<double>();
  s.puncture_force_n = j.at("force").get<double>();
  s.puncture_at_first_contact = j.at("first_contact").get<bool>();
  s.puncture_objective_m = j.at("objective").get<double>();
  s.peak_force_n = j.at("peak").get<double>();
  s.margin = j.at("margin").is_null() ? INFINITY : j.at("margin").get<double>();
  s.passes = j.at("passes").get<bool>();
  return s;
}

}  // namespace

std::optional<UncertaintyResult> run_uncertainty_mpi(
    const MpiSession& session, const std::filesystem::path& scene_file,
    const std::vector<VariedValue>& inputs, const PluginRegistry& registry,
    const UncertaintyOptions& options, const std::function<void(int, int)>& on_sample) {
  const bool coordinator = session.rank() == 0;
  const std::string source = scene_file.string();
  // Every rank must draw the same samples of the same scene: what defines them is compared with
  // rank 0's before anything runs (a rank that reads another file stops the run).
  std::string text, failure;
  try {
    text = read_input_file(scene_file);
  } catch (const std::exception& e) {
    failure = e.what();
  }
  std::string definition =
      text + "|" + std::to_string(options.samples) + "|" + std::to_string(options.seed) + "|" +
      (options.latin_hypercube ? "lhs" : "mc") + "|" + options.fidelity + "|" + options.model +
      "|" + options.material.value_or("") + "|" + (options.sensitivity ? "s" : "") +
      "|jobs=" + std::to_string(std::max(1, options.jobs));  // rank 0 counts the others' threads
  for (const auto& v : inputs) definition += "|" + v.text;
  if (!session.matches_rank0(definition) && failure.empty())
    failure =
        "uncertainty --mpi: rank " + std::to_string(session.rank()) +
        " sees another scene or other settings (or --jobs) than rank 0 (every rank must read the "
        "same files)";
  // Under MPI every failure before the samples stops every rank; each error is said once.
  const auto stop_if_any_failed = [&](bool ok, const std::function<void()>& rethrow) {
    const auto agreement = session.agree(ok);
    if (agreement.all) return;
    if (!ok && (coordinator || agreement.rank0)) rethrow();
    if (coordinator)
      throw InputError("uncertainty --mpi: another rank could not start (its line says why)");
    throw RankStopped();
  };
  stop_if_any_failed(failure.empty(), [&] { throw InputError(failure); });

  const int jobs = std::max(1, options.jobs);
  // Several ranks on one machine, or several threads in one rank: one OpenBLAS thread each, as
  // the threads of the serial run (the same factorisations, so the same samples).
  std::optional<BlasThreadLimit> blas;
  if (jobs > 1 || session.size() > 1) blas.emplace(1);
  const RunAll over_ranks = [&](std::size_t runs,
                                const std::function<UncertaintySample(std::size_t)>& run,
                                std::vector<UncertaintySample>& done,
                                const std::function<void()>& on_done) {
    std::atomic<std::size_t> next{0};
    std::mutex record;
    std::vector<char> recorded(runs, 0);
    const auto keep = [&](std::size_t i, UncertaintySample s) {
      std::lock_guard<std::mutex> lock(record);
      if (recorded[i]) return;
      done[i] = std::move(s);
      recorded[i] = 1;
      on_done();
    };
    DealtTasks tasks;
    tasks.count = runs;
    tasks.claim = [&]() -> std::optional<std::size_t> {
      const std::size_t i = next++;
      if (i < runs) return i;
      return std::nullopt;
    };
    tasks.run_here = [&](std::size_t i) { keep(i, run(i)); };
    tasks.run_for_rank0 = [&](std::size_t i) {
      try {
        return sample_text(run(i));
      } catch (const std::exception& e) {  // run() catches its own; this is text that failed
        UncertaintySample s;
        s.error = e.what();
        return sample_text(s);
      }
    };
    tasks.record_text = [&](std::size_t i, const std::string& text) {
      UncertaintySample s;
      try {
        s = sample_from_text(text);
      } catch (const std::exception& e) {
        s.error = std::string("the result sent by another rank is unreadable (") + e.what() + ")";
      }
      keep(i, std::move(s));
    };
    deal_over_ranks(session, jobs, tasks, "uncertainty");
    if (!coordinator) return false;
    // Every run dealt had its result back; should one ever not, it is an error row, not zeros.
    for (std::size_t i = 0; i < runs; ++i)
      if (!recorded[i]) done[i].error = "no result came back for this run";
    return true;
  };
  const Settle settle = [&](const std::exception_ptr& e) {
    stop_if_any_failed(e == nullptr, [&] { std::rethrow_exception(e); });
  };
  return uncertainty_core(text, source, inputs, options,
                          scene_needle_evaluator(registry, options, source), on_sample, over_ranks,
                          settle);
}

double binomial_standard_error(double p, double n) {
  return n > 0.0 ? std::sqrt(p * (1.0 - p) / n) : 0.0;
}

}  // namespace mneedle
