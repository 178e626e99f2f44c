#include "mneedle/scene/scene.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <numbers>
#include <set>
#include <sstream>
#include <utility>

#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/needle_frame.h"

namespace mneedle {
namespace {

// Relative slack when comparing sums of layer thicknesses with the block depth: the decimal
// inputs ("20 um" + "100 um" + ...) do not add up exactly in binary.
constexpr double kRelativeSlack = 1e-9;

int line_of(const toml::node& n) {
  return static_cast<int>(n.source().begin.line);
}

std::string join_path(const std::string& parent, std::string_view key) {
  return parent.empty() ? std::string(key) : parent + "." + std::string(key);
}

std::string indexed(const std::string& path, std::size_t i) {
  return path + "[" + std::to_string(i) + "]";
}

// Reads one TOML table, remembers which keys it was asked about and reports every other key as
// unknown in finish(): that is how typos anywhere in a scene are caught.
class Table {
 public:
  Table(const toml::table& table, std::string path, const std::string& file, int fallback_line)
      : table_(table), path_(std::move(path)), file_(file) {
    line_ = line_of(table) > 0 ? line_of(table) : fallback_line;
  }

  const std::string& path() const { return path_; }
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  std::string key_path(std::string_view key) const { return join_path(path_, key); }

  const toml::node* get(std::string_view key) {
    known_.emplace(key);
    return table_.get(key);
  }

  [[noreturn]] void fail(std::string_view key_path_text, int line, std::string_view problem) const {
    throw InputError(file_ + ":" + std::to_string(line > 0 ? line : line_) + ": " +
                     std::string(key_path_text) + ": " + std::string(problem));
  }

  [[noreturn]] void fail_key(std::string_view key, std::string_view problem) {
    const toml::node* node = get(key);
    fail(key_path(key), node ? line_of(*node) : line_, problem);
  }

  [[noreturn]] void fail_missing(std::string_view key, std::string_view expected) const {
    // A missing key is most often a misspelt one: report the typo, it is the real mistake.
    // Up to half the shorter name's letters (at least one, at most two) may differ: `nu` is not a
    // misspelt `E`.
    for (const auto& [given, node] : table_) {
      const std::size_t shorter = std::min(given.str().size(), key.size());
      const std::size_t allowed = std::clamp<std::size_t>(shorter / 2, 1, 2);
      if (!known_.count(std::string(given.str())) && edit_distance(given.str(), key) <= allowed) {
        fail(key_path(given.str()), line_of(node),
             "unknown key (did you mean '" + std::string(key) + "'?)");
      }
    }
    fail(key_path(key), line_, "required key is missing (expected " + std::string(expected) + ")");
  }

  // A quantity: a string with a unit; a plain number only where there is no unit to forget (a
  // dimensionless key) or none is needed (0). `thickness = 20` is 20 what? (docs/scene.md,
  // "General rules").
  double quantity_of(const toml::node& node, const std::string& where, Dimension d) const {
    if (const auto* s = node.as_string()) {
      try {
        return parse_quantity(s->get(), d);
      } catch (const InputError& e) {
        fail(where, line_of(node), e.what());
      }
    }
    if (node.is_number()) {
      const double v = node.value<double>().value_or(NAN);
      if (!std::isfinite(v)) fail(where, line_of(node), "not a finite number");
      if (d != Dimension::Dimensionless && v != 0.0)
        fail(where, line_of(node),
             "a number needs its unit here: " + expectation(d) + " (" + unit_names(d) + ")");
      return v;
    }
    fail(where, line_of(node), "expected " + expectation(d));
  }

  std::optional<double> optional_quantity(std::string_view key, Dimension d) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    return quantity_of(*node, key_path(key), d);
  }

  double required_quantity(std::string_view key, Dimension d) {
    const auto v = optional_quantity(key, d);
    if (!v) fail_missing(key, expectation(d));
    return *v;
  }

  double required_positive(std::string_view key, Dimension d) {
    const double v = required_quantity(key, d);
    require_positive(key, v, d);
    return v;
  }

  std::optional<double> optional_positive(std::string_view key, Dimension d) {
    const auto v = optional_quantity(key, d);
    if (v) require_positive(key, *v, d);
    return v;
  }

  void require_positive(std::string_view key, double v, Dimension d) {
    if (!(v > 0.0)) fail_key(key, "must be positive, got " + format_quantity(v, d));
  }

  // A whole number in [lo, hi] (a count: dimensionless, so no unit).
  std::optional<int> optional_count(std::string_view key, int lo, int hi) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    const auto* integer = node->as_integer();
    if (!integer) fail(key_path(key), line_of(*node), "expected a whole number");
    const std::int64_t v = integer->get();
    if (v < lo || v > hi)
      fail(key_path(key), line_of(*node),
           "must be " + std::to_string(lo) + " to " + std::to_string(hi) + ", got " +
               std::to_string(v));
    return static_cast<int>(v);
  }

