#include "mneedle/insertion/surface_loads.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
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
  require(c.stiffness_Pa || !c.layers.empty(),
          "stiffness not given and no tissue layers to derive it from");
  for (std::size_t i = 0; i < c.layers.size(); ++i) {
    const LoadLayer& layer = c.layers[i];
    const std::string where = "layer " + std::to_string(i + 1) + ": ";
    require(layer.youngs_modulus_Pa > 0.0 && std::isfinite(layer.youngs_modulus_Pa),
            where + "Young's modulus must be positive");
    require(layer.poisson_ratio > -1.0 && layer.poisson_ratio < 0.5,
            where + "Poisson ratio must lie in (-1, 0.5)");
    require(i + 1 == c.layers.size() || layer.thickness_m > 0.0,
            where + "thickness must be positive");
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
  c.scale = scene.loads.scale;
  c.stiffness_Pa = scene.loads.stiffness;
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
  for (const TissueLayer& layer : scene.tissue.layers) {
    c.layers.push_back(
        {layer.thickness, layer.material.youngs_modulus, layer.material.poisson_ratio});
  }
  return c;
}

double layer_stiffness(const LoadLayer& layer) {
  return layer.youngs_modulus_Pa / (1.0 - layer.poisson_ratio * layer.poisson_ratio);
}

double pentahedron_load(const std::array<Vec3, 3>& triangle,
                        const std::array<double, 3>& vertex_loads_Pa) {
  using namespace vec3;
  const Vec3 twice_area_normal =
      cross(sub(triangle[1], triangle[0]), sub(triangle[2], triangle[0]));
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
  if (constants_.stiffness_Pa) {
    layer_bottom_m_ = {kInfinity};
    layer_k_Pa_ = {*constants_.stiffness_Pa};
  } else {
    double bottom = 0.0;
    for (std::size_t i = 0; i < constants_.layers.size(); ++i) {
      const bool last = i + 1 == constants_.layers.size();
      bottom = last ? kInfinity : bottom + constants_.layers[i].thickness_m;
      layer_bottom_m_.push_back(bottom);
      layer_k_Pa_.push_back(layer_stiffness(constants_.layers[i]));
    }
  }
}

void SurfaceLoadModel::add_piece(const Face& face, const std::vector<Vertex>& polygon, double k_Pa,
                                 LoadSample& sample) const {
  const double pressure = k_Pa * constants_.scale;
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    const Vertex& a = polygon[0];
    const Vertex& b = polygon[i];
    const Vertex& c = polygon[i + 1];
    const double area = std::abs(signed_area(a, b, c));
    switch (face.group) {
      case SurfaceGroup::alpha:
        sample.alpha_N += pressure * area;  // eq. 18
        break;
      case SurfaceGroup::beta: {
        // Vertex load: K S times the lateral opening h tan(theta), per reference radius.
        const double per_height = pressure * face.tan_theta / reference_radius_m_;
        const double resultant =
            pentahedron_load({Vec3{a.u, a.v, 0.0}, Vec3{b.u, b.v, 0.0}, Vec3{c.u, c.v, 0.0}},
                             {per_height * a.height, per_height * b.height, per_height * c.height});
        sample.beta_N += resultant * face.along;
        break;
      }
      case SurfaceGroup::side:
        if (constants_.friction == ShaftFriction::coulomb && !face.in_bore) {
          sample.friction_N += constants_.friction_coefficient * pressure * area;
        }
        break;
      case SurfaceGroup::back:
        break;
    }
  }
}

void SurfaceLoadModel::add_face(const Face& face, double depth_m, LoadSample& sample) const {
  double layer_top = 0.0;
  for (std::size_t j = 0; j < layer_bottom_m_.size(); ++j) {
    // Layer j covers heights above the tip in [depth - bottom, depth - top].
    const double high = depth_m - layer_top;
    const double low = depth_m - layer_bottom_m_[j];
    layer_top = layer_bottom_m_[j];
    if (face.lowest >= high || face.highest <= low) continue;
    const std::vector<Vertex> polygon = clip_to_slab(face, low, high);
    if (polygon.size() >= 3) add_piece(face, polygon, layer_k_Pa_[j], sample);
  }
}

LoadSample SurfaceLoadModel::at(double depth_m) const {
  require(!std::isnan(depth_m), "depth is not a number");
  LoadSample sample;
  sample.depth_m = depth_m;
  if (depth_m > 0.0) {
    for (const Face& face : faces_) {
      if (face.lowest < depth_m) add_face(face, depth_m, sample);
    }
    if (constants_.friction == ShaftFriction::linear_growth) {
      // Paper C eq. 2: F_f = F_max x / d up to full penetration, F_max after.
      const double ratio = std::min(depth_m / *constants_.friction_saturation_depth_m, 1.0);
      sample.friction_N = *constants_.friction_max_force_N * ratio;
    }
  }
  sample.force_N = sample.alpha_N + sample.beta_N + sample.friction_N;
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
