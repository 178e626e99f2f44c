#include "mneedle/fe/stress_probe.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/fe/material.h"
#include "mneedle/fe/parallel.h"

namespace mneedle::fe {

namespace {

constexpr int kEdgeNodes[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
// Sub-tetrahedra cut by the averaging sphere are split into eight until they are this many
// levels deep (4096 pieces per element at most); the cut's volume error then falls as 8^-level.
constexpr int kMaxLevel = 4;

using Barycentric = Eigen::Vector4d;

// dN/dX at barycentric point `l` (TET4 or TET10, VTK node order) for an element whose reference
// geometry is affine (midside nodes at edge midpoints, as the tissue mesh makes them).
Eigen::MatrixXd shape_gradients(int node_count, const Barycentric& l,
                                const Eigen::Matrix3d& inverse_jacobian) {
  Eigen::MatrixXd by_barycentric = Eigen::MatrixXd::Zero(node_count, 4);
  if (node_count == 4) {
    by_barycentric.setIdentity();
  } else {
    for (int i = 0; i < 4; ++i) by_barycentric(i, i) = 4.0 * l(i) - 1.0;
    for (int e = 0; e < 6; ++e) {
      const int a = kEdgeNodes[e][0], b = kEdgeNodes[e][1];
      by_barycentric(4 + e, a) = 4.0 * l(b);
      by_barycentric(4 + e, b) = 4.0 * l(a);
    }
  }
  Eigen::Matrix<double, 4, 3> chain;
  chain << -1, -1, -1, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  return by_barycentric * chain * inverse_jacobian;
}

// One element of the layer: its corner geometry, displacement and material.
struct ElementField {
  std::array<Eigen::Vector3d, 4> corners;
  Eigen::Matrix3d inverse_jacobian;
  Eigen::MatrixXd displacement;  // node_count x 3
  const Material* material = nullptr;
  bool linear_kinematics = true;

  Eigen::Vector3d position(const Barycentric& l) const {
    return l(0) * corners[0] + l(1) * corners[1] + l(2) * corners[2] + l(3) * corners[3];
  }

  // The Cauchy stress; the linear law's stress is already Cauchy.
  Eigen::Matrix3d cauchy(const Barycentric& l) const {
    const Eigen::MatrixXd g =
        shape_gradients(static_cast<int>(displacement.rows()), l, inverse_jacobian);
    const Eigen::Matrix3d F = Eigen::Matrix3d::Identity() + displacement.transpose() * g;
    if (!linear_kinematics && !(F.determinant() > 0.0))
      throw SolverError("stress probe: inverted element (det F <= 0)");
    const Eigen::Matrix3d S = material->evaluate(F).S;
    return linear_kinematics ? S : Eigen::Matrix3d(F * S * F.transpose() / F.determinant());
  }

  // Largest eigenvalue of the Cauchy stress.
  double max_principal(const Barycentric& l) const {
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cauchy(l), Eigen::EigenvaluesOnly)
        .eigenvalues()
        .maxCoeff();
  }
};

struct Accumulator {
  double stress_volume = 0.0;  // Pa m^3
  double volume = 0.0;         // m^3
};

// An element's corners, their centroid and the farthest corner's distance from it: the cheap
// bound by which an element is left out of a ball before any per-element work.
struct Bounds {
  std::array<Eigen::Vector3d, 4> corners;
  Eigen::Vector3d mid;
  double reach = 0.0;
};

Bounds element_bounds(const TetMesh& mesh, std::size_t e) {
  Bounds b;
  for (int i = 0; i < 4; ++i)
    b.corners[static_cast<std::size_t>(i)] =
        mesh.nodes[static_cast<std::size_t>(mesh.elements[e][static_cast<std::size_t>(i)])];
  b.mid = 0.25 * (b.corners[0] + b.corners[1] + b.corners[2] + b.corners[3]);
  for (const auto& q : b.corners) b.reach = std::max(b.reach, (q - b.mid).norm());
  return b;
}

double tet_volume(const std::array<Eigen::Vector3d, 4>& p) {
  return std::abs((p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0]))) / 6.0;
}

