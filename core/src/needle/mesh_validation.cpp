#include "mneedle/needle/mesh_validation.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polygon_mesh_processing/shape_predicates.h>
#include <CGAL/Polygon_mesh_processing/stitch_borders.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <map>
#include <numeric>
#include <queue>
#include <set>
#include <unordered_map>
#include <utility>

#include "mneedle/base/error.h"
#include "needle/cgal_mesh.h"

namespace PMP = CGAL::Polygon_mesh_processing;

namespace mneedle {
namespace {

using Polygon = std::vector<std::size_t>;
using FaceIndex = SurfaceMesh::Face_index;

std::string counted(std::size_t n, const std::string& singular, const std::string& plural) {
  return std::to_string(n) + " " + (n == 1 ? singular : plural);
}

CgalPoint to_point(const Vec3& p) {
  return {p[0], p[1], p[2]};
}

bool has_repeated_corner(const Triangle& t) {
  return t[0] == t[1] || t[1] == t[2] || t[0] == t[2];
}

bool is_degenerate(const TriangleMesh& mesh, const Triangle& t) {
  return has_repeated_corner(t) ||
         CGAL::collinear(to_point(mesh.vertices[t[0]]), to_point(mesh.vertices[t[1]]),
                         to_point(mesh.vertices[t[2]]));
}

bool all_finite(const Vec3& p) {
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

// One use of an undirected edge by a triangle; `forward` when the triangle runs low -> high.
struct EdgeUse {
  std::size_t face;
  bool forward;
};
using EdgeMap = std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<EdgeUse>>;

EdgeMap collect_edges(const TriangleMesh& mesh) {
  EdgeMap edges;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const Triangle& t = mesh.triangles[f];
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = t[k];
      const std::uint32_t b = t[(k + 1) % 3];
      if (a == b) continue;
      edges[{std::min(a, b), std::max(a, b)}].push_back({f, a < b});
    }
  }
  return edges;
}

// Propagates orientation across manifold edges (two triangles agree when they run the shared
// edge in opposite directions); in each connected patch the smaller camp counts as flipped.
std::size_t count_inconsistent_faces(const TriangleMesh& mesh, const EdgeMap& edges) {
  const std::size_t n = mesh.triangles.size();
  std::vector<std::vector<std::pair<std::size_t, bool>>> neighbours(n);  // (face, must flip)
  for (const auto& [edge, uses] : edges) {
    if (uses.size() != 2) continue;
    const bool disagree = uses[0].forward == uses[1].forward;
    neighbours[uses[0].face].push_back({uses[1].face, disagree});
    neighbours[uses[1].face].push_back({uses[0].face, disagree});
  }
  std::vector<int> flip(n, -1);
  std::size_t inconsistent = 0;
  for (std::size_t seed = 0; seed < n; ++seed) {
    if (flip[seed] != -1) continue;
    std::size_t camp_size[2] = {0, 0};
    std::size_t contradictions = 0;  // a non-orientable patch (Moebius-like)
    std::queue<std::size_t> queue;
    flip[seed] = 0;
    queue.push(seed);
    while (!queue.empty()) {
      const std::size_t f = queue.front();
      queue.pop();
      ++camp_size[flip[f]];
      for (const auto& [g, must_flip] : neighbours[f]) {
        const int wanted = flip[f] ^ static_cast<int>(must_flip);
        if (flip[g] == -1) {
          flip[g] = wanted;
          queue.push(g);
        } else if (flip[g] != wanted) {
          ++contradictions;
        }
      }
    }
    inconsistent += std::min(camp_size[0], camp_size[1]);
    if (contradictions > 0 && camp_size[0] > 0 && camp_size[1] == 0) ++inconsistent;
  }
  return inconsistent;
}

std::size_t find_root(std::vector<std::size_t>& parent, std::size_t i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// A vertex is manifold when its triangles form one fan, joined through the edges at the vertex.
std::size_t count_non_manifold_vertices(const TriangleMesh& mesh) {
  std::vector<std::vector<std::size_t>> faces_at(mesh.vertices.size());
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    if (has_repeated_corner(mesh.triangles[f])) continue;
    for (std::uint32_t v : mesh.triangles[f]) faces_at[v].push_back(f);
  }
  std::size_t count = 0;
  for (std::size_t v = 0; v < faces_at.size(); ++v) {
    const std::vector<std::size_t>& faces = faces_at[v];
    std::vector<std::size_t> parent(faces.size());
    std::iota(parent.begin(), parent.end(), std::size_t{0});
    std::unordered_map<std::uint32_t, std::size_t> first_face_on_edge;  // other end -> slot
    for (std::size_t slot = 0; slot < faces.size(); ++slot) {
      for (std::uint32_t w : mesh.triangles[faces[slot]]) {
        if (w == v) continue;
        const auto [it, inserted] = first_face_on_edge.emplace(w, slot);
        if (!inserted) parent[find_root(parent, slot)] = find_root(parent, it->second);
      }
    }
    std::size_t fans = 0;
    for (std::size_t slot = 0; slot < faces.size(); ++slot) fans += find_root(parent, slot) == slot;
    if (fans > 1) ++count;
  }
  return count;
}

// A surface mesh for the geometric tests even when the triangles are not manifold or not
// consistently oriented: orient_polygon_soup duplicates the offending vertices.
SurfaceMesh to_any_surface_mesh(const TriangleMesh& mesh) {
  TriangleMesh usable = mesh;
  std::erase_if(usable.triangles, has_repeated_corner);
  if (is_halfedge_representable(usable)) return to_surface_mesh(usable);
  std::vector<CgalPoint> points;
  points.reserve(usable.vertices.size());
  for (const Vec3& p : usable.vertices) points.push_back(to_point(p));
  std::vector<Polygon> polygons;
  for (const Triangle& t : usable.triangles) polygons.push_back({t[0], t[1], t[2]});
  PMP::orient_polygon_soup(points, polygons);
  SurfaceMesh surface;
  PMP::polygon_soup_to_polygon_mesh(points, polygons, surface);
  return surface;
}

std::size_t count_self_intersections(const SurfaceMesh& surface) {
  std::vector<std::pair<FaceIndex, FaceIndex>> pairs;
  PMP::self_intersections(surface, std::back_inserter(pairs));
  // Degenerate faces come back paired with themselves and touch their neighbours; they are
  // reported once, as degenerate, so every pair involving one is left out here.
  std::set<FaceIndex> degenerate;
  for (const auto& [f, g] : pairs) {
    if (f == g) degenerate.insert(f);
  }
  return static_cast<std::size_t>(std::count_if(pairs.begin(), pairs.end(), [&](const auto& p) {
    return !degenerate.contains(p.first) && !degenerate.contains(p.second);
  }));
}

double volume_tolerance(const TriangleMesh& mesh) {
  const BoundingBox box = bounding_box(mesh);
  double diagonal = 0.0;
  for (int k = 0; k < 3; ++k) diagonal = std::max(diagonal, box.max[k] - box.min[k]);
  return 1e-12 * diagonal * diagonal * diagonal;
}

void check_orientation(const TriangleMesh& mesh, const SurfaceMesh& surface,
                       MeshValidation& result) {
  result.outward = result.volume_m3 > 0.0;
  const bool orientable = result.border_edges == 0 && result.non_manifold_edges == 0 &&
                          result.non_manifold_vertices == 0 && result.inconsistent_faces == 0 &&
                          result.self_intersections == 0 && result.degenerate_faces == 0;
  if (!orientable) return;
  if (std::abs(result.volume_m3) <= volume_tolerance(mesh)) {
    result.outward = false;
    result.errors.push_back("mesh encloses no volume");
  } else if (result.volume_m3 < 0.0) {
    result.errors.push_back(
        "mesh is inward-oriented (negative volume; `screen --repair` or `mneedle inspect FILE "
        "--repair -o fixed.stl` reorients it)");
  } else if (!PMP::does_bound_a_volume(surface)) {
    result.outward = false;
    result.errors.push_back("mesh does not bound a volume (a shell is inside out)");
  }
}

void check_topology(const TriangleMesh& mesh, MeshValidation& result) {
  const EdgeMap edges = collect_edges(mesh);
  for (const auto& [edge, uses] : edges) {
    if (uses.size() == 1) ++result.border_edges;
    if (uses.size() > 2) ++result.non_manifold_edges;
  }
  result.non_manifold_vertices = count_non_manifold_vertices(mesh);
  result.inconsistent_faces = count_inconsistent_faces(mesh, edges);
  if (result.border_edges > 0) {
    result.errors.push_back("mesh is not closed (" +
                            counted(result.border_edges, "border edge", "border edges") + ")");
  }
  if (result.non_manifold_edges > 0) {
    result.errors.push_back("mesh is not manifold (" +
                            counted(result.non_manifold_edges, "edge", "edges") +
                            " shared by more than two faces)");
  }
  if (result.non_manifold_vertices > 0) {
    result.errors.push_back(
        "mesh is not manifold (" +
        counted(result.non_manifold_vertices, "non-manifold vertex", "non-manifold vertices") +
        ")");
  }
  if (result.inconsistent_faces > 0) {
    result.errors.push_back("mesh is not consistently oriented (" +
                            counted(result.inconsistent_faces, "flipped face", "flipped faces") +
                            ")");
  }
}

bool indices_valid(const TriangleMesh& mesh) {
  return std::all_of(mesh.triangles.begin(), mesh.triangles.end(), [&](const Triangle& t) {
    return std::all_of(t.begin(), t.end(),
                       [&](std::uint32_t v) { return v < mesh.vertices.size(); });
  });
}

}  // namespace