  std::optional<std::string> optional_string(std::string_view key) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    const auto* s = node->as_string();
    if (!s) fail(key_path(key), line_of(*node), "expected a string in quotes");
    if (s->get().empty()) fail(key_path(key), line_of(*node), "must not be empty");
    return s->get();
  }

  std::string required_string(std::string_view key, std::string_view example) {
    auto s = optional_string(key);
    if (!s) fail_missing(key, "a string such as " + std::string(example));
    return *s;
  }

  template <class E>
  std::optional<E> optional_choice(std::string_view key,
                                   std::initializer_list<std::pair<std::string_view, E>> options) {
    const auto s = optional_string(key);
    if (!s) return std::nullopt;
    return choose(key_path(key), line_of(*get(key)), *s, options);
  }

  template <class E>
  E choose(const std::string& where, int line, const std::string& text,
           std::initializer_list<std::pair<std::string_view, E>> options) const {
    std::string names;
    for (const auto& [name, value] : options) {
      if (name == text) return value;
      names += (names.empty() ? "" : ", ") + std::string(name);
    }
    fail(where, line, "unknown value '" + text + "'; expected one of: " + names);
  }

  // A sub-table, inline `{ ... }` or `[a.b]`; nullopt when absent.
  std::optional<Table> optional_table(std::string_view key) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    const auto* t = node->as_table();
    if (!t) fail(key_path(key), line_of(*node), "expected a table");
    return Table(*t, key_path(key), file_, line_of(*node) > 0 ? line_of(*node) : line_);
  }

  Table required_table(std::string_view key, std::string_view expected) {
    auto t = optional_table(key);
    if (!t) fail_missing(key, expected);
    return std::move(*t);
  }

  // An array of tables (`[[key]]`); empty when absent.
  std::vector<Table> table_array(std::string_view key) {
    std::vector<Table> out;
    const toml::node* node = get(key);
    if (!node) return out;
    const auto* array = node->as_array();
    if (!array)
      fail(key_path(key), line_of(*node), "expected an array of tables [[" + key_path(key) + "]]");
    for (std::size_t i = 0; i < array->size(); ++i) {
      const auto* t = (*array)[i].as_table();
      if (!t) fail(indexed(key_path(key), i), line_of((*array)[i]), "expected a table");
      out.emplace_back(*t, indexed(key_path(key), i), file_, line_of((*array)[i]));
    }
    return out;
  }

  // A fixed-length array of quantities, e.g. size = ["3000 um", "3000 um", "1150 um"].
  template <std::size_t N>
  std::optional<std::array<double, N>> optional_quantities(std::string_view key, Dimension d) {
    const toml::node* node = get(key);
    if (!node) return std::nullopt;
    const auto* array = node->as_array();
    if (!array || array->size() != N) {
      fail(key_path(key), line_of(*node),
           "expected an array of " + std::to_string(N) + " " + std::string(dimension_name(d)) +
               "s such as [" + example_list(N, d) + "]");
    }
    std::array<double, N> out{};
    for (std::size_t i = 0; i < N; ++i) {
      out[i] = quantity_of((*array)[i], indexed(key_path(key), i), d);
    }
    return out;
  }

  // Every key of the table, marked as known: for tables whose keys are free (plugin parameters).
  std::vector<std::pair<std::string, const toml::node*>> take_all() {
    std::vector<std::pair<std::string, const toml::node*>> out;
    for (const auto& [key, node] : table_) {
      known_.emplace(key.str());
      out.emplace_back(std::string(key.str()), &node);
    }
    return out;
  }

  void finish() const {
    for (const auto& [key, node] : table_) {
      if (known_.count(std::string(key.str()))) continue;
      std::string problem = "unknown key";
      std::string best;
      std::size_t best_distance = 3;
      for (const auto& k : known_) {
        const std::size_t d = edit_distance(key.str(), k);
        if (d < best_distance) best_distance = d, best = k;
      }
      if (!best.empty()) problem += " (did you mean '" + best + "'?)";
      std::string list;
      for (const auto& k : known_) list += (list.empty() ? "" : ", ") + k;
      problem += list.empty() ? "; this table takes no keys" : "; expected one of: " + list;
      fail(key_path(key.str()), line_of(node), problem);
    }
  }

  static std::string expectation(Dimension d) {
    switch (d) {
      case Dimension::Dimensionless:
        return "a plain number";
      case Dimension::Length:
        return "a length such as \"230 um\"";
      case Dimension::Angle:
        return "an angle such as \"30 deg\"";
      case Dimension::Pressure:
        return "a pressure such as \"0.2 MPa\"";
      case Dimension::Force:
        return "a force such as \"0.1 N\"";
      case Dimension::Speed:
        return "a speed such as \"1 mm/s\"";
      case Dimension::Toughness:
        return "a toughness such as \"19 J/m^2\"";
      default:
        return "a " + std::string(dimension_name(d)) + " with its unit";
    }
  }

 private:
  static std::string example_list(std::size_t n, Dimension d) {
    std::string one = d == Dimension::Length ? "\"1 mm\"" : "\"1 " + std::string(si_unit(d)) + "\"";
    std::string out;
    for (std::size_t i = 0; i < n; ++i) out += (i ? ", " : "") + one;
    return out;
  }

  const toml::table& table_;
  std::string path_;
  const std::string& file_;
  int line_ = 1;
  std::set<std::string> known_;
};

// ---- tissue ---------------------------------------------------------------------------------

double read_poisson_ratio(Table& t, std::string_view key) {
  const double nu = t.required_quantity(key, Dimension::Dimensionless);
  if (std::fabs(nu - 0.5) < 1e-12) {
    t.fail_key(key, "0.5 means incompressible, which is not supported; use 0.49");
  }
  if (!(nu > -1.0 && nu < 0.5)) {
    std::ostringstream s;
    s << "Poisson's ratio must lie in (-1, 0.5), got " << nu;
    t.fail_key(key, s.str());
  }
  return nu;
}

// A tissue's Young's modulus, from gels (tens of Pa) to dry stratum corneum (GPa), with room on
// either side; beyond it the stiffness matrix loses its digits (1e300 Pa overflowed at the first
// step, 5e-324 Pa was singular) and the run failed late, naming no key.
constexpr double kSmallestModulus = 1.0;  // Pa
constexpr double kLargestModulus = 1e12;  // Pa
constexpr double kLargestFrictionCoefficient = 10.0;

void check_modulus(Table& t, std::string_view key, double e, std::string_view what) {
  if (!(e >= kSmallestModulus && e <= kLargestModulus)) {
    t.fail_key(key, std::string(what) + " " + format_quantity(e, Dimension::Pressure) +
                        " is outside the tissues' range, 1 Pa to 1e12 Pa");
  }
}