// The eight children of the eight-way split (every edge halved; equal volumes), of corners given
// in any affine coordinates.
std::array<std::array<Barycentric, 4>, 8> split_in_eight(const std::array<Barycentric, 4>& t) {
  const auto m = [&](int a, int b) { return Barycentric(0.5 * (t[a] + t[b])); };
  const Barycentric m01 = m(0, 1), m02 = m(0, 2), m03 = m(0, 3), m12 = m(1, 2), m13 = m(1, 3),
                    m23 = m(2, 3);
  return {{{t[0], m01, m02, m03},
           {m01, t[1], m12, m13},
           {m02, m12, t[2], m23},
           {m03, m13, m23, t[3]},
           {m01, m02, m03, m13},
           {m01, m02, m12, m13},
           {m02, m03, m13, m23},
           {m02, m12, m13, m23}}};
}

// Integrates over a sub-tetrahedron (four barycentric corners) of the element: whole when it is
// inside the sphere, skipped when outside, split in eight when cut. The stress of a TET10 is
// linear in the element, so a 4-point rule per piece, and 1 point for a TET4, is enough.
void integrate(const ElementField& field, const std::array<Barycentric, 4>& sub,
               const Eigen::Vector3d& centre, double radius, int level, Accumulator* sum) {
  std::array<Eigen::Vector3d, 4> p;
  for (int i = 0; i < 4; ++i) p[static_cast<std::size_t>(i)] = field.position(sub[i]);
  const Eigen::Vector3d mid = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  double reach = 0.0, farthest = 0.0;
  for (const auto& q : p) {
    reach = std::max(reach, (q - mid).norm());
    farthest = std::max(farthest, (q - centre).norm());
  }
  const double distance = (mid - centre).norm();
  if (distance - reach > radius) return;
  const double volume = tet_volume(p);
  const bool inside = farthest <= radius;
  if (!inside && level < kMaxLevel) {
    for (const auto& child : split_in_eight(sub))
      integrate(field, child, centre, radius, level + 1, sum);
    return;
  }
  const Barycentric centroid = 0.25 * (sub[0] + sub[1] + sub[2] + sub[3]);
  if (!inside && (field.position(centroid) - centre).norm() > radius) return;
  if (field.displacement.rows() == 4) {
    sum->stress_volume += volume * field.max_principal(centroid);
  } else {
    const double a = 0.5854101966249685, b = 0.1381966011250105;
    for (int i = 0; i < 4; ++i) {
      Barycentric weights = Barycentric::Constant(b);
      weights(i) = a;
      Barycentric l = Barycentric::Zero();
      for (int j = 0; j < 4; ++j) l += weights(j) * sub[static_cast<std::size_t>(j)];
      sum->stress_volume += 0.25 * volume * field.max_principal(l);
    }
  }
  sum->volume += volume;
}

// Material of `layer` as the solid model evaluates it: small strain only when every layer is
// linear, and a linear layer in a nonlinear model is its St Venant-Kirchhoff extension.
Material layer_material(const TetMesh& mesh, int layer, bool* all_linear) {
  *all_linear = true;
  for (const TissueLayer& l : mesh.layers)
    *all_linear = *all_linear && l.material.model == MaterialModel::Linear;
  MaterialParameters parameters = mesh.layers[static_cast<std::size_t>(layer)].material;
  if (!*all_linear && parameters.model == MaterialModel::Linear)
    parameters.model = MaterialModel::StVenantKirchhoff;
  return Material(parameters);
}

// The element's field (corners, inverse Jacobian, displacement) at `u`.
ElementField element_field(const TetMesh& mesh, const Eigen::VectorXd& u, std::size_t e,
                           const Material& material, bool linear_kinematics) {
  const auto& element = mesh.elements[e];
  ElementField field;
  for (int i = 0; i < 4; ++i)
    field.corners[static_cast<std::size_t>(i)] = mesh.nodes[static_cast<std::size_t>(element[i])];
  Eigen::Matrix3d jacobian;
  for (int i = 0; i < 3; ++i) jacobian.col(i) = field.corners[i + 1] - field.corners[0];
  field.inverse_jacobian = jacobian.inverse();  // dX/dL_i = X_i - X_0 for L1..L3
  const int n = mesh.nodes_per_element();
  field.displacement.resize(n, 3);
  for (int a = 0; a < n; ++a)
    field.displacement.row(a) =
        u.segment<3>(3 * static_cast<Eigen::Index>(element[static_cast<std::size_t>(a)]))
            .transpose();
  field.material = &material;
  field.linear_kinematics = linear_kinematics;
  return field;
}

