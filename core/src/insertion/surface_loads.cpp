#include "mneedle/insertion/surface_loads.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/scene/scene.h"
#include "needle/vec3_ops.h"

namespace mneedle {
namespace {

using Vertex = SurfaceLoadModel::Vertex;
using Face = SurfaceLoadModel::Face;
constexpr double kInfinity = std::numeric_limits<double>::infinity();

void require(bool ok, const std::string& problem) {
  if (!ok) throw InputError("[loads] " + problem);
}

void check_constants(const LoadConstants& c) {
  require(c.scale > 0.0 && std::isfinite(c.scale), "scale must be a positive number");
  require(!c.stiffness_Pa || (*c.stiffness_Pa > 0.0 && std::isfinite(*c.stiffness_Pa)),
          "stiffness must be a positive pressure");
  require(c.friction_coefficient >= 0.0 && std::isfinite(c.friction_coefficient),
          "friction_coefficient must be a non-negative number");
  if (c.friction == ShaftFriction::linear_growth) {
    require(c.friction_max_force_N && *c.friction_max_force_N >= 0.0 &&
                std::isfinite(*c.friction_max_force_N),
            "friction = linear_growth needs friction_max_force >= 0");
    require(c.friction_saturation_depth_m && *c.friction_saturation_depth_m > 0.0 &&
                std::isfinite(*c.friction_saturation_depth_m),
            "friction = linear_growth needs friction_saturation_depth > 0");
  }
  require(!c.beta_length_m || (*c.beta_length_m > 0.0 && std::isfinite(*c.beta_length_m)),
          "beta_length must be a positive length");
  if (c.mode == LoadModelMode::paper_a_fig17) {
    require(!c.stiffness_Pa && !c.beta_length_m,
            "mode paper_a_fig17 sets K and beta_length itself; give neither");
    for (const auto& [value, name] : {std::pair{c.specimen_diameter_m, "specimen_diameter"},
                                      std::pair{c.specimen_height_m, "specimen_height"}}) {
      require(value && *value > 0.0 && std::isfinite(*value),
              std::string("mode paper_a_fig17 needs a positive ") + name);
    }
    require(!c.layers.empty(), "mode paper_a_fig17 needs the tissue layers (their E)");
  }
  require(c.stiffness_Pa || !c.layers.empty(),
          "stiffness not given and no tissue layers to derive it from");
  require(!c.tissue_depth_m || (*c.tissue_depth_m > 0.0 && !std::isnan(*c.tissue_depth_m)),
          "the tissue depth must be positive");
  for (std::size_t i = 0; i < c.layers.size(); ++i) {
    const LoadLayer& layer = c.layers[i];
    const std::string where = "layer " + std::to_string(i + 1) + ": ";
    require(layer.youngs_modulus_Pa > 0.0 && std::isfinite(layer.youngs_modulus_Pa),
            where + "Young's modulus must be positive");
    require(layer.poisson_ratio > -1.0 && layer.poisson_ratio < 0.5,
            where + "Poisson ratio must lie in (-1, 0.5)");
    require(i + 1 == c.layers.size() || layer.thickness_m > 0.0,
            where + "thickness must be positive");
    require(!layer.pressure_scale_Pa ||
                (*layer.pressure_scale_Pa > 0.0 && std::isfinite(*layer.pressure_scale_Pa)),
            where + "pressure_scale must be a positive pressure");
    require(!layer.pressure_scale_Pa || !layer.pressure_scale_source.empty(),
            where + "pressure_scale needs its source");
    require(!layer.tensile_strength_Pa ||
                (*layer.tensile_strength_Pa > 0.0 && !std::isnan(*layer.tensile_strength_Pa)),
            where + "strength must be a positive pressure");
  }
}

double signed_area(const Vertex& a, const Vertex& b, const Vertex& c) {
  return 0.5 * ((b.u - a.u) * (c.v - a.v) - (c.u - a.u) * (b.v - a.v));
}

Vertex interpolate(const Vertex& a, const Vertex& b, double height) {
  const double t = (height - a.height) / (b.height - a.height);
  return {a.u + t * (b.u - a.u), a.v + t * (b.v - a.v), height};
}

// Sutherland-Hodgman against one half-plane of the height: keep (height - level) * side <= 0.
std::vector<Vertex> clip_height(const std::vector<Vertex>& polygon, double level, double side) {
  std::vector<Vertex> out;
  for (std::size_t i = 0, n = polygon.size(); i < n; ++i) {
    const Vertex& a = polygon[i];
    const Vertex& b = polygon[(i + 1) % n];
    const bool a_in = (a.height - level) * side <= 0.0;
    const bool b_in = (b.height - level) * side <= 0.0;
    if (a_in) out.push_back(a);
    if (a_in != b_in) out.push_back(interpolate(a, b, level));
  }
  return out;
}

std::vector<Vertex> clip_to_slab(const Face& face, double low, double high) {
  std::vector<Vertex> polygon(face.vertex.begin(), face.vertex.end());
  if (face.highest > high) polygon = clip_height(polygon, high, +1.0);
  if (face.lowest < low && polygon.size() >= 3) polygon = clip_height(polygon, low, -1.0);
  return polygon;
}

double tetrahedron_volume(const Vec3& p1, const Vec3& p2, const Vec3& p3, const Vec3& p4) {
  using namespace vec3;
  return std::abs(dot(sub(p1, p4), cross(sub(p2, p4), sub(p3, p4)))) / 6.0;  // eq. 19
}

// Eq. 20 for paper A's three cases (Fig. 9), unloaded vertices first.
double pentahedron_volume(const std::array<Vec3, 3>& base, const std::array<Vec3, 3>& top,
                          long unloaded) {
  switch (unloaded) {
    case 2:  // Fig. 9(B): a single tetrahedron
      return tetrahedron_volume(base[0], base[1], base[2], top[2]);
    case 1:  // Fig. 9(A): a pyramid on the quadrilateral base[1] base[2] top[2] top[1]
      return tetrahedron_volume(base[0], base[1], base[2], top[2]) +
             tetrahedron_volume(base[0], base[1], top[2], top[1]);
    default:  // Fig. 9(C): the full truncated prism, three tetrahedra
      return tetrahedron_volume(base[0], base[1], base[2], top[0]) +
             tetrahedron_volume(base[1], base[2], top[0], top[1]) +
             tetrahedron_volume(base[2], top[0], top[1], top[2]);
  }
}

Face make_face(const std::array<Vec3, 3>& p, const Vec3& d, double tip_s,
               const GroupTolerances& tolerances) {
  using namespace vec3;
  const Vec3 normal = normalized(cross(sub(p[1], p[0]), sub(p[2], p[0])));
  const Vec3 e1 = normalized(sub(p[1], p[0]));
  const Vec3 e2 = cross(normal, e1);
  Face face{};
  face.group = classify_normal(normal, d, tolerances);
  face.along = dot(normal, d);
  const double across = norm(cross(normal, d));
  face.tan_theta = across > 0.0 ? face.along / across : 0.0;
  face.lowest = kInfinity;
  face.highest = -kInfinity;
  for (int k = 0; k < 3; ++k) {
    const Vec3 r = sub(p[k], p[0]);
    face.vertex[k] = {dot(r, e1), dot(r, e2), -dot(p[k], d) - tip_s};
    face.lowest = std::min(face.lowest, face.vertex[k].height);
    face.highest = std::max(face.highest, face.vertex[k].height);
  }
  return face;
}

struct SideFace {
  Vec3 centroid;
  Vec3 normal;
  double area;
  std::size_t index;
};

SideFace side_face(const std::array<Vec3, 3>& p, double area, std::size_t index) {
  using namespace vec3;
  const Vec3 centroid = scale(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
  return {centroid, normalized(cross(sub(p[1], p[0]), sub(p[2], p[0]))), area, index};
}

// The shaft's axis passes through the area centroid of its side faces; a side face whose
// outward normal points toward that axis is the wall of a bore, which the tissue outside the
// needle never touches (no coring is modelled).
void mark_bore_walls(const std::vector<SideFace>& sides, const Vec3& d, std::vector<Face>& faces) {
  using namespace vec3;
  Vec3 axis_point{0.0, 0.0, 0.0};
  double total = 0.0;
  for (const SideFace& s : sides) {
    axis_point = add(axis_point, scale(s.centroid, s.area));
    total += s.area;
  }
  if (!(total > 0.0)) return;
  axis_point = scale(axis_point, 1.0 / total);
  for (const SideFace& s : sides) {
    const Vec3 offset = sub(s.centroid, axis_point);
    const Vec3 radial = sub(offset, scale(d, dot(offset, d)));
    faces[s.index].in_bore = dot(s.normal, radial) < 0.0;
  }
}

}  // namespace

LoadConstants load_constants(const Scene& scene) {
  LoadConstants c;
  c.mode = scene.loads.mode == LoadMode::PaperAFig17 ? LoadModelMode::paper_a_fig17
                                                     : LoadModelMode::distributed;
  c.scale = scene.loads.scale;
  c.stiffness_Pa = scene.loads.stiffness;
  c.beta_length_m = scene.loads.beta_length;
  c.specimen_diameter_m = scene.loads.specimen_diameter;
  c.specimen_height_m = scene.loads.specimen_height;
  c.friction_coefficient = scene.loads.friction_coefficient;
  switch (scene.loads.friction) {
    case FrictionLaw::Coulomb:
      c.friction = ShaftFriction::coulomb;
      break;
    case FrictionLaw::LinearGrowth:
      c.friction = ShaftFriction::linear_growth;
      c.friction_max_force_N = scene.loads.friction_max_force;
      c.friction_saturation_depth_m = scene.loads.friction_saturation_depth;
      break;
    case FrictionLaw::None:
      c.friction = ShaftFriction::none;
      break;
  }
  c.tissue_depth_m = scene.tissue.depth();
  for (const TissueLayer& layer : scene.tissue.layers) {
    LoadLayer l{layer.thickness,      layer.material.youngs_modulus, layer.material.poisson_ratio,
                layer.pressure_scale, layer.pressure_scale_source,   std::nullopt,
                std::nullopt};
    if (layer.strength) l.tensile_strength_Pa = layer.strength->strength;
    if (layer.fracture) l.critical_pressure_Pa = layer.fracture->critical_pressure;
    c.layers.push_back(l);
  }
  return c;
}

double layer_stiffness(const LoadLayer& layer) {
  return layer.youngs_modulus_Pa / (1.0 - layer.poisson_ratio * layer.poisson_ratio);
}

std::vector<LayerPressure> layer_pressures(const LoadConstants& c) {
  check_constants(c);
  std::ostringstream scale_text;
  scale_text << "S = " << c.scale;
  const std::string s = scale_text.str();
  std::vector<LayerPressure> out;
  if (c.layers.empty()) {
    out.push_back(
        {*c.stiffness_Pa * c.scale, kInfinity, kInfinity, "[loads] stiffness K times " + s});
    return out;
  }
  for (const LoadLayer& layer : c.layers) {
    LayerPressure p;
    p.wall_pressure_cap_Pa = kInfinity;
    p.cutting_pressure_cap_Pa = kInfinity;
    if (c.mode == LoadModelMode::paper_a_fig17) {
      // Paper A's "tissue toughness" K of Fig. 17 is E D / (4 H) of its phantom (docs/model.md).
      p.pressure_scale_Pa =
          c.scale * layer.youngs_modulus_Pa * *c.specimen_diameter_m / (4.0 * *c.specimen_height_m);
      p.source = "paper A Fig. 17: S E D / (4 H), " + s;
      out.push_back(p);
      continue;
    }
    if (layer.pressure_scale_Pa) {
      p.pressure_scale_Pa = *layer.pressure_scale_Pa;
      p.source = layer.pressure_scale_source;
    } else if (c.stiffness_Pa) {
      p.pressure_scale_Pa = *c.stiffness_Pa * c.scale;
      p.source = "[loads] stiffness K times " + s;
    } else {
      p.pressure_scale_Pa = layer_stiffness(layer) * c.scale;
      p.source = "derived: S E / (1 - nu^2), " + s + " (not fitted to this tissue)";
    }
    if (layer.tensile_strength_Pa) p.wall_pressure_cap_Pa = *layer.tensile_strength_Pa;
    if (layer.critical_pressure_Pa) p.cutting_pressure_cap_Pa = *layer.critical_pressure_Pa;
    out.push_back(p);
  }
  return out;
}

double pentahedron_load(const std::array<Vec3, 3>& triangle,
                        const std::array<double, 3>& vertex_loads_Pa) {
  using namespace vec3;
  const Vec3 twice_area_normal =
      cross(sub(triangle[1], triangle[0]), sub(triangle[2], triangle[0]));
  // A piece without area (a sliver clipped at an interface that rounding put a few 1e-20 m
  // from the tip) carries nothing; its normal would be 0/0.
  if (!(norm(twice_area_normal) > 0.0)) return 0.0;
  const Vec3 normal = normalized(twice_area_normal);
  const double peak = *std::max_element(vertex_loads_Pa.begin(), vertex_loads_Pa.end());
  if (!(peak > 0.0)) return 0.0;
  // Loads (Pa, ~1e4) drawn as lengths beside coordinates (m, ~1e-4) would leave the triple
  // products of eq. 19 to cancellation; draw them at the triangle's own size and scale back
  // (the volume is linear in the height scale).
  const double length_per_Pa = std::sqrt(0.5 * norm(twice_area_normal)) / peak;
  // Unloaded vertices ("on the tip") first, so each of paper A's three cases (Fig. 9) is a
  // prefix of the general decomposition of the prism P1 P2 P3 / T1 T2 T3.
  std::array<int, 3> order{0, 1, 2};
  std::stable_partition(order.begin(), order.end(),
                        [&](int k) { return vertex_loads_Pa[k] == 0.0; });
  std::array<Vec3, 3> base;
  std::array<Vec3, 3> top;
  for (int k = 0; k < 3; ++k) {
    base[k] = triangle[order[k]];
    top[k] = add(base[k], scale(normal, vertex_loads_Pa[order[k]] * length_per_Pa));
  }
  return pentahedron_volume(base, top,
                            std::count(vertex_loads_Pa.begin(), vertex_loads_Pa.end(), 0.0)) /
         length_per_Pa;
}

SurfaceLoadModel::SurfaceLoadModel(const TriangleMesh& mesh, const LoadConstants& constants,
                                   const Vec3& direction, const GroupTolerances& tolerances)
    : constants_(constants) {
  check_constants(constants);
  const double length = vec3::norm(direction);
  require(length > 0.0 && std::isfinite(length), "insertion direction must be non-zero");
  const Vec3 d = vec3::scale(direction, 1.0 / length);
  double tip_s = kInfinity;
  for (const Vec3& p : mesh.vertices) tip_s = std::min(tip_s, -vec3::dot(p, d));
  faces_.reserve(mesh.triangles.size());
  std::vector<SideFace> sides;
  for (const Triangle& t : mesh.triangles) {
    const std::array<Vec3, 3> p{mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]};
    Face face = make_face(p, d, tip_s, tolerances);
    const double area = std::abs(signed_area(face.vertex[0], face.vertex[1], face.vertex[2]));
    if (!(area > 0.0)) continue;  // degenerate: no normal, no load
    if (face.group == SurfaceGroup::alpha || face.group == SurfaceGroup::beta) {
      frontal_area_m2_ += area * face.along;
    }
    if (face.group == SurfaceGroup::side) sides.push_back(side_face(p, area, faces_.size()));
    faces_.push_back(face);
  }
  mark_bore_walls(sides, d, faces_);
  require(frontal_area_m2_ > 0.0, "the needle mesh has no face looking along the insertion axis");
  reference_radius_m_ = std::sqrt(frontal_area_m2_ / std::numbers::pi);
  beta_length_m_ = constants_.mode == LoadModelMode::paper_a_fig17
                       ? kPaperAFig17BetaLength_m
                       : constants_.beta_length_m.value_or(reference_radius_m_);
  layers_ = layer_pressures(constants_);
  const double floor = constants_.tissue_depth_m.value_or(kInfinity);
  if (constants_.layers.empty()) {
    layer_bottom_m_ = {floor};
  } else {
    double bottom = 0.0;
    for (std::size_t i = 0; i < constants_.layers.size(); ++i) {
      const bool last = i + 1 == constants_.layers.size();
      bottom = last ? floor : std::min(floor, bottom + constants_.layers[i].thickness_m);
      layer_bottom_m_.push_back(bottom);
    }
  }
}

// The beta load of one face piece: f = q h tan(theta) / l, rising from the tip, capped at the
// layer's wall-pressure cap. The cap is reached at one height on a planar face (f is linear in
// h there), so clipping at that height keeps the resultant exact: linear below, uniform above.
void SurfaceLoadModel::add_beta(const Face& face, const std::vector<Vertex>& polygon,
                                const LayerPressure& layer, LoadSample& sample) const {
  const double per_height = layer.pressure_scale_Pa * face.tan_theta / beta_length_m_;
  const double cap = layer.wall_pressure_cap_Pa;
  const double cap_height = per_height > 0.0 ? cap / per_height : kInfinity;
  std::vector<Vertex> below = polygon;
  std::vector<Vertex> above;
  double highest = -kInfinity;
  for (const Vertex& v : polygon) highest = std::max(highest, v.height);
  if (highest > cap_height) {
    below = clip_height(polygon, cap_height, +1.0);
    above = clip_height(polygon, cap_height, -1.0);
  }
  for (std::size_t i = 1; i + 1 < below.size(); ++i) {
    const Vertex& a = below[0];
    const Vertex& b = below[i];
    const Vertex& c = below[i + 1];
    const double resultant =
        pentahedron_load({Vec3{a.u, a.v, 0.0}, Vec3{b.u, b.v, 0.0}, Vec3{c.u, c.v, 0.0}},
                         {per_height * a.height, per_height * b.height, per_height * c.height});
    sample.beta_N += resultant * face.along;
  }
  for (std::size_t i = 1; i + 1 < above.size(); ++i) {
    sample.beta_N += cap * std::abs(signed_area(above[0], above[i], above[i + 1])) * face.along;
  }
}

void SurfaceLoadModel::add_piece(const Face& face, const std::vector<Vertex>& polygon,
                                 const LayerPressure& layer, LoadSample& sample) const {
  if (face.group == SurfaceGroup::beta) {
    add_beta(face, polygon, layer, sample);
    return;
  }
  // The shaft is pressed by the opened hole's wall: q, unless the layer splits first.
  const double wall = std::min(layer.pressure_scale_Pa, layer.wall_pressure_cap_Pa);
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    const double area = std::abs(signed_area(polygon[0], polygon[i], polygon[i + 1]));
    if (face.group == SurfaceGroup::alpha) {
      // Eq. 18, with the tissue ahead cutting at its critical pressure (docs/model.md).
      sample.alpha_N += std::min(layer.pressure_scale_Pa, layer.cutting_pressure_cap_Pa) * area;
    } else if (face.group == SurfaceGroup::side && !face.in_bore &&
               constants_.friction == ShaftFriction::coulomb) {
      sample.friction_N += constants_.friction_coefficient * wall * area;
    }
  }
}