void reject_keys(Table& t, std::initializer_list<std::string_view> keys, std::string_view why) {
  for (const auto key : keys) {
    if (t.get(key)) t.fail_key(key, std::string(key) + " " + std::string(why));
  }
}

// Mooney–Rivlin: C10, C01 and either nu or the bulk modulus K; E is derived, not given.
void read_mooney_rivlin(Table& t, TissueMaterial& m) {
  reject_keys(t, {"E"},
              "is derived from C10 and C01 for mooney_rivlin (E = 4 (C10 + C01)(1 + nu))");
  m.c10 = t.required_quantity("C10", Dimension::Pressure);
  m.c01 = t.required_quantity("C01", Dimension::Pressure);
  // As the material model requires (each term's energy must not be negative): `scene check`
  // accepted C10 = -30 kPa with C01 = 30.000001 kPa, which `simulate` then refused.
  if (!(m.c10 >= 0.0)) t.fail_key("C10", "must not be negative");
  if (!(m.c01 >= 0.0)) t.fail_key("C01", "must not be negative");
  const double mu = 2.0 * (m.c10 + m.c01);
  if (!(mu > 0.0)) t.fail_key("C10", "C10 + C01 must be positive (it is half the shear modulus)");
  const bool has_nu = t.get("nu") != nullptr;
  const bool has_k = t.get("K") != nullptr;
  if (has_nu == has_k) {
    t.fail(t.path(), t.line(),
           "mooney_rivlin needs exactly one of nu (Poisson's ratio) or K (bulk modulus)");
  }
  if (has_nu) {
    m.poisson_ratio = read_poisson_ratio(t, "nu");
  } else {
    const double k = t.required_positive("K", Dimension::Pressure);
    m.poisson_ratio = (3.0 * k - 2.0 * mu) / (2.0 * (3.0 * k + mu));
    // K far above the shear modulus makes nu 0.5 to the last digit (incompressible), far below
    // it nu -1: named here, not as a Poisson's ratio of the [loads] model later.
    if (!(m.poisson_ratio > -1.0 && m.poisson_ratio < 0.5)) {
      std::ostringstream why;
      why << "gives Poisson's ratio " << m.poisson_ratio
          << " with C10 + C01, outside (-1, 0.5): K must be finite, positive and not so far above "
             "the shear modulus that nu is 0.5 to double precision";
      t.fail_key("K", why.str());
    }
  }
  m.youngs_modulus = 2.0 * mu * (1.0 + m.poisson_ratio);
  check_modulus(t, "C10", m.youngs_modulus, "the Young's modulus 4 (C10 + C01)(1 + nu) =");
}

TissueMaterial read_tissue_material(Table t) {
  TissueMaterial m;
  m.model = [&] {
    const auto model =
        t.optional_choice<MaterialModel>("model", {{"linear", MaterialModel::Linear},
                                                   {"svk", MaterialModel::StVenantKirchhoff},
                                                   {"neo_hookean", MaterialModel::NeoHookean},
                                                   {"mooney_rivlin", MaterialModel::MooneyRivlin}});
    if (!model) t.fail_missing("model", "one of linear, svk, neo_hookean, mooney_rivlin");
    return *model;
  }();
  if (m.model == MaterialModel::MooneyRivlin) {
    read_mooney_rivlin(t, m);
  } else {
    reject_keys(t, {"C10", "C01", "K"}, "applies only to model = \"mooney_rivlin\"");
    m.youngs_modulus = t.required_positive("E", Dimension::Pressure);
    check_modulus(t, "E", m.youngs_modulus, "E =");
    m.poisson_ratio = read_poisson_ratio(t, "nu");
  }
  t.finish();
  return m;
}

std::optional<Fracture> read_fracture(Table& parent) {
  auto t = parent.optional_table("fracture");
  if (!t) return std::nullopt;
  Fracture f;
  f.toughness = t->required_positive("toughness", Dimension::Toughness);
  f.critical_pressure = t->required_positive("critical_pressure", Dimension::Pressure);
  f.cohesive_strength = t->optional_positive("cohesive_strength", Dimension::Pressure);
  if (const auto ratio = t->optional_quantity("cohesive_peak_ratio", Dimension::Dimensionless)) {
    if (!f.cohesive_strength)
      t->fail_key("cohesive_peak_ratio", "shapes the cohesive law: give cohesive_strength too");
    // Below 1e-4 the initial stiffness sigma_c / delta_y swamps the tissue's (the puncture
    // drifted by 10 % at 1e-7, the stiffness lost its definiteness at 1e-20); above 0.9 the
    // process zone needs ten times the cells (docs/model.md, "The cohesive criterion").
    if (!(*ratio >= 1e-4 && *ratio <= 0.9))
      t->fail_key("cohesive_peak_ratio", "delta_y / delta_0 must lie in [1e-4, 0.9], got " +
                                             format_quantity(*ratio, Dimension::Dimensionless));
    f.cohesive_peak_ratio = *ratio;
  }
  t->finish();
  return f;
}

std::optional<LayerStrength> read_layer_strength(Table& t) {
  const auto strength = t.optional_positive("strength", Dimension::Pressure);
  const auto length = t.optional_positive("strength_length", Dimension::Length);
  if (strength.has_value() != length.has_value()) {
    t.fail_key(strength ? "strength" : "strength_length",
               "strength and strength_length go together (the stress criterion averages the "
               "stress over strength_length)");
  }
  if (!strength) return std::nullopt;
  return LayerStrength{*strength, *length};
}

struct LayerDraft {
  TissueLayer layer;
  bool has_thickness = false;
};