namespace {

// Number of separate solid bodies: pieces of triangles that share vertices (union-find) whose
// signed volume is positive. A cavity's inward shell (negative volume) is not a body of its own.
std::size_t count_bodies(const TriangleMesh& mesh) {
  std::vector<std::uint32_t> parent(mesh.vertices.size());
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&parent](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const Triangle& t : mesh.triangles) {
    parent[find(t[1])] = find(t[0]);
    parent[find(t[2])] = find(t[0]);
  }
  std::map<std::uint32_t, double> six_volume;
  for (const Triangle& t : mesh.triangles) {
    const Vec3& a = mesh.vertices[t[0]];
    const Vec3& b = mesh.vertices[t[1]];
    const Vec3& c = mesh.vertices[t[2]];
    six_volume[find(t[0])] += a[0] * (b[1] * c[2] - b[2] * c[1]) -
                              a[1] * (b[0] * c[2] - b[2] * c[0]) +
                              a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  return static_cast<std::size_t>(std::count_if(six_volume.begin(), six_volume.end(),
                                                [](const auto& v) { return v.second > 0.0; }));
}

}  // namespace

MeshValidation validate_mesh(const TriangleMesh& mesh) {
  MeshValidation result;
  if (mesh.triangles.empty()) {
    result.errors.push_back("mesh is empty (no triangles)");
    return result;
  }
  if (!indices_valid(mesh)) {
    result.errors.push_back("mesh has a triangle with a vertex index out of range");
    return result;
  }
  result.non_finite_vertices = static_cast<std::size_t>(std::count_if(
      mesh.vertices.begin(), mesh.vertices.end(), [](const Vec3& p) { return !all_finite(p); }));
  if (result.non_finite_vertices > 0) {
    result.errors.push_back("mesh has " +
                            counted(result.non_finite_vertices, "vertex", "vertices") +
                            " with non-finite coordinates");
    return result;  // geometric predicates are meaningless on NaN
  }
  result.bodies = count_bodies(mesh);
  if (result.bodies > 1) {
    result.errors.push_back("mesh holds " + std::to_string(result.bodies) +
                            " separate bodies; a needle file must hold one (export the needle "
                            "alone)");
  }
  check_topology(mesh, result);
  const SurfaceMesh surface = to_any_surface_mesh(mesh);
  result.self_intersections = count_self_intersections(surface);
  if (result.self_intersections > 0) {
    result.errors.push_back(
        "mesh self-intersects (" +
        counted(result.self_intersections, "intersecting face pair", "intersecting face pairs") +
        ")");
  }
  result.degenerate_faces = static_cast<std::size_t>(
      std::count_if(mesh.triangles.begin(), mesh.triangles.end(),
                    [&](const Triangle& t) { return is_degenerate(mesh, t); }));
  if (result.degenerate_faces > 0) {
    result.errors.push_back("mesh has " + counted(result.degenerate_faces,
                                                  "degenerate (zero-area) face",
                                                  "degenerate (zero-area) faces"));
  }
  result.volume_m3 = signed_volume(mesh);
  check_orientation(mesh, surface, result);
  result.valid = result.errors.empty();
  return result;
}

