#pragma once
// The stress puncture criterion's measure: the maximum principal stress in one layer near a
// point, averaged over a material length so that it converges under a sharp tip where the
// pointwise stress is singular.

#include <Eigen/Core>
#include <vector>

#include "mneedle/fe/tissue_mesh.h"

namespace mneedle::fe {

/// Volume-weighted mean of the maximum principal Cauchy stress (Pa) over the part of `layer`
/// within `length_m` of `point_m` (reference coordinates), at nodal displacement `u` (3 per node,
/// m). Returns 0 when no part of the layer is within reach.
double averaged_max_principal_stress(const TetMesh& mesh, const Eigen::VectorXd& u,
                                     const Eigen::Vector3d& point_m, double length_m, int layer);

/// The stress criterion's measure (docs/model.md, "Criteria", stress): per site, the largest
/// over centres of the layer's maximum principal stress averaged over the part of `layer` within
/// `length_m` of the centre (the volume method of the theory of critical distances). The centres
/// are the layer's nodes within a search radius (horizontal distance) of the site, so the probe
/// finds the tensile peak wherever the layer has it (under a point load on a stiff layer, its
/// underside), not only at one chosen point. Built once per mesh for the largest search radius
/// of each site; peak() per displacement, with the radii of that moment.
/// Each element near a site is split into 64 equal sub-tetrahedra, each carrying the stress at
/// its centroid and weighed by its volume inside each ball (found once, at construction, by
/// splitting the sub-tetrahedra the ball's surface cuts; docs/model.md, "Tip stress").
class PeakStressProbe {
 public:
  /// `sites_xy` (m, reference) with the largest search radius of each; centres deeper than
  /// `search_depth_m` below the surface are not searched (the stress that breaks the layer is
  /// near the needle; the bound keeps the probe's nodes few in a thick layer). On a half or
  /// quarter model (mesh.mirror_y0, mirror_x0) each ball also holds the mirror image of the
  /// meshed part, as in the whole block. Throws InputError on a bad length, radius, depth or
  /// layer.
  PeakStressProbe(const TetMesh& mesh, std::vector<Eigen::Vector2d> sites_xy,
                  std::vector<double> search_radius_m, double search_depth_m, double length_m,
                  int layer);

  /// Per site: the peak averaged maximum principal stress (Pa) at nodal displacement `u`
  /// (3 per node, m) over the centres within `search_radius_m` of it (each at most the
  /// constructor's: InputError otherwise); 0 where no centre lies within reach.
  std::vector<double> peak(const Eigen::VectorXd& u,
                           const std::vector<double>& search_radius_m) const;
  /// The nodes whose displacement peak() reads (those of the elements within reach), ascending:
  /// the other entries of `u` may be anything.
  const std::vector<int>& nodes() const { return nodes_; }
  /// The centres (reference positions, m) and the volume of the layer each one's ball holds
  /// (m^3; 4/3 pi L^3 for a ball wholly inside the layer, to the weighting's error).
  std::vector<Eigen::Vector3d> centres() const;
  std::vector<double> ball_volumes() const;

 private:
  struct SubPoint {
    Eigen::Vector3d x;  // reference position of the sub-tetrahedron's centroid
    double volume;
    int element;
    int sub;  // index into the subdivision's centroids
  };
  struct Candidate {
    Eigen::Vector3d x;
    int site;
    double distance;  // horizontal, to the site
  };
  const TetMesh* mesh_;
  double length_;
  int layer_;
  std::size_t site_count_;
  std::vector<int> elements_;  // the layer's elements within reach of a site
  std::vector<int> nodes_;     // their nodes, ascending
  std::vector<SubPoint> points_;
  std::vector<std::size_t> piece_start_;  // elements_[k]'s pieces: points_[start[k], start[k + 1])
  std::vector<double> search_radius_;     // the constructor's, per site
  std::vector<Candidate> candidates_;
  // Each candidate's ball (compressed rows): the sub-points it holds, with the volume of each
  // (or of its mirror image) inside it; a sub-point may appear twice through its image.
  std::vector<std::size_t> ball_start_;
  std::vector<int> ball_source_;
  std::vector<double> ball_volume_;
};

}  // namespace mneedle::fe