// An element's corners (local indices) in an order that its mirror images across x = 0 and
// y = 0 share: by depth, then |x|, then |y| (then x, y for corners that tie, which lie on
// opposite sides of a plane no element of a mirrored model straddles). The eight-way split's
// inner diagonal, hence where a ball's edge cuts the pieces, follows the corner order, so in the
// mesh's own order a half model's balls and the whole block's were cut differently and read
// 0.05-0.3 % apart (docs/model.md, "Tip stress and cracked meshes").
std::array<int, 4> canonical_corners(const TetMesh& mesh, std::size_t e) {
  std::array<int, 4> order = {0, 1, 2, 3};
  const auto& element = mesh.elements[e];
  const auto key = [&](int a) {
    const Eigen::Vector3d& p =
        mesh.nodes[static_cast<std::size_t>(element[static_cast<std::size_t>(a)])];
    return std::array<double, 5>{p.z(), std::abs(p.x()), std::abs(p.y()), p.x(), p.y()};
  };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return key(a) < key(b); });
  return order;
}

// The 8^levels equal sub-tetrahedra of the reference element in barycentric corners (the
// eight-way split halves every edge; its children have equal volume).
std::vector<std::array<Barycentric, 4>> sub_tetrahedra(int levels) {
  std::vector<std::array<Barycentric, 4>> pieces = {
      {Barycentric(1, 0, 0, 0), Barycentric(0, 1, 0, 0), Barycentric(0, 0, 1, 0),
       Barycentric(0, 0, 0, 1)}};
  for (int level = 0; level < levels; ++level) {
    std::vector<std::array<Barycentric, 4>> next;
    for (const auto& sub : pieces) {
      const auto children = split_in_eight(sub);
      next.insert(next.end(), children.begin(), children.end());
    }
    pieces = std::move(next);
  }
  return pieces;
}

// The pieces of one, eight and 64 (levels 0, 1 and 2 of the eight-way split) in one table: an
// element split `level` times uses the 8^level entries from subdivision_offset(level) on.
constexpr int kProbeLevels = 3;
const std::vector<std::array<Barycentric, 4>>& probe_subdivision() {
  static const std::vector<std::array<Barycentric, 4>> pieces = [] {
    std::vector<std::array<Barycentric, 4>> all;
    for (int level = 0; level < kProbeLevels; ++level) {
      const auto some = sub_tetrahedra(level);
      all.insert(all.end(), some.begin(), some.end());
    }
    return all;
  }();
  return pieces;
}

std::size_t subdivision_offset(int level) {
  std::size_t offset = 0;
  for (int l = 0; l < level; ++l) offset += std::size_t{1} << (3 * l);
  return offset;
}

// Splits an element of `reach` (its farthest corner from its centroid, m) needs so that no
// piece reaches farther than kPieceReachPerLength L; at most two (64 pieces). The fidelities'
// skin meshes keep 64 pieces (their depths did not move, to the last digit, at fast, standard
// and fine); a finer element (the convergence study's contact zone) takes fewer, none wider
// than that, instead of 64 each (which ran a 6 um zone out of memory, docs/validation.md).
constexpr double kPieceReachPerLength = 0.5;
int probe_level(double reach, double length) {
  int level = 0;
  while (level + 1 < kProbeLevels && reach / std::ldexp(1.0, level) > kPieceReachPerLength * length)
    ++level;
  return level;
}

Barycentric centroid_of(const std::array<Barycentric, 4>& sub) {
  return 0.25 * (sub[0] + sub[1] + sub[2] + sub[3]);
}

// The centroids of the eight children of the eight-way split, in the parent's barycentric
// coordinates.
const std::array<Barycentric, 8>& child_centroids() {
  static const std::array<Barycentric, 8> centroids = [] {
    std::array<Barycentric, 8> out;
    const std::vector<std::array<Barycentric, 4>> children = sub_tetrahedra(1);
    for (std::size_t i = 0; i < 8; ++i) out[i] = centroid_of(children[i]);
    return out;
  }();
  return centroids;
}

