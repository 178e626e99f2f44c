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
#include <random>
#include <sstream>
#include <thread>

#include "mneedle/base/error.h"
#include "mneedle/base/files.h"
#include "mneedle/base/text.h"
#include "mneedle/blas_threads.h"
#include "mneedle/design_evaluation.h"
#include "mneedle/design_source.h"

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
  return (static_cast<double>(bits >> 11) + 0.5) * 0x1.0p-53;
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
      if (toml::node* n = t->get(key)) return n;
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

std::string sample_material(const Scene& scene, const UncertaintyOptions& o) {
  if (o.material) return *o.material;
  for (const auto& n : scene.needles)
    if (n.material) return *n.material;
  return "silicon";
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
  Quantity a{};
  try {
    a = parse_quantity(first);
  } catch (const InputError& e) {
    bad_spec(spec, e.what());
  }
  v.distribution.dimension = a.dimension;
  v.distribution.a = a.value_si;
  // The second value: a percentage (of the first), or a quantity of the first's dimension.
  const auto relative = percentage(second);
  double b = 0.0;
  if (!relative) {
    try {
      b = quantity_in(parse_quantity(second), a.dimension, v.path);
    } catch (const InputError& e) {
      bad_spec(spec, e.what());
    }
  }
  if (kind == "normal") {
    v.distribution.kind = DistributionKind::Normal;
    v.distribution.b = relative ? *relative * std::abs(a.value_si) : b;
    if (!(v.distribution.b > 0.0)) bad_spec(spec, "the standard deviation must be > 0");
  } else if (kind == "lognormal") {
    v.distribution.kind = DistributionKind::LogNormal;
    if (!relative) bad_spec(spec, "lognormal(MEDIAN,CV%) takes its spread as a percentage");
    if (!(a.value_si > 0.0)) bad_spec(spec, "a lognormal median must be > 0");
    if (!(*relative > 0.0)) bad_spec(spec, "the coefficient of variation must be > 0");
    v.distribution.b = std::sqrt(std::log1p(*relative * *relative));
  } else if (kind == "uniform") {
    v.distribution.kind = DistributionKind::Uniform;
    if (relative) bad_spec(spec, "uniform(LOW,HIGH) takes two values with units");
    v.distribution.b = b;
    if (!(b > a.value_si)) bad_spec(spec, "uniform needs LOW < HIGH");
  } else {
    bad_spec(spec, "unknown distribution '" + kind + "' (normal, lognormal, uniform)");
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
  for (const auto& [varied, value] : values) {
    toml::node* node = locate(root, varied.path);
    const std::string where = source + ": --vary " + varied.path;
    if (node == nullptr)
      throw InputError(where +
                       ": no such value in the scene (a layer name and one of its keys or its "
                       "material's, fracture.KEY, needle.KEY or a dotted path; write the value "
                       "into the scene first)");
    const Dimension d = varied.distribution.dimension;
    if (auto* text = node->as_string()) {
      const Quantity written = parse_quantity(text->get());
      if (!dimensions_compatible(d, written.dimension))
        throw InputError(where + ": the scene's value \"" + text->get() + "\" is a " +
                         std::string(dimension_name(written.dimension)) +
                         ", the distribution's a " + std::string(dimension_name(d)));
      *text =
          exact_text(value, written.dimension == Dimension::Dimensionless ? d : written.dimension);
    } else if (node->is_number()) {
      if (d != Dimension::Dimensionless)
        throw InputError(where + ": the scene's value is a plain number, the distribution's a " +
                         std::string(dimension_name(d)));
      if (auto* f = node->as_floating_point()) {
        *f = value;
      } else {
        // an integer in the scene takes a real value: replace the node
        throw InputError(where + ": the scene's value is an integer; write it as a real number");
      }
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

UncertaintyResult run_uncertainty(const std::filesystem::path& scene_file,
                                  const std::vector<VariedValue>& inputs,
                                  const PluginRegistry& registry, const UncertaintyOptions& options,
                                  const std::function<void(int, int)>& on_sample) {
  if (inputs.empty()) throw InputError("uncertainty: nothing to vary (give --vary PATH=DIST)");
  if (inputs.size() > kMaxInputs)
    throw InputError("uncertainty: " + std::to_string(inputs.size()) + " --vary values (at most " +
                     std::to_string(kMaxInputs) + ")");
  if (options.samples < 1 || options.samples > kMaxSamples)
    throw InputError("uncertainty: --samples " + std::to_string(options.samples) + " (from 1 to " +
                     std::to_string(kMaxSamples) + ")");
  const fe::Fidelity fidelity = parse_fidelity(options.fidelity);
  const PreModel model = parse_pre_model(options.model);
  const std::string text = read_input_file(scene_file);
  const std::string source = scene_file.string();

  UncertaintyResult result;
  result.inputs = inputs;
  // Every value is checked against the scene once, before any run: a misspelt path fails here.
  {
    std::vector<std::pair<VariedValue, double>> medians;
    for (const auto& v : inputs)
      medians.emplace_back(v, distribution_quantile(v.distribution, 0.5));
    parse_scene(scene_with_values(text, source, medians), source);
  }

  // Evaluates the scene with the values `set` (none: as written); never throws.
  using Edit = std::vector<std::pair<VariedValue, double>>;
  const auto evaluate = [&](const Edit& set) {
    UncertaintySample s;
    for (const auto& [v, value] : set) s.values.push_back(value);
    try {
      const Scene scene =
          parse_scene(set.empty() ? text : scene_with_values(text, source, set), source);
      if (scene.needles.empty()) throw InputError(source + ": the scene has no needle to evaluate");
      const NeedleSource needle = needle_from_scene(registry, scene.needles.front());
      EvaluationOptions o;
      o.fidelity = fidelity;
      o.model = model;
      o.axisymmetric = axisymmetric_profile(registry, needle, source);
      o.mirror_symmetric_y0 = o.axisymmetric.has_value() || mirror_symmetric_y0(needle.mesh);
      const DesignEvaluation e =
          evaluate_design(needle.mesh, scene, sample_material(scene, options), o);
      s.ok = true;
      if (e.puncture) {
        s.puncture_depth_m = e.puncture->depth_m;
        s.puncture_force_n = e.puncture->force_N;
        s.puncture_at_first_contact = e.puncture->at_first_contact;
      }
      s.puncture_objective_m = e.puncture_objective_m;
      s.peak_force_n = e.peak_force_n;
      s.margin = e.margin;
      s.passes = e.passes;
    } catch (const std::exception& e) {
      s.ok = false;
      s.error = e.what();
    }
    return s;
  };

  // The draws, in a fixed order and before any run: sample i, value k takes the i-th draw of
  // value k (Monte Carlo), or a point of stratum perm_k[i] (Latin hypercube).
  const auto n = static_cast<std::size_t>(options.samples);
  std::mt19937_64 random(options.seed);
  std::vector<Edit> runs(1 + n);  // runs[0]: the scene as written
  for (std::size_t i = 0; i < n; ++i)
    for (const auto& v : inputs) runs[1 + i].emplace_back(v, 0.0);
  if (options.latin_hypercube) {
    for (std::size_t k = 0; k < inputs.size(); ++k) {
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
        runs[1 + i][k].second = distribution_quantile(inputs[k].distribution, u);
      }
    }
  } else {
    for (std::size_t i = 0; i < n; ++i)
      for (std::size_t k = 0; k < inputs.size(); ++k)
        runs[1 + i][k].second = distribution_quantile(inputs[k].distribution, open_unit(random()));
  }
  // One at a time: each value at its 5 % and 95 % quantiles, every other as the scene has it.
  if (options.sensitivity)
    for (const auto& v : inputs)
      for (const double q : {0.05, 0.95})
        runs.push_back({{v, distribution_quantile(v.distribution, q)}});

  std::vector<UncertaintySample> done(runs.size());
  std::atomic<std::size_t> next{0};
  std::mutex report;
  int finished = 0;
  const auto worker = [&] {
    for (std::size_t j = next++; j < runs.size(); j = next++) {
      done[j] = evaluate(runs[j]);
      std::lock_guard<std::mutex> lock(report);
      ++finished;
      if (on_sample) on_sample(finished, static_cast<int>(runs.size()));
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(runs.size())));
  // As in screen: one OpenBLAS thread per job, so that jobs share the cores (and the samples'
  // arithmetic does not depend on how many run at once).
  std::optional<BlasThreadLimit> blas;
  if (jobs > 1) blas.emplace(1);
  std::vector<std::thread> pool;
  for (int t = 1; t < jobs; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();

  result.nominal = done[0];
  if (!result.nominal.ok)
    throw InputError("uncertainty: the scene as written cannot be evaluated: " +
                     result.nominal.error);
  result.samples.assign(done.begin() + 1, done.begin() + 1 + static_cast<std::ptrdiff_t>(n));
  std::vector<double> depth, force, peak, margin;
  std::size_t ran = 0, punctured = 0, passed = 0, first_contact = 0;
  for (const auto& s : result.samples) {
    if (!s.ok) {
      ++result.failed;
      continue;
    }
    ++ran;
    peak.push_back(s.peak_force_n);
    if (std::isfinite(s.margin)) margin.push_back(s.margin);
    passed += s.passes ? 1 : 0;
    first_contact += s.puncture_at_first_contact ? 1 : 0;
    // A depth that is only the first step's says nothing of the tissue: not in the spread.
    if (s.puncture_depth_m && !s.puncture_at_first_contact) {
      ++punctured;
      depth.push_back(*s.puncture_depth_m);
      force.push_back(s.puncture_force_n);
    }
  }
  result.puncture_depth_m = percentiles(depth);
  result.puncture_force_n = percentiles(force);
  result.peak_force_n = percentiles(peak);
  result.margin = percentiles(margin);
  result.punctured_fraction = ran ? static_cast<double>(punctured) / static_cast<double>(ran) : 0.0;
  result.first_contact_fraction =
      ran ? static_cast<double>(first_contact) / static_cast<double>(ran) : 0.0;
  result.pass_probability = ran ? static_cast<double>(passed) / static_cast<double>(ran) : 0.0;
  if (options.sensitivity) {
    for (std::size_t k = 0; k < inputs.size(); ++k) {
      Sensitivity s;
      s.path = inputs[k].path;
      s.low = done[1 + n + 2 * k];
      s.high = done[1 + n + 2 * k + 1];
      if (s.low.ok && s.high.ok) {
        s.depth_effect_m = std::abs(s.high.puncture_objective_m - s.low.puncture_objective_m);
        s.peak_effect_n = std::abs(s.high.peak_force_n - s.low.peak_force_n);
      }
      result.sensitivity.push_back(std::move(s));
    }
    std::stable_sort(result.sensitivity.begin(), result.sensitivity.end(),
                     [](const Sensitivity& a, const Sensitivity& b) {
                       if (a.depth_effect_m != b.depth_effect_m)
                         return a.depth_effect_m > b.depth_effect_m;
                       return a.peak_effect_n > b.peak_effect_n;
                     });
  }
  return result;
}

}  // namespace mneedle
