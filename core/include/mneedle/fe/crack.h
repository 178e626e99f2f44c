#pragma once
// Cracked copies of a tissue mesh, for the energy puncture criterion: the energy release rate is
// G = (U_intact - U_cracked) / crack area at the same needle position (paper A eq. 12 read as
// Griffith's criterion at fixed displacement; docs/model.md).

#include <Eigen/Core>
#include <vector>

#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

/// A planar crack through a needle's axis: the half-disc of radius `depth_m` below `origin_m`
/// (a point on the undeformed surface z = 0, reference coordinates) in the plane through
/// `origin_m` with normal `normal` (horizontal).
struct PlanarCrack {
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitX();
  double depth_m = 0.0;
};

/// The mesh with the faces inside the crack opened: nodes on the crack's interior are doubled,
/// one copy per side (nodes on the crack front stay shared). `area_m2` receives the area of the
/// faces opened (one side). The copies are appended after the original nodes, whose indices do
/// not change; `original_node`, when given, receives for every node of the result its node in
/// `mesh`. Throws InputError when no mesh face lies on the crack's plane there.
TetMesh crack_mesh(const TetMesh& mesh, const PlanarCrack& crack, double* area_m2,
                   std::vector<int>* original_node = nullptr);

/// Where the energy criterion opens a needle's crack (normal x): under its first contact point
/// `tip_m` (x, y on the surface; a bevel's tip) when the mesh has the grid plane x = tip x,
/// otherwise through its axis `axis_m`. A crack through a bevel's axis lies a radius away from
/// the load and releases almost nothing.
Eigen::Vector3d crack_origin_under(const TetMesh& mesh, const Eigen::Vector2d& axis_m,
                                   const Eigen::Vector2d& tip_m);

}  // namespace mneedle::fe