void require_valid_mesh(const TriangleMesh& mesh, std::string_view source_name) {
  const MeshValidation validation = validate_mesh(mesh);
  if (validation.valid) return;
  std::string message(source_name);
  for (std::size_t i = 0; i < validation.errors.size(); ++i) {
    message += (i == 0 ? ": " : "; ") + validation.errors[i];
  }
  throw InputError(message);
}

namespace {

struct Soup {
  std::vector<CgalPoint> points;
  std::vector<Polygon> polygons;
};

Soup to_soup(const TriangleMesh& mesh) {
  Soup soup;
  soup.points.reserve(mesh.vertices.size());
  for (const Vec3& p : mesh.vertices) soup.points.push_back(to_point(p));
  for (const Triangle& t : mesh.triangles) soup.polygons.push_back({t[0], t[1], t[2]});
  return soup;
}

CgalKernel::Vector_3 polygon_normal(const std::vector<CgalPoint>& points, const Polygon& p) {
  return CGAL::cross_product(points[p[1]] - points[p[0]], points[p[2]] - points[p[0]]);
}

CgalKernel::Vector_3 face_normal(const SurfaceMesh& surface, FaceIndex f) {
  const auto h = surface.halfedge(f);
  const CgalPoint& a = surface.point(surface.source(h));
  const CgalPoint& b = surface.point(surface.target(h));
  const CgalPoint& c = surface.point(surface.target(surface.next(h)));
  return CGAL::cross_product(b - a, c - a);
}

// Faces keep their index from soup to surface mesh until garbage collection, so each
// surviving face can be compared with the polygon it came from.
std::size_t count_reversed_faces(const SurfaceMesh& surface,
                                 const std::vector<CgalKernel::Vector_3>& original_normals) {
  std::size_t reversed = 0;
  for (FaceIndex f : surface.faces()) {
    const std::size_t i = static_cast<std::size_t>(f);
    if (i < original_normals.size() && face_normal(surface, f) * original_normals[i] < 0.0) {
      ++reversed;
    }
  }
  return reversed;
}

void repair_soup(Soup& soup, RepairReport& report) {
  const std::size_t points_before = soup.points.size();
  const std::size_t polygons_before = soup.polygons.size();
  PMP::repair_polygon_soup(soup.points, soup.polygons);
  if (soup.points.size() < points_before) {
    report.changes.push_back("removed " + counted(points_before - soup.points.size(),
                                                  "duplicate or unused vertex",
                                                  "duplicate or unused vertices"));
  }
  if (soup.polygons.size() < polygons_before) {
    report.changes.push_back("removed " + counted(polygons_before - soup.polygons.size(),
                                                  "duplicate or degenerate face",
                                                  "duplicate or degenerate faces"));
  }
  const std::size_t points_before_orient = soup.points.size();
  PMP::orient_polygon_soup(soup.points, soup.polygons);
  if (soup.points.size() > points_before_orient) {
    report.changes.push_back("split " + counted(soup.points.size() - points_before_orient,
                                                "non-manifold vertex", "non-manifold vertices"));
  }
}

std::size_t count_degenerate_faces(const SurfaceMesh& surface) {
  return static_cast<std::size_t>(
      std::count_if(surface.faces().begin(), surface.faces().end(),
                    [&](FaceIndex f) { return PMP::is_degenerate_triangle_face(f, surface); }));
}

void repair_surface(SurfaceMesh& surface, RepairReport& report) {
  const std::size_t stitched = PMP::stitch_borders(surface);
  if (stitched > 0) {
    report.changes.push_back("stitched " +
                             counted(stitched, "border edge pair", "border edge pairs"));
  }
  const std::size_t degenerate_before = count_degenerate_faces(surface);
  if (degenerate_before > 0) {
    PMP::remove_degenerate_faces(surface);
    const std::size_t degenerate_after = count_degenerate_faces(surface);
    if (degenerate_after < degenerate_before) {
      report.changes.push_back(
          "removed " +
          counted(degenerate_before - degenerate_after, "degenerate face", "degenerate faces") +
          " (edge collapses and flips)");
    }
  }
  if (!CGAL::is_closed(surface)) return;
  if (!PMP::does_self_intersect(surface)) {
    PMP::orient_to_bound_a_volume(surface);
  } else {
    PMP::orient(surface);  // outward per shell; nesting is unknowable while shells intersect
  }
}

}  // namespace

RepairReport repair_mesh(TriangleMesh& mesh) {
  RepairReport report;
  if (mesh.triangles.empty() || !indices_valid(mesh) ||
      !std::all_of(mesh.vertices.begin(), mesh.vertices.end(), all_finite)) {
    return report;  // nothing a repair could do; validation names the defect
  }
  Soup soup = to_soup(mesh);
  std::vector<CgalKernel::Vector_3> original_normals;
  repair_soup(soup, report);
  // The reference orientation is the input's: orient_polygon_soup may have flipped either side.
  Soup reference = to_soup(mesh);
  PMP::repair_polygon_soup(reference.points, reference.polygons);
  for (const Polygon& p : reference.polygons) {
    original_normals.push_back(polygon_normal(reference.points, p));
  }
  SurfaceMesh surface;
  PMP::polygon_soup_to_polygon_mesh(soup.points, soup.polygons, surface);
  repair_surface(surface, report);
  const std::size_t reversed = count_reversed_faces(surface, original_normals);
  if (reversed > 0) report.changes.push_back("reoriented " + counted(reversed, "face", "faces"));
  if (report.changes.empty()) return report;
  surface.collect_garbage();
  mesh = from_surface_mesh(surface);
  return report;
}

}  // namespace mneedle