// The eight children's centroids of the sub-tetrahedron with corners `p`.
std::array<Eigen::Vector3d, 8> children_of(const std::array<Eigen::Vector3d, 4>& p) {
  std::array<Eigen::Vector3d, 8> out;
  for (std::size_t i = 0; i < 8; ++i) {
    const Barycentric& l = child_centroids()[i];
    out[i] = l(0) * p[0] + l(1) * p[1] + l(2) * p[2] + l(3) * p[3];
  }
  return out;
}

// The volume of a sub-tetrahedron (centroid `mid`, farthest corner `reach` from it, children's
// centroids `children`) inside the ball (centre, radius): whole or nothing when it lies clearly
// in or out; when the sphere cuts it, an eighth for each of its eight children whose centroid
// lies inside (the count of a split one level deeper: the stress stays the sub-tetrahedron's,
// only its weight is refined).
double volume_in_ball(const std::array<Eigen::Vector3d, 8>& children, double volume, double reach,
                      const Eigen::Vector3d& mid, const Eigen::Vector3d& centre, double radius) {
  const double distance = (mid - centre).norm();
  if (distance - reach > radius) return 0.0;
  if (distance + reach <= radius) return volume;
  int inside = 0;
  for (const Eigen::Vector3d& x : children)
    inside += (x - centre).squaredNorm() <= radius * radius ? 1 : 0;
  return volume * inside / 8.0;
}

using Cell = std::array<long long, 3>;

Cell cell_of(const Eigen::Vector3d& x, double size) {
  return {static_cast<long long>(std::floor(x.x() / size)),
          static_cast<long long>(std::floor(x.y() / size)),
          static_cast<long long>(std::floor(x.z() / size))};
}

// 21 bits per axis, offset to be non-negative: a block spans far fewer than 2^20 averaging
// lengths (the scene's checks bound both).
long long cell_key(const Cell& c) {
  constexpr long long kOffset = 1LL << 20, kMask = (1LL << 21) - 1;
  return (((c[0] + kOffset) & kMask) << 42) | (((c[1] + kOffset) & kMask) << 21) |
         ((c[2] + kOffset) & kMask);
}

// Centres closer than this fraction of the averaging length are thinned (spaced_centres): the
// averaged stress varies over L, and on a contact zone's sub-micrometre elements every node a
// centre made the probe 60 % of a run. On paper A's skin with a resolved tip, spacings of 0, L/20,
// L/10 and L/5 gave the same puncture depth to 14 digits; fast's and standard's meshes are not
// fine enough to lose a centre, fine's own contact zone is (docs/model.md, "Tip stress").
constexpr double kCentreSpacingPerLength = 0.1;

// The nodes kept as centres where the mesh is finer than `spacing`: taken deepest first (a layer's
// underside, where a bent layer's tension peaks, keeps all it has up to the spacing), then
// nearest the planes x = 0 and y = 0, each dropped when a kept one lies within `spacing` of it.
// Independent of the nodes' numbering; on a mesh no finer than `spacing` every node stays.
std::vector<int> spaced_centres(const TetMesh& mesh, std::vector<int> nodes, double spacing) {
  const auto at = [&](int node) -> const Eigen::Vector3d& {
    return mesh.nodes[static_cast<std::size_t>(node)];
  };
  std::sort(nodes.begin(), nodes.end(), [&](int a, int b) {
    const Eigen::Vector3d &p = at(a), &q = at(b);
    if (p.z() != q.z()) return p.z() < q.z();
    // Nearest the planes x = 0 and y = 0 first, a mirror pair one after the other: a half or
    // quarter model keeps the mirror images of what the whole block keeps near its planes, up to
    // the pairs closer than `spacing` across a plane (docs/model.md, "Tip stress").
    if (std::abs(p.y()) != std::abs(q.y())) return std::abs(p.y()) < std::abs(q.y());
    if (std::abs(p.x()) != std::abs(q.x())) return std::abs(p.x()) < std::abs(q.x());
    if (p.y() != q.y()) return p.y() < q.y();
    if (p.x() != q.x()) return p.x() < q.x();
    return a < b;
  });
  std::unordered_map<long long, std::vector<int>> kept_in;
  std::vector<int> kept;
  for (int node : nodes) {
    const Cell home = cell_of(at(node), spacing);
    bool crowded = false;
    for (int dx = -1; dx <= 1 && !crowded; ++dx)
      for (int dy = -1; dy <= 1 && !crowded; ++dy)
        for (int dz = -1; dz <= 1 && !crowded; ++dz) {
          const auto cell = kept_in.find(cell_key({home[0] + dx, home[1] + dy, home[2] + dz}));
          if (cell == kept_in.end()) continue;
          for (int other : cell->second)
            if ((at(other) - at(node)).norm() < spacing) {
              crowded = true;
              break;
            }
        }
    if (crowded) continue;
    kept_in[cell_key(home)].push_back(node);
    kept.push_back(node);
  }
  std::sort(kept.begin(), kept.end());
  return kept;
}

}  // namespace