void SurfaceLoadModel::add_face(const Face& face, double depth_m, LoadSample& sample,
                                std::vector<LoadSample>* by_layer) const {
  double layer_top = 0.0;
  for (std::size_t j = 0; j < layer_bottom_m_.size(); ++j) {
    // Layer j covers heights above the tip in [depth - bottom, depth - top].
    const double high = depth_m - layer_top;
    const double low = depth_m - layer_bottom_m_[j];
    layer_top = layer_bottom_m_[j];
    // A face across the axis (no height extent) lies in one layer: the deeper one when it sits
    // on an interface (docs/model.md, "Pressure scale"); any other face overlaps a slab or not at
    // all.
    const bool across = face.highest == face.lowest;
    if (across ? !(face.lowest > low && face.lowest <= high)
               : (face.lowest >= high || face.highest <= low))
      continue;
    const std::vector<Vertex> polygon = clip_to_slab(face, low, high);
    if (polygon.size() < 3) continue;
    if (by_layer == nullptr) {
      add_piece(face, polygon, layers_[j], sample);
      continue;
    }
    LoadSample piece;
    add_piece(face, polygon, layers_[j], piece);
    for (LoadSample* s : {&sample, &(*by_layer)[j]}) {
      s->alpha_N += piece.alpha_N;
      s->beta_N += piece.beta_N;
      s->friction_N += piece.friction_N;
    }
  }
}

