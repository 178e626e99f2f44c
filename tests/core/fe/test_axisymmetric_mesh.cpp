#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "mneedle/base/error.h"
#include "mneedle/fe/axisymmetric.h"

namespace mneedle::fe {
namespace {

MaterialParameters material(MaterialModel model, double E, double nu) {
  MaterialParameters p;
  p.model = model;
  p.E = E;
  p.nu = nu;
  return p;
}

TEST(AxisymmetricMesh, LayersConformAndGradingCoarsensOutward) {
  AxisymmetricMeshOptions o;
  o.radius_m = 1e-3;
  o.h_m = 1e-5;
  o.fine_radius_m = 5e-5;
  o.fine_depth_m = 5e-5;
  o.growth = 1.3;
  const std::vector<AxisymmetricLayer> layers{{15e-6, material(MaterialModel::Linear, 1e9, 0.4)},
                                              {985e-6, material(MaterialModel::Linear, 1e5, 0.4)}};
  const AxisymmetricMesh mesh = make_axisymmetric_mesh(layers, o);
  bool interface_row = false;
  for (const Eigen::Vector2d& x : mesh.nodes) interface_row |= std::abs(x.y() + 15e-6) < 1e-12;
  EXPECT_TRUE(interface_row);
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const double zc = (mesh.nodes[mesh.elements[e][0]].y() + mesh.nodes[mesh.elements[e][1]].y() +
                       mesh.nodes[mesh.elements[e][2]].y()) /
                      3.0;
    EXPECT_EQ(mesh.element_layer[e], zc > -15e-6 ? 0 : 1);
  }
  const auto& s = mesh.surface_nodes;
  EXPECT_LT(mesh.nodes[s[2]].x() - mesh.nodes[s[0]].x(),
            mesh.nodes[s[s.size() - 1]].x() - mesh.nodes[s[s.size() - 3]].x());
  EXPECT_GT(mesh.min_angle_deg, 0.5);
}

TEST(AxisymmetricMesh, EveryElementIsCounterClockwiseAndLayerBoundariesAreClamped) {
  AxisymmetricMeshOptions o;
  o.radius_m = 2e-3;
  o.h_m = 2e-5;
  o.fine_radius_m = 1e-4;
  o.fine_depth_m = 2e-4;
  const AxisymmetricMesh mesh =
      make_axisymmetric_mesh({{1e-3, material(MaterialModel::Linear, 1e5, 0.4)}}, o);
  for (const auto& e : mesh.elements) {
    const Eigen::Vector2d a = mesh.nodes[e[1]] - mesh.nodes[e[0]];
    const Eigen::Vector2d b = mesh.nodes[e[2]] - mesh.nodes[e[0]];
    EXPECT_GT(a.x() * b.y() - a.y() * b.x(), 0.0);
    // Mid-edge node 4 halfway between corners 1 and 2 (straight-sided elements).
    EXPECT_LT((mesh.nodes[e[3]] - 0.5 * (mesh.nodes[e[0]] + mesh.nodes[e[1]])).norm(), 1e-15);
  }
  for (std::uint32_t n : mesh.fixed_nodes) {
    const Eigen::Vector2d x = mesh.nodes[n];
    EXPECT_TRUE(std::abs(x.y() + 1e-3) < 1e-15 || std::abs(x.x() - 2e-3) < 1e-15);
  }
  for (std::uint32_t n : mesh.surface_nodes) EXPECT_EQ(mesh.nodes[n].y(), 0.0);
}

// A depth break a round-off away from the end of the fine zone (a crack depth computed as 2 a
// where the fine zone ends at a + a) is the same row, not a row of zero height.
TEST(AxisymmetricMesh, DepthBreakWithinRoundOffOfTheFineZoneEndAddsNoSliverRow) {
  AxisymmetricMeshOptions o;
  o.radius_m = 2e-3;
  o.h_m = 2e-5;
  o.fine_radius_m = 2.3e-4;
  o.fine_depth_m = 115e-6 + 115e-6;
  o.depth_breaks_m = {std::nextafter(o.fine_depth_m, 1.0)};
  const AxisymmetricMesh mesh =
      make_axisymmetric_mesh({{1e-3, material(MaterialModel::Linear, 1e5, 0.4)}}, o);
  EXPECT_GT(mesh.min_angle_deg, 1.0);
  for (const auto& e : mesh.elements) {
    const Eigen::Vector2d a = mesh.nodes[e[1]] - mesh.nodes[e[0]];
    const Eigen::Vector2d b = mesh.nodes[e[2]] - mesh.nodes[e[0]];
    ASSERT_GT(a.x() * b.y() - a.y() * b.x(), 1e-6 * o.h_m * o.h_m);
  }
}

// The cohesive ring's band: 2 um cells at r = 100 um down to 200 um, the mesh's own 10 um
// elsewhere in the fine zone, graded in between by the growth (1.3: 2, 2.6, 3.38, ... up to 10).
TEST(AxisymmetricMesh, ABandRefinesTheCellsAlongItsColumnOnly) {
  AxisymmetricMeshOptions o;
  o.radius_m = 2e-3;
  o.h_m = 10e-6;
  o.fine_radius_m = 150e-6;
  o.fine_depth_m = 200e-6;
  o.growth = 1.3;
  o.radial_breaks_m = {100e-6};
  o.depth_breaks_m = {200e-6};
  o.band_radius_m = 100e-6;
  o.band_size_m = 2e-6;
  o.band_depth_m = 200e-6;
  const AxisymmetricMesh mesh =
      make_axisymmetric_mesh({{2e-3, material(MaterialModel::Linear, 1e5, 0.45)}}, o);
  // Corner columns on the surface (every second surface node: quadratic edges).
  std::vector<double> r;
  for (std::size_t k = 0; k < mesh.surface_nodes.size(); k += 2)
    r.push_back(mesh.nodes[mesh.surface_nodes[k]].x());
  const auto ring =
      std::find_if(r.begin(), r.end(), [](double x) { return std::abs(x - 100e-6) < 1e-15; });
  ASSERT_NE(ring, r.end());
  const std::size_t i = static_cast<std::size_t>(ring - r.begin());
  EXPECT_NEAR(r[i + 1] - r[i], 2e-6, 1e-12);  // the band on either side
  EXPECT_NEAR(r[i] - r[i - 1], 2e-6, 1e-12);
  EXPECT_NEAR(r[i + 2] - r[i + 1], 2.6e-6, 1e-12);  // graded by 1.3
  EXPECT_NEAR(r[i - 1] - r[i - 2], 2.6e-6, 1e-12);
  // The mesh's own at the axis: 35.2 um of grading leaves 64.8 um in 7 cells of 9.26 um.
  EXPECT_NEAR(r[1] - r[0], 64.8e-6 / 7, 0.01e-6);
  // Rows 2 um apart down the band (100 of them to 200 um), then coarser.
  std::vector<double> depth;
  for (const Eigen::Vector2d& x : mesh.nodes)
    if (x.x() == 0.0) depth.push_back(-x.y());
  std::sort(depth.begin(), depth.end());
  const auto rows_above =
      std::count_if(depth.begin(), depth.end(), [](double d) { return d < 200e-6 - 1e-12; });
  EXPECT_EQ(rows_above, 200);  // corners and mid-edge nodes of 100 rows of 2 um
  // Within the fine zone the band's 2 um rows meet columns of at most 10 um: no corner below
  // atan(2 / 10), 11.3 degrees. (Outside it a tensor grid's fine rows and columns meet coarse
  // ones in slivers, band or not: the band's 2 um columns run down to the bottom.)
  double smallest = 180.0;
  for (const auto& e : mesh.elements) {
    const Eigen::Vector2d p[3] = {mesh.nodes[e[0]], mesh.nodes[e[1]], mesh.nodes[e[2]]};
    if (std::max({p[0].x(), p[1].x(), p[2].x()}) > 150e-6 + 1e-12 ||
        std::min({p[0].y(), p[1].y(), p[2].y()}) < -200e-6 - 1e-12)
      continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2d u = p[(k + 1) % 3] - p[k], v = p[(k + 2) % 3] - p[k];
      smallest = std::min(smallest, std::acos(u.dot(v) / (u.norm() * v.norm())) * 180.0 / M_PI);
    }
  }
  EXPECT_GE(smallest, 11.3 - 1e-9);
}

