#include "fe/mirror_planes.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

#include "fe/needle_shape.h"
#include "mneedle/base/error.h"
#include "mneedle/needle/mesh.h"

namespace mneedle::fe {

namespace {

bool same_mesh(const TriangleMesh& a, const TriangleMesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles;
}

std::string position_of(const Needle3d& n) {
  std::ostringstream s;
  s << std::setprecision(6) << "(" << n.x * 1e6 << ", " << n.y * 1e6 << ") um";
  return s.str();
}

// The needle at `position` with the same mesh as `needle`; npos-like size() when there is none.
std::size_t needle_at(const std::vector<Needle3d>& needles, const Needle3d& needle,
                      const Eigen::Vector2d& position) {
  for (std::size_t k = 0; k < needles.size(); ++k)
    if (needles[k].x == position.x() && needles[k].y == position.y() &&
        same_mesh(needles[k].mesh, needle.mesh))
      return k;
  return needles.size();
}

double mesh_size(const TriangleMesh& mesh) {
  const BoundingBox box = bounding_box(mesh);
  return std::hypot(box.max[0] - box.min[0], box.max[1] - box.min[1], box.max[2] - box.min[2]);
}

void check_plane(const std::vector<Needle3d>& needles, bool across_x) {
  const std::string plane = across_x ? "x = 0" : "y = 0";
  for (const Needle3d& n : needles) {
    const std::string where =
        "3-D mirror plane " + plane + ": needle '" + n.name + "' at " + position_of(n);
    const Eigen::Vector2d image =
        across_x ? Eigen::Vector2d(-n.x, n.y) : Eigen::Vector2d(n.x, -n.y);
    if (needle_at(needles, n, image) == needles.size())
      throw InputError(where + " has no needle of the same mesh at its mirror image " +
                       "(use the full model)");
    const NeedleShape shape(n.mesh);
    const double tolerance = 1e-6 * mesh_size(n.mesh) + 1e-12;
    const bool symmetric =
        across_x ? shape.mirror_symmetric_x(tolerance) : shape.mirror_symmetric_y(tolerance);
    if (!symmetric)
      throw InputError(where + " is not symmetric about its own " + plane +
                       " plane (use the full model)");
  }
}

}  // namespace

MirrorSelection select_mirrored_part(const std::vector<Needle3d>& needles, bool mirror_x,
                                     bool mirror_y) {
  if (mirror_x) check_plane(needles, true);
  if (mirror_y) check_plane(needles, false);
  MirrorSelection selection;
  std::vector<std::size_t> kept_index(needles.size(), needles.size());
  for (std::size_t i = 0; i < needles.size(); ++i)
    if ((!mirror_x || needles[i].x >= 0.0) && (!mirror_y || needles[i].y >= 0.0)) {
      kept_index[i] = selection.kept.size();
      selection.kept.push_back(needles[i]);
      selection.kept_from.push_back(i);
    }
  for (const Needle3d& n : needles) {
    const bool flip_x = mirror_x && n.x < 0.0, flip_y = mirror_y && n.y < 0.0;
    const Eigen::Vector2d image(flip_x ? -n.x : n.x, flip_y ? -n.y : n.y);
    // check_plane found an image for each plane alone, so the image across both exists too.
    selection.source.push_back(kept_index[needle_at(needles, n, image)]);
    selection.lateral_sign.emplace_back(flip_x ? -1.0 : 1.0, flip_y ? -1.0 : 1.0);
  }
  return selection;
}

Step3d whole_scene_step(const Step3d& reduced, const MirrorSelection& selection,
                        const std::vector<Needle3d>& needles) {
  Step3d whole = reduced;
  whole.needles.clear();
  for (std::size_t i = 0; i < needles.size(); ++i) {
    NeedleStep3d n = reduced.needles[selection.source[i]];
    n.name = needles[i].name;
    n.lateral_force_N[0] *= selection.lateral_sign[i].x();
    n.lateral_force_N[1] *= selection.lateral_sign[i].y();
    whole.needles.push_back(n);
  }
  return whole;
}

}  // namespace mneedle::fe
