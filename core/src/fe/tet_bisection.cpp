#include "fe/tet_bisection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include "mneedle/base/error.h"

namespace mneedle::fe {

namespace {
// Recursion depth of the conforming closure: each level goes to a coarser neighbour, so the
// depth is bounded by the generations in the mesh (three per halving); more means a bug.
constexpr int kMaxClosureDepth = 200;
}  // namespace

TetBisection::TetBisection(std::vector<Eigen::Vector3d> nodes)
    : nodes_(std::move(nodes)), node_tets_(nodes_.size()) {}

void TetBisection::add_kuhn_tet(const std::array<int, 4>& path, int layer) {
  const int t = static_cast<int>(tets_.size());
  tets_.push_back(path);
  tag_.push_back(3);
  layer_.push_back(layer);
  for (int v : path) node_tets_[static_cast<std::size_t>(v)].push_back(t);
}

double TetBisection::extent(int t) const {
  const auto& v = tets_[static_cast<std::size_t>(t)];
  Eigen::Vector3d lo = nodes_[static_cast<std::size_t>(v[0])], hi = lo;
  for (int i = 1; i < 4; ++i) {
    lo = lo.cwiseMin(nodes_[static_cast<std::size_t>(v[static_cast<std::size_t>(i)])]);
    hi = hi.cwiseMax(nodes_[static_cast<std::size_t>(v[static_cast<std::size_t>(i)])]);
  }
  return (hi - lo).maxCoeff();
}

Eigen::Vector3d TetBisection::centroid(int t) const {
  const auto& v = tets_[static_cast<std::size_t>(t)];
  // Sorted summation: a tetrahedron and its mirror image get the same centroid to the last bit
  // (up to sign), so a symmetric target refines symmetrically.
  Eigen::Vector3d c;
  for (int d = 0; d < 3; ++d) {
    std::array<double, 4> x{};
    for (int i = 0; i < 4; ++i)
      x[static_cast<std::size_t>(i)] =
          nodes_[static_cast<std::size_t>(v[static_cast<std::size_t>(i)])][d];
    std::sort(x.begin(), x.end(), [](double a, double b) { return std::abs(a) < std::abs(b); });
    c[d] = 0.25 * (((x[0] + x[1]) + x[2]) + x[3]);
  }
  return c;
}

std::vector<int> TetBisection::tets_around(int a, int b) const {
  std::vector<int> around;
  for (int t : node_tets_[static_cast<std::size_t>(a)]) {
    const auto& v = tets_[static_cast<std::size_t>(t)];
    if (std::find(v.begin(), v.end(), b) != v.end()) around.push_back(t);
  }
  return around;
}

bool TetBisection::has_refinement_edge(int t, int a, int b) const {
  const auto& v = tets_[static_cast<std::size_t>(t)];
  const int x0 = v[0], xk = v[static_cast<std::size_t>(tag_[static_cast<std::size_t>(t)])];
  return (x0 == a && xk == b) || (x0 == b && xk == a);
}

// Bisects t's refinement edge in every tetrahedron around it, first bisecting (recursively) each
// of those whose own refinement edge is another one: a midpoint is never a hanging node.
void TetBisection::bisect_conforming(int t, int depth) {
  if (depth > kMaxClosureDepth)
    throw std::logic_error("tet bisection: conforming closure did not terminate");
  // Copies, not a reference into tets_: the recursion below grows the vector.
  const auto ti = static_cast<std::size_t>(t);
  const int a = tets_[ti][0], b = tets_[ti][static_cast<std::size_t>(tag_[ti])];
  while (true) {
    const std::vector<int> around = tets_around(a, b);
    if (around.empty()) return;  // the edge was bisected by the closure of a neighbour
    const auto other = std::find_if(around.begin(), around.end(),
                                    [&](int u) { return !has_refinement_edge(u, a, b); });
    if (other != around.end()) {
      bisect_conforming(*other, depth + 1);
      continue;
    }
    const int midpoint = static_cast<int>(nodes_.size());
    nodes_.push_back(0.5 *
                     (nodes_[static_cast<std::size_t>(a)] + nodes_[static_cast<std::size_t>(b)]));
    node_tets_.emplace_back();
    for (int u : around) bisect(u, midpoint);
    return;
  }
}

// Maubach's rule for T = (x0, x1, x2, x3) with tag k, z the midpoint of x0-xk:
//   T1 = (x0, ..., x_{k-1}, z, x_{k+1}, ..., x3), T2 = (x1, ..., x_k, z, x_{k+1}, ..., x3),
// both with tag k - 1 (3 after 1). T1 keeps the index of T.
void TetBisection::bisect(int t, int midpoint) {
  const auto ti = static_cast<std::size_t>(t);
  const std::array<int, 4> v = tets_[ti];
  const int k = tag_[ti];
  const int next = k > 1 ? k - 1 : 3;
  std::array<int, 4> first = v;
  first[static_cast<std::size_t>(k)] = midpoint;
  std::array<int, 4> second{};
  for (int i = 0; i < k; ++i)
    second[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i + 1)];
  second[static_cast<std::size_t>(k)] = midpoint;
  for (int i = k + 1; i < 4; ++i)
    second[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i)];

  auto& xk_tets = node_tets_[static_cast<std::size_t>(v[static_cast<std::size_t>(k)])];
  xk_tets.erase(std::find(xk_tets.begin(), xk_tets.end(), t));
  node_tets_[static_cast<std::size_t>(midpoint)].push_back(t);
  tets_[ti] = first;
  tag_[ti] = next;

  const int s = static_cast<int>(tets_.size());
  tets_.push_back(second);
  tag_.push_back(next);
  layer_.push_back(layer_[ti]);
  for (int node : second) node_tets_[static_cast<std::size_t>(node)].push_back(s);
}

void TetBisection::refine(const std::function<double(const Eigen::Vector3d&)>& target,
                          std::size_t max_tets) {
  // A small margin: a box exactly at the target size is not split again.
  constexpr double kMargin = 1.0 + 1e-9;
  while (true) {
    std::vector<int> marked;
    for (int t = 0; t < static_cast<int>(tets_.size()); ++t)
      if (extent(t) > kMargin * target(centroid(t))) marked.push_back(t);
    if (marked.empty()) return;
    for (int t : marked) {
      // The closure of an earlier one may have bisected it already: T1 took its index.
      if (!(extent(t) > kMargin * target(centroid(t)))) continue;
      bisect_conforming(t, 0);
      if (tets_.size() > max_tets)
        throw InputError("tissue block: mesh refinement: more than " + std::to_string(max_tets) +
                         " tetrahedra; a coarser [model] contact_zone or contact_zone_tip, fewer "
                         "mesh_refinement levels or a coarser fidelity needs fewer");
    }
  }
}

}  // namespace mneedle::fe