TEST(AxisymmetricMesh, RejectsEmptyLayersAndBadSizes) {
  AxisymmetricMeshOptions o;
  o.radius_m = 1e-3;
  o.h_m = 1e-4;
  EXPECT_THROW(make_axisymmetric_mesh({}, o), InputError);
  o.h_m = 0.0;
  EXPECT_THROW(make_axisymmetric_mesh({{1e-3, material(MaterialModel::Linear, 1e5, 0.4)}}, o),
               InputError);
}

TEST(AxisymmetricNeedle, ConeProfileGivesHeightAtWhichEachRadiusIsReached) {
  const AxisymmetricNeedle cone = AxisymmetricNeedle::cone(std::atan(0.5), 1e-4);
  EXPECT_DOUBLE_EQ(cone.lowest_height_at(0.0), 0.0);
  EXPECT_NEAR(cone.lowest_height_at(5e-5), 1e-4, 1e-15);
  EXPECT_EQ(cone.lowest_height_at(2e-4), std::numeric_limits<double>::infinity());
  const AxisymmetricNeedle hollow = AxisymmetricNeedle::flat_punch(1e-4, 4e-5);
  EXPECT_EQ(hollow.lowest_height_at(2e-5), std::numeric_limits<double>::infinity());
  EXPECT_DOUBLE_EQ(hollow.lowest_height_at(6e-5), 0.0);
}

}  // namespace
}  // namespace mneedle::fe