LayerDraft read_layer(Table t, bool is_last) {
  LayerDraft d;
  d.layer.line = t.line();
  d.layer.name = t.required_string("name", "\"dermis\"");
  const auto thickness = t.optional_positive("thickness", Dimension::Length);
  if (!thickness && !is_last) {
    t.fail_missing("thickness", "a length such as \"100 um\"; only the last layer may omit it");
  }
  d.has_thickness = thickness.has_value();
  d.layer.thickness = thickness.value_or(0.0);
  d.layer.material = read_tissue_material(t.required_table(
      "material", "a table such as { model = \"linear\", E = \"0.08 MPa\", nu = 0.4 }"));
  d.layer.fracture = read_fracture(t);
  d.layer.fracture_is_own = d.layer.fracture.has_value();
  d.layer.strength = read_layer_strength(t);
  d.layer.pressure_scale = t.optional_positive("pressure_scale", Dimension::Pressure);
  if (const auto source = t.optional_string("pressure_scale_source")) {
    if (!d.layer.pressure_scale) {
      t.fail_key("pressure_scale_source", "given without pressure_scale");
    }
    d.layer.pressure_scale_source = *source;
  }
  if (d.layer.pressure_scale && d.layer.pressure_scale_source.empty()) {
    t.fail_missing("pressure_scale_source",
                   "where pressure_scale comes from, such as \"fitted by mneedle calibrate to "
                   "curve.csv\"");
  }
  t.finish();
  return d;
}

// Stacks the layers from the surface down; the last may omit its thickness and fill the rest.
void stack_layers(Table& tissue_table, std::vector<LayerDraft>& drafts, double depth) {
  const std::string where = tissue_table.key_path("layers");
  double top = 0.0;
  for (std::size_t i = 0; i + 1 < drafts.size(); ++i) {
    drafts[i].layer.top = top;
    top += drafts[i].layer.thickness;
  }
  LayerDraft& last = drafts.back();
  last.layer.top = top;
  const double slack = kRelativeSlack * depth;
  const double given_total = top + last.layer.thickness;
  if (!last.has_thickness) {
    if (depth - top <= slack) {
      tissue_table.fail(indexed(where, drafts.size() - 1), last.layer.line,
                        "the layers above already fill " + format_quantity(top, Dimension::Length) +
                            " of the " + format_quantity(depth, Dimension::Length) +
                            " block, leaving nothing for this layer");
    }
  } else if (given_total > depth + slack) {
    tissue_table.fail(where, drafts.front().layer.line,
                      "the layers add up to " + format_quantity(given_total, Dimension::Length) +
                          ", more than the block depth tissue.size[2] = " +
                          format_quantity(depth, Dimension::Length));
  } else if (given_total < depth - slack) {
    tissue_table.fail(indexed(where, drafts.size() - 1), last.layer.line,
                      "the layers add up to " + format_quantity(given_total, Dimension::Length) +
                          " but the block is " + format_quantity(depth, Dimension::Length) +
                          " deep; leave out the last layer's thickness to let it fill the rest");
  }
  last.layer.thickness = depth - top;  // exact closure, also when the sum was within slack
}

Tissue read_tissue(Table t) {
  Tissue tissue;
  const auto size = t.optional_quantities<3>("size", Dimension::Length);
  if (!size) t.fail_missing("size", "[x, y, depth] lengths such as [\"3 mm\", \"3 mm\", \"1 mm\"]");
  tissue.size = *size;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!(tissue.size[i] > 0.0)) {
      t.fail(indexed(t.key_path("size"), i), line_of(*t.get("size")),
             "must be positive, got " + format_quantity(tissue.size[i], Dimension::Length));
    }
  }
  tissue.boundary = t.optional_choice<Boundary>("boundary", {{"fixed", Boundary::Fixed}})
                        .value_or(Boundary::Fixed);
  tissue.fracture = read_fracture(t);

  auto layer_tables = t.table_array("layers");
  if (layer_tables.empty()) {
    t.fail(t.key_path("layers"), t.line(), "at least one [[tissue.layers]] is required");
  }
  std::vector<LayerDraft> drafts;
  for (std::size_t i = 0; i < layer_tables.size(); ++i) {
    drafts.push_back(read_layer(std::move(layer_tables[i]), i + 1 == layer_tables.size()));
  }
  for (std::size_t i = 0; i < drafts.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (drafts[i].layer.name == drafts[j].layer.name) {
        t.fail(indexed(t.key_path("layers"), i) + ".name", drafts[i].layer.line,
               "duplicate layer name '" + drafts[i].layer.name + "' (also tissue.layers[" +
                   std::to_string(j) + "])");
      }
    }
  }
  stack_layers(t, drafts, tissue.depth());
  // The stress criterion averages over a ball of this radius around points of the layer: one as
  // large as the block averages the whole block (1 m read as no puncture, without a word).
  const double smallest = std::min({tissue.size[0], tissue.size[1], tissue.size[2]});
  for (std::size_t i = 0; i < drafts.size(); ++i) {
    const auto& strength = drafts[i].layer.strength;
    if (strength && !(strength->length < 0.5 * smallest)) {
      t.fail(indexed(t.key_path("layers"), i) + ".strength_length", drafts[i].layer.line,
             format_quantity(strength->length, Dimension::Length) +
                 " must be below half the block's smallest side (" +
                 format_quantity(smallest, Dimension::Length) +
                 "): the stress is averaged over a ball of this radius");
    }
  }
  for (auto& d : drafts) {
    if (!d.layer.fracture) d.layer.fracture = tissue.fracture;
    tissue.layers.push_back(std::move(d.layer));
  }
  t.finish();
  return tissue;
}

// ---- needles --------------------------------------------------------------------------------

struct NeedleDraft {
  NeedleSpec spec;
  bool named = false;
  std::string auto_name;
  std::optional<double> length;    // m, the plugin parameter `length` when given
  std::optional<double> diameter;  // m, the plugin parameter `diameter` when given
};

