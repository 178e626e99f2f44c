#pragma once
// PRIVATE to mneedle::core: the contact traction on the tissue surface recovered from nodal
// contact forces (docs/model.md, "Contact pressure in the field output"). The nodal forces f of a
// FE solution are the traction t weighted by the shape functions, f_i = Σ_faces ∫ N_i t dA; the
// traction field t_h = Σ N_j t_j that reproduces them solves M t = f with the surface "mass"
// matrix M_ij = ∫ N_i N_j dA (an L2 projection, as mortar methods recover contact pressure). By
// the partition of unity ∫ t_h dA = Σ f exactly, so the recovered traction carries the force.

#include <Eigen/Core>
#include <array>
#include <vector>

namespace mneedle::fe {

/// Faces are 3-node (linear) or 6-node (corners, then mid-edges 0-1, 1-2, 2-0) triangles given by
/// node indices into `points`; faces_nodes is 3 or 6. Returns the traction per point (Pa; zero at
/// points of no face). Each face is integrated as the flat triangle of its corners, with the
/// exact mass matrix of its shape functions. Throws SolverError when M cannot be factorised
/// (a face of zero area).
std::vector<Eigen::Vector3d> recover_traction(const std::vector<Eigen::Vector3d>& points,
                                              const std::vector<std::array<int, 6>>& faces,
                                              int face_nodes,
                                              const std::vector<Eigen::Vector3d>& nodal_force);

/// Unit normal of each point: the area-weighted mean of the normals of its faces at `points`
/// (current positions), each oriented as its face's normal at `reference` points +z (the top
/// faces' outward normal before the needle pushed them, so a face tilted past vertical under a
/// tip keeps its side); zero at points of no face.
std::vector<Eigen::Vector3d> face_normals_at_points(const std::vector<Eigen::Vector3d>& points,
                                                    const std::vector<Eigen::Vector3d>& reference,
                                                    const std::vector<std::array<int, 6>>& faces,
                                                    int face_nodes);

}  // namespace mneedle::fe