PeakStressProbe::PeakStressProbe(const TetMesh& mesh, std::vector<Eigen::Vector2d> sites_xy,
                                 std::vector<double> search_radius_m, double search_depth_m,
                                 double length_m, int layer)
    : mesh_(&mesh),
      length_(length_m),
      layer_(layer),
      site_count_(sites_xy.size()),
      search_radius_(search_radius_m) {
  if (!(length_m > 0.0) || !std::isfinite(length_m))
    throw InputError("stress probe: averaging length must be positive and finite");
  if (layer < 0 || layer >= static_cast<int>(mesh.layers.size()))
    throw InputError("stress probe: layer index out of range");
  if (search_radius_m.size() != sites_xy.size())
    throw InputError("stress probe: one search radius per site");
  for (double r : search_radius_m)
    if (!(r >= 0.0) || !std::isfinite(r))
      throw InputError("stress probe: search radius must be >= 0 and finite");
  if (!(search_depth_m >= 0.0) || !std::isfinite(search_depth_m))
    throw InputError("stress probe: search depth must be >= 0 and finite");
  const std::vector<std::array<Barycentric, 4>>& subs = probe_subdivision();
  std::vector<char> candidate_node(mesh.nodes.size(), 0);
  std::vector<std::array<int, 4>> element_order;  // canonical_corners of each of elements_
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    if (mesh.element_layer[e] != layer) continue;
    const auto& element = mesh.elements[e];
    const auto [corners, mid, reach] = element_bounds(mesh, e);
    // Within reach of a centre: a ball of radius L about a node no farther than the search
    // radius from a site and no deeper than the search depth (a mirror image is as far from a
    // site on the plane as its source, so the meshed part holds every element they come from).
    bool near = mid.z() + reach >= -(search_depth_m + length_m);
    bool beside = false;
    for (std::size_t s = 0; s < sites_xy.size(); ++s)
      beside =
          beside || (mid.head<2>() - sites_xy[s]).norm() - reach <= search_radius_m[s] + length_m;
    if (!near || !beside) continue;
    elements_.push_back(static_cast<int>(e));
    const int level = probe_level(reach, length_m);
    const std::size_t first = subdivision_offset(level), count = std::size_t{1} << (3 * level);
    const double volume = tet_volume(corners) / static_cast<double>(count);
    const std::array<int, 4> order = canonical_corners(mesh, e);
    element_order.push_back(order);
    for (std::size_t k = first; k < first + count; ++k) {
      const Barycentric l = centroid_of(subs[k]);
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int a = 0; a < 4; ++a) x += l(a) * corners[static_cast<std::size_t>(order[a])];
      points_.push_back({x, volume, static_cast<int>(e), static_cast<int>(k)});
    }
    // Every node a centre, midside nodes too: with corners only the STL cone's peak read lower
    // and its puncture on human_skin.toml moved from 108.1 to 120.7 um at fast.
    for (int a = 0; a < mesh.nodes_per_element(); ++a) {
      candidate_node[static_cast<std::size_t>(element[a])] = 1;
      nodes_.push_back(element[a]);
    }
  }
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  // Thinned among the nodes within reach of a site only, so that a node outside every search
  // radius never displaces one inside.
  std::vector<int> centre_nodes;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!candidate_node[i] || mesh.nodes[i].z() < -search_depth_m) continue;
    bool within = false;
    for (std::size_t s = 0; s < sites_xy.size() && !within; ++s)
      within = (mesh.nodes[i].head<2>() - sites_xy[s]).norm() <= search_radius_m[s];
    if (within) centre_nodes.push_back(static_cast<int>(i));
  }
  centre_nodes = spaced_centres(mesh, std::move(centre_nodes), kCentreSpacingPerLength * length_m);
  for (int node : centre_nodes) {
    const auto i = static_cast<std::size_t>(node);
    for (std::size_t s = 0; s < sites_xy.size(); ++s)
      if ((mesh.nodes[i].head<2>() - sites_xy[s]).norm() <= search_radius_m[s])
        candidates_.push_back(
            {mesh.nodes[i], static_cast<int>(s), (mesh.nodes[i].head<2>() - sites_xy[s]).norm()});
  }
  // Each sub-tetrahedron's children's centroids and its farthest corner's distance from its
  // centroid.
  std::vector<std::array<Eigen::Vector3d, 8>> sub_children(points_.size());
  std::vector<double> sub_reach(points_.size(), 0.0);
  std::size_t in_elements = 0;  // index into elements_ of points_[i]'s element
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (i > 0 && points_[i].element != points_[i - 1].element) ++in_elements;
    const auto& element = mesh.elements[static_cast<std::size_t>(points_[i].element)];
    const std::array<Barycentric, 4>& sub = subs[static_cast<std::size_t>(points_[i].sub)];
    const std::array<int, 4>& order = element_order[in_elements];
    std::array<Eigen::Vector3d, 4> corners;
    for (std::size_t v = 0; v < 4; ++v) {
      Eigen::Vector3d x = Eigen::Vector3d::Zero();
      for (int a = 0; a < 4; ++a)
        x += sub[v](a) *
             mesh.nodes[static_cast<std::size_t>(element[static_cast<std::size_t>(order[a])])];
      corners[v] = x;
      sub_reach[i] = std::max(sub_reach[i], (x - points_[i].x).norm());
    }
    sub_children[i] = children_of(corners);
  }
  // The pieces of elements_[k] are points_[piece_start_[k] .. piece_start_[k + 1]).
  piece_start_.assign(1, 0);
  for (std::size_t i = 0; i < points_.size(); ++i)
    if (i + 1 == points_.size() || points_[i + 1].element != points_[i].element)
      piece_start_.push_back(i + 1);
  const std::vector<std::size_t>& piece_start = piece_start_;
  // The balls of a half (quarter) model see the mirror image of the meshed part as the whole
  // block's do: an element with a sub-tetrahedron that reaches within L of a symmetry plane is
  // reflected across it (its other pieces are too far to enter a ball and weigh nothing).
  struct Image {
    Eigen::Vector3d mid;  // the element's centroid, reflected
    double reach;         // the farthest corner's distance from it
    int element;          // index into elements_
    int mirror;           // bit 0: y negated, bit 1: x negated
  };
  std::vector<Image> images;
  double widest = 0.0;
  for (std::size_t k = 0; k < elements_.size(); ++k) {
    const Bounds bounds = element_bounds(mesh, static_cast<std::size_t>(elements_[k]));
    widest = std::max(widest, bounds.reach);
    bool near[2] = {false, false};  // x = 0, y = 0
    for (std::size_t i = piece_start[k]; i < piece_start[k + 1]; ++i)
      for (int axis : {0, 1})
        near[axis] = near[axis] || points_[i].x(axis) < length_m + sub_reach[i];
    const bool mirror_y = mesh.mirror_y0 && near[1], mirror_x = mesh.mirror_x0 && near[0];
    for (int mirror = 0; mirror < 4; ++mirror) {
      if (((mirror & 1) && !mirror_y) || ((mirror & 2) && !mirror_x)) continue;
      Eigen::Vector3d mid = bounds.mid;
      if (mirror & 1) mid.y() = -mid.y();
      if (mirror & 2) mid.x() = -mid.x();
      images.push_back({mid, bounds.reach, static_cast<int>(k), mirror});
    }
  }
  // Element images bucketed on a grid of cells a hair wider than L plus the widest element's
  // reach: an element that reaches into a ball has its centroid in a neighbouring cell. Elements
  // first, then their pieces: 64 times fewer tests than bucketing every piece.
  const double cell = (length_m + widest) * (1.0 + 1e-9);
  std::unordered_map<long long, std::vector<int>> buckets;
  for (std::size_t i = 0; i < images.size(); ++i)
    buckets[cell_key(cell_of(images[i].mid, cell))].push_back(static_cast<int>(i));
  // Each centre's ball, once: the volume of every sub-tetrahedron (or its image) inside it.
  // Counting a sub-tetrahedron by its centroid instead made the ball's edge ragged by a quarter
  // element: on the fast skin mesh the sharp bevel's puncture moved from 64.8 to 99.9 um when the
  // elements were split eight times finer (docs/model.md, "Tip stress").
  // Centres are independent: chunks of them run on the factorisations' threads, each ball into
  // its own list, joined in centre order, so the lists do not depend on the thread count.
  std::vector<std::vector<std::pair<int, double>>> balls(candidates_.size());
  parallel_chunks(candidates_.size(), loop_threads(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Candidate& c = candidates_[k];
      std::vector<std::pair<int, double>>& ball = balls[k];
      const Cell home = cell_of(c.x, cell);
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const auto bucket = buckets.find(cell_key({home[0] + dx, home[1] + dy, home[2] + dz}));
            if (bucket == buckets.end()) continue;
            for (int q : bucket->second) {
              const Image& image = images[static_cast<std::size_t>(q)];
              const double apart = (image.mid - c.x).norm();
              if (apart - image.reach > length_m) continue;
              // The image's pieces against the centre are the source's against the centre's
              // image.
              Eigen::Vector3d centre = c.x;
              if (image.mirror & 1) centre.y() = -centre.y();
              if (image.mirror & 2) centre.x() = -centre.x();
              const bool whole = apart + image.reach <= length_m;
              const auto e = static_cast<std::size_t>(image.element);
              for (std::size_t i = piece_start[e]; i < piece_start[e + 1]; ++i) {
                const double volume =
                    whole ? points_[i].volume
                          : volume_in_ball(sub_children[i], points_[i].volume, sub_reach[i],
                                           points_[i].x, centre, length_m);
                if (volume > 0.0) ball.emplace_back(static_cast<int>(i), volume);
              }
            }
          }
    }
  });
  std::size_t entries = 0;
  for (const auto& ball : balls) entries += ball.size();
  ball_source_.reserve(entries);
  ball_volume_.reserve(entries);
  ball_start_.reserve(balls.size() + 1);
  ball_start_.push_back(0);
  for (auto& ball : balls) {
    for (const auto& [source, volume] : ball) {
      ball_source_.push_back(source);
      ball_volume_.push_back(volume);
    }
    ball_start_.push_back(ball_source_.size());
    std::vector<std::pair<int, double>>().swap(ball);  // freed as it is copied
  }
}