Quantity plugin_parameter(const Table& g, const std::string& where, const toml::node& node) {
  if (const auto* s = node.as_string()) {
    try {
      return parse_quantity(s->get());
    } catch (const InputError& e) {
      g.fail(where, line_of(node), e.what());
    }
  }
  if (node.is_number()) {
    const double v = node.value<double>().value_or(NAN);
    if (!std::isfinite(v)) g.fail(where, line_of(node), "not a finite number");
    return {v, Dimension::Dimensionless};
  }
  g.fail(where, line_of(node), "expected a quantity such as \"230 um\" or a plain number");
}

// The scene needs `length` (depth check) and `diameter` (footprint check) of a plugin needle.
std::optional<double> plugin_length(Table& g, const PluginGeometry& p, std::string_view key) {
  const auto it = p.parameters.find(std::string(key));
  if (it == p.parameters.end()) return std::nullopt;
  double v = 0.0;
  try {
    v = quantity_in(it->second, Dimension::Length, "the value");
  } catch (const InputError& e) {
    g.fail_key(key, e.what());
  }
  g.require_positive(key, v, Dimension::Length);
  return v;
}

PluginGeometry read_plugin_geometry(Table& g, NeedleDraft& draft) {
  PluginGeometry p;
  for (const auto& [key, node] : g.take_all()) {
    if (key == "plugin") {
      const auto* s = node->as_string();
      if (!s || s->get().empty()) {
        g.fail(g.key_path(key), line_of(*node), "expected a plugin name such as \"sharp_bevel\"");
      }
      p.plugin = s->get();
    } else if (key == "stl" || key == "unit" || key == "axis") {
      g.fail(g.key_path(key), line_of(*node),
             "applies to stl geometry only; a geometry has either plugin or stl");
    } else {
      p.parameters[key] = plugin_parameter(g, g.key_path(key), *node);
    }
  }
  draft.length = plugin_length(g, p, "length");
  draft.diameter = plugin_length(g, p, "diameter");
  draft.auto_name = p.plugin;
  return p;
}

StlGeometry read_stl_geometry(Table& g, NeedleDraft& draft, const std::filesystem::path& base) {
  StlGeometry stl;
  const std::filesystem::path given = *g.optional_string("stl");
  stl.path = given.is_relative() ? (base / given).lexically_normal() : given;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(stl.path, ec)) {
    g.fail_key("stl", "no such file: " + stl.path.string() + " (relative paths start at the " +
                          "scene file's folder)");
  }
  // An empty file has no unit to declare: say what it is, not that the unit is missing.
  if (std::filesystem::file_size(stl.path, ec) == 0 && !ec)
    g.fail_key("stl", stl.path.string() + ": empty file");
  // No unit and none in the file: a guess (CAD tools write mm, others um or m) is refused.
  const auto declared = declared_length_unit(stl.path);
  const auto given_unit = g.optional_string("unit");
  if (!given_unit && !declared)
    g.fail_key("unit", "missing: " + stl.path.filename().string() +
                           " does not say its length unit; add unit = \"mm\" (what CAD tools "
                           "export), \"um\" or \"m\"");
  stl.unit = given_unit.value_or(declared.value_or("mm"));
  try {
    stl.unit_scale = length_unit_scale(stl.unit);
  } catch (const InputError& e) {
    g.fail_key("unit", e.what());
  }
  // axis = "auto" | "x" | "y" | "z" | [a, b, c] (the tip direction); docs/scene.md.
  if (const toml::node* axis = g.get("axis")) {
    if (const auto* text = axis->as_string()) {
      stl.axis = text->get();
    } else if (const auto* list = axis->as_array(); list && list->size() == 3) {
      std::ostringstream joined;
      joined.precision(17);
      for (std::size_t k = 0; k < 3; ++k) {
        const auto value = (*list)[k].value<double>();
        if (!value) g.fail_key("axis", "expected three numbers, e.g. [0, -1, 0]");
        joined << (k ? "," : "") << *value;
      }
      stl.axis = joined.str();
    } else {
      g.fail_key("axis", "expected \"auto\", \"x\", \"y\", \"z\" or a tip direction [a, b, c]");
    }
    try {
      parse_axis_choice(stl.axis);
    } catch (const InputError& e) {
      g.fail_key("axis", e.what());
    }
  }
  g.finish();
  draft.auto_name = given.stem().string();
  return stl;
}

void check_inside_block(Table& n, const NeedleDraft& d, const Tissue& tissue) {
  const double radius = d.diameter.value_or(0.0) / 2.0;
  for (std::size_t i = 0; i < 2; ++i) {
    const double half = tissue.size[i] / 2.0;
    const double reach = std::fabs(d.spec.at[i]) + radius;
    const bool inside = radius > 0.0 ? reach <= half * (1.0 + kRelativeSlack) : reach < half;
    if (!inside) {
      n.fail_key("at", std::string(i == 0 ? "x" : "y") + " = " +
                           format_quantity(d.spec.at[i], Dimension::Length) +
                           (radius > 0.0 ? " with needle radius " +
                                               format_quantity(radius, Dimension::Length)
                                         : std::string()) +
                           " is not inside the block top, which spans +-" +
                           format_quantity(half, Dimension::Length) + " around the origin");
    }
  }
}

NeedleDraft read_needle(Table n, const Tissue& tissue, const std::filesystem::path& base) {
  NeedleDraft d;
  d.spec.line = n.line();
  auto g = n.required_table(
      "geometry", "{ plugin = \"sharp_bevel\", ... } or { stl = \"needle.stl\", unit = \"um\" }");
  const bool has_plugin = g.get("plugin") != nullptr;
  const bool has_stl = g.get("stl") != nullptr;
  if (has_plugin && has_stl) g.fail_key("stl", "a geometry has either plugin or stl, not both");
  if (!has_plugin && !has_stl) g.fail_missing("plugin", "plugin = \"name\" or stl = \"file\"");
  if (has_plugin) {
    d.spec.geometry = read_plugin_geometry(g, d);
  } else {
    d.spec.geometry = read_stl_geometry(g, d, base);
  }
  if (const auto name = n.optional_string("name")) {
    d.spec.name = *name;
    d.named = true;
  }
  d.spec.at = n.optional_quantities<2>("at", Dimension::Length).value_or(std::array{0.0, 0.0});
  check_inside_block(n, d, tissue);
  d.spec.material = n.optional_string("material");
  n.finish();
  return d;
}

