#include <gtest/gtest.h>

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