std::vector<double> PeakStressProbe::peak(const Eigen::VectorXd& u,
                                          const std::vector<double>& search_radius_m) const {
  const TetMesh& mesh = *mesh_;
  if (u.size() != 3 * static_cast<Eigen::Index>(mesh.nodes.size()))
    throw InputError("stress probe: displacement size does not match the mesh");
  if (search_radius_m.size() != site_count_)
    throw InputError("stress probe: one search radius per site");
  for (std::size_t s = 0; s < site_count_; ++s)
    if (search_radius_m[s] > search_radius_[s] * (1.0 + 1e-12))
      throw InputError("stress probe: a search radius beyond the one the probe was built for");
  bool all_linear = true;
  const Material material = layer_material(mesh, layer_, &all_linear);
  const std::vector<std::array<Barycentric, 4>>& subs = probe_subdivision();
  // The stress at every sub-point, element by element (points_ is grouped by element). With
  // small strain and a linear law the stress of a TET4 is constant and that of a TET10 linear in
  // the element, so it is interpolated from the corners' (exact, and 16 times fewer material
  // evaluations); otherwise it is evaluated at each sub-point.
  std::vector<double> stress(points_.size(), 0.0);
  const Barycentric corner[4] = {Barycentric(1, 0, 0, 0), Barycentric(0, 1, 0, 0),
                                 Barycentric(0, 0, 1, 0), Barycentric(0, 0, 0, 1)};
  const auto largest = [](const Eigen::Matrix3d& sigma) {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(sigma, Eigen::EigenvaluesOnly);
    return eigen.eigenvalues().maxCoeff();
  };
  // Elements, then centres, in chunks on the factorisations' threads: each writes its own
  // entries, and the peak is taken in centre order, so the answer does not depend on the count.
  const int threads = loop_threads();
  parallel_chunks(elements_.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const auto e = static_cast<std::size_t>(elements_[k]);
      const ElementField field = element_field(mesh, u, e, material, all_linear);
      // The sub-points' barycentrics are over the canonical corners; the field's over the local.
      const std::array<int, 4> order = canonical_corners(mesh, e);
      const auto local = [&](const Barycentric& l) {
        Barycentric out;
        for (int a = 0; a < 4; ++a) out(order[static_cast<std::size_t>(a)]) = l(a);
        return out;
      };
      const auto centroid = [&](std::size_t i) {
        return local(centroid_of(subs[static_cast<std::size_t>(points_[i].sub)]));
      };
      if (all_linear) {
        Eigen::Matrix3d at_corner[4];
        for (int c = 0; c < 4; ++c) at_corner[c] = field.cauchy(corner[c]);
        for (std::size_t i = piece_start_[k]; i < piece_start_[k + 1]; ++i) {
          const Barycentric l = centroid(i);
          stress[i] = largest(l(0) * at_corner[0] + l(1) * at_corner[1] + l(2) * at_corner[2] +
                              l(3) * at_corner[3]);
        }
      } else {
        for (std::size_t i = piece_start_[k]; i < piece_start_[k + 1]; ++i)
          stress[i] = field.max_principal(centroid(i));
      }
    }
  });
  // Each centre's mean (NaN: outside its site's radius now, or an empty ball).
  std::vector<double> mean(candidates_.size(), std::numeric_limits<double>::quiet_NaN());
  parallel_chunks(candidates_.size(), threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t k = begin; k < end; ++k) {
      const Candidate& c = candidates_[k];
      if (c.distance > search_radius_m[static_cast<std::size_t>(c.site)]) continue;
      double stress_volume = 0.0, volume = 0.0;
      for (std::size_t j = ball_start_[k]; j < ball_start_[k + 1]; ++j) {
        stress_volume += ball_volume_[j] * stress[static_cast<std::size_t>(ball_source_[j])];
        volume += ball_volume_[j];
      }
      if (volume > 0.0) mean[k] = stress_volume / volume;
    }
  });
  std::vector<double> best(site_count_, 0.0);
  std::vector<char> found(site_count_, 0);
  for (std::size_t k = 0; k < candidates_.size(); ++k) {
    if (std::isnan(mean[k])) continue;
    const auto s = static_cast<std::size_t>(candidates_[k].site);
    if (!found[s] || mean[k] > best[s]) best[s] = mean[k];
    found[s] = 1;
  }
  return best;
}