// Explicit names must be unique; a missing name becomes the plugin name or STL stem, suffixed
// _2, _3, ... until it is unique.
void name_needles(Table& root, std::vector<NeedleDraft>& drafts) {
  std::set<std::string> taken;
  for (std::size_t i = 0; i < drafts.size(); ++i) {
    if (!drafts[i].named) continue;
    if (!taken.insert(drafts[i].spec.name).second) {
      root.fail(indexed("needles", i) + ".name", drafts[i].spec.line,
                "duplicate needle name '" + drafts[i].spec.name + "'");
    }
  }
  for (auto& d : drafts) {
    if (d.named) continue;
    std::string name = d.auto_name;
    for (int k = 2; taken.count(name); ++k) name = d.auto_name + "_" + std::to_string(k);
    taken.insert(name);
    d.spec.name = name;
  }
}

// ---- insertion, model, loads, requirements, materials ---------------------------------------

Insertion read_insertion(Table t, const Tissue& tissue, const std::vector<NeedleDraft>& needles) {
  Insertion ins;
  ins.depth = t.required_positive("depth", Dimension::Length);
  if (ins.depth >= tissue.depth()) {
    t.fail_key("depth", format_quantity(ins.depth, Dimension::Length) +
                            " reaches the bottom of the block (tissue.size[2] = " +
                            format_quantity(tissue.depth(), Dimension::Length) +
                            "); the tip must stay inside the tissue");
  }
  for (std::size_t i = 0; i < needles.size(); ++i) {
    const auto& length = needles[i].length;
    if (length && ins.depth >= *length) {
      t.fail_key("depth", format_quantity(ins.depth, Dimension::Length) +
                              " reaches the length of needle '" + needles[i].spec.name + "' (" +
                              format_quantity(*length, Dimension::Length) + ", needles[" +
                              std::to_string(i) + "].geometry.length): its base would enter " +
                              "the tissue");
    }
  }
  ins.speed = t.optional_positive("speed", Dimension::Speed).value_or(ins.speed);
  ins.angle = t.optional_quantity("angle", Dimension::Angle).value_or(ins.angle);
  if (std::fabs(ins.angle - std::numbers::pi / 2.0) > 1e-9) {
    t.fail_key("angle", format_quantity(ins.angle, Dimension::Angle) +
                            ": oblique insertion is not modelled yet; use \"90 deg\" " +
                            "(perpendicular; plain numbers are radians)");
  }
  t.finish();
  return ins;
}

std::vector<Output> read_outputs(Table& t) {
  const toml::node* node = t.get("outputs");
  const auto* array = node ? node->as_array() : nullptr;
  if (!array || array->empty()) {
    t.fail_key("outputs",
               "expected a non-empty array of strings from: puncture, force_curve, "
               "fields");
  }
  std::vector<Output> outputs;
  for (std::size_t i = 0; i < array->size(); ++i) {
    const std::string where = indexed(t.key_path("outputs"), i);
    const toml::node& item = (*array)[i];
    const auto* s = item.as_string();
    if (!s) t.fail(where, line_of(item), "expected a string");
    const Output o = t.choose<Output>(where, line_of(item), s->get(),
                                      {{"puncture", Output::Puncture},
                                       {"force_curve", Output::ForceCurve},
                                       {"fields", Output::Fields}});
    if (std::find(outputs.begin(), outputs.end(), o) != outputs.end()) {
      t.fail(where, line_of(item), "'" + s->get() + "' is listed twice");
    }
    outputs.push_back(o);
  }
  return outputs;
}

// A criterion named in the scene must find what it needs on the surface layer.
void check_criterion_inputs(Table& t, PunctureCriterion c, const Tissue& tissue) {
  const TissueLayer& top = tissue.layers.front();
  const std::string layer = "the top layer tissue.layers[0] ('" + top.name + "')";
  if (c == PunctureCriterion::Stress && !top.strength) {
    t.fail_key("criterion", "\"stress\" needs strength and strength_length on " + layer);
  }
  if (c != PunctureCriterion::Stress && !top.fracture) {
    t.fail_key("criterion", "\"" + std::string(to_string(c)) + "\" needs fracture data on " +
                                layer + " or in [tissue.fracture]");
  }
  if (c == PunctureCriterion::Cohesive && !top.fracture->cohesive_strength) {
    // A layer's own fracture table replaces [tissue.fracture] whole: name the one that counts.
    t.fail_key("criterion", top.fracture_is_own
                                ? "\"cohesive\" needs cohesive_strength in the fracture table of " +
                                      layer + " (its own table replaces [tissue.fracture])"
                                : "\"cohesive\" needs fracture.cohesive_strength on " + layer +
                                      " or in [tissue.fracture]");
  }
}