LoadSample SurfaceLoadModel::at(double depth_m) const {
  return at(depth_m, nullptr);
}

LoadSample SurfaceLoadModel::at(double depth_m, std::vector<LoadSample>* by_layer) const {
  require(!std::isnan(depth_m), "depth is not a number");
  LoadSample sample;
  sample.depth_m = depth_m;
  if (by_layer != nullptr) by_layer->assign(layer_bottom_m_.size(), LoadSample{depth_m});
  if (depth_m > 0.0) {
    for (const Face& face : faces_) {
      if (face.lowest < depth_m) add_face(face, depth_m, sample, by_layer);
    }
    if (constants_.friction == ShaftFriction::linear_growth) {
      // Paper C eq. 2: F_f = F_max x / d up to full penetration, F_max after.
      const double ratio = std::min(depth_m / *constants_.friction_saturation_depth_m, 1.0);
      sample.friction_N = *constants_.friction_max_force_N * ratio;
    }
  }
  sample.force_N = sample.alpha_N + sample.beta_N + sample.friction_N;
  if (by_layer != nullptr)
    for (LoadSample& layer : *by_layer)
      layer.force_N = layer.alpha_N + layer.beta_N + layer.friction_N;
  return sample;
}

std::vector<LoadSample> SurfaceLoadModel::curve(const std::vector<double>& depths_m) const {
  std::vector<LoadSample> samples;
  samples.reserve(depths_m.size());
  for (double depth : depths_m) samples.push_back(at(depth));
  return samples;
}

LoadSample surface_load(const TriangleMesh& mesh, const LoadConstants& constants, double depth_m,
                        const Vec3& direction) {
  return SurfaceLoadModel(mesh, constants, direction).at(depth_m);
}

}  // namespace mneedle