std::vector<Eigen::Vector3d> PeakStressProbe::centres() const {
  std::vector<Eigen::Vector3d> out;
  for (const Candidate& c : candidates_) out.push_back(c.x);
  return out;
}

std::vector<double> PeakStressProbe::ball_volumes() const {
  std::vector<double> out;
  for (std::size_t k = 0; k < candidates_.size(); ++k) {
    double volume = 0.0;
    for (std::size_t j = ball_start_[k]; j < ball_start_[k + 1]; ++j) volume += ball_volume_[j];
    out.push_back(volume);
  }
  return out;
}

double averaged_max_principal_stress(const TetMesh& mesh, const Eigen::VectorXd& u,
                                     const Eigen::Vector3d& point_m, double length_m, int layer) {
  if (!(length_m > 0.0) || !std::isfinite(length_m))
    throw InputError("stress probe: averaging length must be positive and finite");
  if (layer < 0 || layer >= static_cast<int>(mesh.layers.size()))
    throw InputError("stress probe: layer index out of range");
  if (u.size() != 3 * static_cast<Eigen::Index>(mesh.nodes.size()))
    throw InputError("stress probe: displacement size does not match the mesh");
  bool all_linear = true;
  const Material material = layer_material(mesh, layer, &all_linear);
  const std::array<Barycentric, 4> whole = {Barycentric(1, 0, 0, 0), Barycentric(0, 1, 0, 0),
                                            Barycentric(0, 0, 1, 0), Barycentric(0, 0, 0, 1)};
  Accumulator sum;
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    if (mesh.element_layer[e] != layer) continue;
    const Bounds b = element_bounds(mesh, e);
    if ((b.mid - point_m).norm() - b.reach > length_m) continue;
    integrate(element_field(mesh, u, e, material, all_linear), whole, point_m, length_m, 0, &sum);
  }
  return sum.volume > 0.0 ? sum.stress_volume / sum.volume : 0.0;
}

}  // namespace mneedle::fe