ModelOptions read_model(std::optional<Table> t, const Tissue& tissue) {
  ModelOptions m;
  if (!t) return m;
  m.fidelity = t->optional_choice<Fidelity>("fidelity", {{"fast", Fidelity::Fast},
                                                         {"standard", Fidelity::Standard},
                                                         {"fine", Fidelity::Fine}})
                   .value_or(m.fidelity);
  if (t->get("outputs")) m.outputs = read_outputs(*t);
  const auto criterion = t->optional_choice<PunctureCriterion>(
      "criterion", {{"pressure", PunctureCriterion::Pressure},
                    {"energy", PunctureCriterion::Energy},
                    {"stress", PunctureCriterion::Stress},
                    {"penetration", PunctureCriterion::Penetration},
                    {"cohesive", PunctureCriterion::Cohesive}});
  if (criterion) {
    check_criterion_inputs(*t, *criterion, tissue);
    m.criterion = *criterion;
  }
  m.contact = t->optional_choice<Contact>("contact", {{"sticking", Contact::Sticking},
                                                      {"frictionless", Contact::Frictionless}})
                  .value_or(m.contact);
  m.crack_faces = t->optional_choice<CrackFaces>("crack_faces", {{"contact", CrackFaces::Contact},
                                                                 {"free", CrackFaces::Free}})
                      .value_or(m.crack_faces);
  m.mesh_refinement = t->optional_count("mesh_refinement", 0, kMaxMeshRefinement);
  // "none" turns off every zone the levels would take (0 inside): speed for accuracy.
  const toml::node* zone = t->get("contact_zone");
  const auto* word = zone ? zone->as_string() : nullptr;
  if (word && word->get() == "none")
    m.contact_zone = 0.0;
  else if (word && word->get().find_first_of("0123456789") == std::string::npos)
    t->fail_key("contact_zone",
                "expected a length such as \"6 um\", or \"none\"; got \"" + word->get() + "\"");
  else
    m.contact_zone = t->optional_positive("contact_zone", Dimension::Length);
  m.contact_zone_tip = t->optional_positive("contact_zone_tip", Dimension::Length);
  if (m.contact_zone_tip && !(m.contact_zone && *m.contact_zone > 0.0))
    t->fail_key("contact_zone_tip",
                "grades the contact zone: give contact_zone too (a size, not \"none\")");
  if (m.contact_zone_tip && m.contact_zone && *m.contact_zone_tip > *m.contact_zone)
    t->fail_key("contact_zone_tip", "must not exceed contact_zone");
  if (m.contact_zone && *m.contact_zone > 0.0 && m.mesh_refinement == 0)
    t->fail_key("contact_zone", "is bisected out of a refined grid: needs mesh_refinement >= 1");
  t->finish();
  return m;
}

Loads read_loads(std::optional<Table> t) {
  Loads l;
  if (!t) return l;
  l.mode = t->optional_choice<LoadMode>("mode", {{"distributed", LoadMode::Distributed},
                                                 {"paper_a_fig17", LoadMode::PaperAFig17}})
               .value_or(l.mode);
  l.scale = t->optional_positive("scale", Dimension::Dimensionless).value_or(l.scale);
  l.stiffness = t->optional_positive("stiffness", Dimension::Pressure);
  l.beta_length = t->optional_positive("beta_length", Dimension::Length);
  l.specimen_diameter = t->optional_positive("specimen_diameter", Dimension::Length);
  l.specimen_height = t->optional_positive("specimen_height", Dimension::Length);
  if (l.mode == LoadMode::PaperAFig17) {
    for (const auto* key : {"stiffness", "beta_length"}) {
      if (t->get(key)) {
        t->fail_key(key, "paper_a_fig17 sets it (K = E D / (4 H), beta_length = 1 um)");
      }
    }
    if (!l.specimen_diameter) {
      t->fail_missing("specimen_diameter", "the phantom's diameter, paper A: \"44.107 mm\"");
    }
    if (!l.specimen_height) {
      t->fail_missing("specimen_height", "the phantom's height, paper A: \"21.145 mm\"");
    }
  } else {
    for (const auto* key : {"specimen_diameter", "specimen_height"}) {
      if (t->get(key)) t->fail_key(key, "applies only to mode = \"paper_a_fig17\"");
    }
  }
  l.friction =
      t->optional_choice<FrictionLaw>("friction", {{"coulomb", FrictionLaw::Coulomb},
                                                   {"linear_growth", FrictionLaw::LinearGrowth},
                                                   {"none", FrictionLaw::None}})
          .value_or(l.friction);
  if (const auto mu = t->optional_quantity("friction_coefficient", Dimension::Dimensionless)) {
    if (l.friction != FrictionLaw::Coulomb) {
      t->fail_key("friction_coefficient", "applies only to friction = \"coulomb\"");
    }
    if (*mu < 0.0) t->fail_key("friction_coefficient", "must not be negative");
    // Measured needle-tissue coefficients lie below 1; 10 leaves room and keeps the friction
    // force finite (1e300 overflowed the force curve to +Inf, naming an output, not this key).
    if (*mu > kLargestFrictionCoefficient) {
      std::ostringstream why;
      why << "must be at most 10 (measured needle-tissue values are below 1), got " << *mu;
      t->fail_key("friction_coefficient", why.str());
    }
    l.friction_coefficient = *mu;
  }
  const auto max_force = t->optional_positive("friction_max_force", Dimension::Force);
  const auto saturation = t->optional_positive("friction_saturation_depth", Dimension::Length);
  if (l.friction == FrictionLaw::LinearGrowth) {
    if (!max_force) t->fail_missing("friction_max_force", "a force such as \"0.9 N\" (F_max)");
    if (!saturation) {
      t->fail_missing("friction_saturation_depth", "a length such as \"1 mm\" (d, paper C eq. 2)");
    }
    l.friction_max_force = *max_force;
    l.friction_saturation_depth = *saturation;
  } else {
    for (const auto* key : {"friction_max_force", "friction_saturation_depth"}) {
      if (t->get(key)) t->fail_key(key, "applies only to friction = \"linear_growth\"");
    }
  }
  t->finish();
  return l;
}

Requirements read_requirements(std::optional<Table> t, const Insertion& insertion) {
  Requirements r;
  if (!t) return r;
  r.target_depth = t->optional_positive("target_depth", Dimension::Length);
  if (r.target_depth && *r.target_depth > insertion.depth) {
    t->fail_key("target_depth", format_quantity(*r.target_depth, Dimension::Length) +
                                    " is deeper than insertion.depth (" +
                                    format_quantity(insertion.depth, Dimension::Length) +
                                    "), so it could never be shown to be reached");
  }
  r.safety_factor =
      t->optional_quantity("safety_factor", Dimension::Dimensionless).value_or(r.safety_factor);
  if (!(r.safety_factor >= 1.0)) t->fail_key("safety_factor", "must be at least 1");
  t->finish();
  return r;
}

UserMaterial read_user_material(Table t) {
  UserMaterial m;
  m.line = t.line();
  m.name = t.required_string("name", "\"my_polymer\"");
  m.youngs_modulus = t.required_positive("E", Dimension::Pressure);
  m.poisson_ratio = read_poisson_ratio(t, "nu");
  m.strength = t.required_positive("strength", Dimension::Pressure);
  m.density = t.optional_positive("density", Dimension::Density);
  t.finish();
  return m;
}

std::vector<UserMaterial> read_materials(Table& root) {
  std::vector<UserMaterial> out;
  for (auto& table : root.table_array("materials")) {
    UserMaterial m = read_user_material(std::move(table));
    for (const auto& other : out) {
      if (other.name == m.name) {
        root.fail(indexed("materials", out.size()) + ".name", m.line,
                  "duplicate material name '" + m.name + "'");
      }
    }
    out.push_back(std::move(m));
  }
  return out;
}

toml::table parse_toml(std::string_view text, const std::string& source_name) {
  try {
    return toml::parse(text, std::string_view(source_name));
  } catch (const toml::parse_error& e) {
    const auto& at = e.source().begin;
    throw InputError(source_name + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
}

}  // namespace

Scene parse_scene(std::string_view text, std::string source_name) {
  const std::string file = source_name;
  const toml::table document = parse_toml(text, file);
  Table root(document, "", file, 1);
  for (const auto* key :
       {"tissue", "needles", "insertion", "model", "loads", "requirements", "materials"}) {
    root.get(key);
  }
  root.finish();

  Scene scene;
  scene.source_name = std::move(source_name);
  scene.tissue = read_tissue(root.required_table("tissue", "a [tissue] table"));
  const std::filesystem::path base = std::filesystem::path(file).parent_path();
  std::vector<NeedleDraft> needles;
  for (auto& table : root.table_array("needles")) {
    needles.push_back(read_needle(std::move(table), scene.tissue, base));
  }
  if (needles.empty()) {
    root.fail("needles", 1, "a scene needs at least one [[needles]] entry");
  }
  name_needles(root, needles);
  scene.insertion = read_insertion(
      root.required_table("insertion", "an [insertion] table with depth"), scene.tissue, needles);
  for (auto& d : needles) scene.needles.push_back(std::move(d.spec));
  scene.model = read_model(root.optional_table("model"), scene.tissue);
  scene.loads = read_loads(root.optional_table("loads"));
  if (scene.loads.mode == LoadMode::PaperAFig17) {
    for (std::size_t i = 0; i < scene.tissue.layers.size(); ++i) {
      if (scene.tissue.layers[i].pressure_scale) {
        root.fail("tissue.layers[" + std::to_string(i) + "].pressure_scale",
                  scene.tissue.layers[i].line,
                  "not with [loads] mode = \"paper_a_fig17\", which takes q = S E D / (4 H)");
      }
    }
  }
  scene.requirements = read_requirements(root.optional_table("requirements"), scene.insertion);
  scene.materials = read_materials(root);
  return scene;
}

Scene load_scene(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open scene file");
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) throw InputError(file.string() + ": cannot read scene file");
  return parse_scene(content.str(), file.string());
}

std::size_t layer_index_at_depth(const Tissue& tissue, double depth) {
  for (std::size_t i = 0; i + 1 < tissue.layers.size(); ++i) {
    if (depth < tissue.layers[i].top + tissue.layers[i].thickness) return i;
  }
  return tissue.layers.empty() ? 0 : tissue.layers.size() - 1;
}

bool ModelOptions::wants(Output o) const {
  return std::find(outputs.begin(), outputs.end(), o) != outputs.end();
}

std::string_view to_string(Boundary) {
  return "fixed";
}

std::string_view to_string(Fidelity f) {
  switch (f) {
    case Fidelity::Fast:
      return "fast";
    case Fidelity::Standard:
      return "standard";
    case Fidelity::Fine:
      return "fine";
  }
  return "?";
}

std::string_view to_string(Output o) {
  switch (o) {
    case Output::Puncture:
      return "puncture";
    case Output::ForceCurve:
      return "force_curve";
    case Output::Fields:
      return "fields";
  }
  return "?";
}

std::string_view to_string(PunctureCriterion c) {
  switch (c) {
    case PunctureCriterion::Pressure:
      return "pressure";
    case PunctureCriterion::Energy:
      return "energy";
    case PunctureCriterion::Stress:
      return "stress";
    case PunctureCriterion::Penetration:
      return "penetration";
    case PunctureCriterion::Cohesive:
      return "cohesive";
  }
  return "?";
}

std::string_view to_string(CrackFaces c) {
  switch (c) {
    case CrackFaces::Contact:
      return "contact";
    case CrackFaces::Free:
      return "free";
  }
  return "?";
}

std::string_view to_string(Contact c) {
  switch (c) {
    case Contact::Sticking:
      return "sticking";
    case Contact::Frictionless:
      return "frictionless";
  }
  return "?";
}

std::string_view to_string(FrictionLaw f) {
  switch (f) {
    case FrictionLaw::Coulomb:
      return "coulomb";
    case FrictionLaw::LinearGrowth:
      return "linear_growth";
    case FrictionLaw::None:
      return "none";
  }
  return "?";
}

}  // namespace mneedle
