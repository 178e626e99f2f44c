// STL input with slivers and near-degenerate faces (tests/assets/meshes/extreme_*.stl, made by
// extreme_make_meshes.py): every path from the file to a number either gives finite, right
// numbers or stops with a one-line error.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/geometry/surface_report.h"
#include "mneedle/insertion/analytic_indentation.h"
#include "mneedle/needle/mesh_io.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/strength/section_table.h"

namespace mneedle {
namespace {

using std::numbers::pi;

constexpr double kRadius = 0.115e-3, kLength = 1e-3;

std::string asset(const char* name) {
  return std::string(MNEEDLE_TEST_ASSETS) + "/meshes/" + name;
}

// The 32-gon cone's volume: (1/3) * polygon area * length.
double cone_volume() {
  return kLength / 3.0 * 0.5 * 32 * kRadius * kRadius * std::sin(2 * pi / 32);
}

Tissue skin_like() {
  Tissue t;
  t.size = {3e-3, 3e-3, 1.15e-3};
  TissueLayer top;
  top.name = "top";
  top.thickness = 0.12e-3;
  top.material.youngs_modulus = 0.2e6;
  top.material.poisson_ratio = 0.45;
  TissueLayer base = top;
  base.name = "base";
  base.thickness = 1.03e-3;
  base.material.youngs_modulus = 0.08e6;
  t.layers = {top, base};
  return t;
}

// Numbers a user gets from this mesh: volume, surface groups, tip areas, sections, analytic force.
void expect_finite_and_right(TriangleMesh mesh, const char* what) {
  EXPECT_NEAR(signed_volume(mesh) / cone_volume(), 1.0, 1e-5) << what;
  place_in_needle_frame(mesh, Vec3{0.0, 0.0, -1.0});
  const SurfaceReport report = surface_report(mesh);
  for (const TipAreaPoint& p : report.tip_area) {
    EXPECT_TRUE(std::isfinite(p.area_m2) && p.area_m2 >= 0.0) << what;
  }
  const SectionTable table = SectionTable::from_mesh(mesh, 50);
  const double h = 0.5 * kLength;
  const double ring = kRadius * h / kLength;  // the polygon's circumradius at h
  EXPECT_NEAR(table.at(h).area_m2 / (0.5 * 32 * ring * ring * std::sin(2 * pi / 32)), 1.0, 1e-3)
      << what;
  const auto needle = equivalent_axisymmetric_needle(mesh, 0.5e-3, 50);
  const auto steps = analytic_indentation(skin_like(), needle, {1e-9, 50e-6, 200e-6});
  for (const AnalyticStep& s : steps) {
    EXPECT_TRUE(std::isfinite(s.force_N) && s.force_N >= 0.0) << what;
    EXPECT_TRUE(std::isfinite(s.contact_pressure_Pa)) << what;
  }
  EXPECT_GT(steps.back().force_N, steps[1].force_N) << what;
}

TEST(ExtremeStl, SliverFacesLoadValidateAndGiveFiniteNumbers) {
  TriangleMesh mesh = load_mesh(asset("extreme_sliver_cone.stl"), 1e-3);
  EXPECT_EQ(mesh.triangles.size(), 128u);
  const MeshValidation v = validate_mesh(mesh);
  // Slivers of non-zero area are legal geometry: the mesh must pass, not be "repaired".
  EXPECT_TRUE(v.valid) << (v.errors.empty() ? "" : v.errors.front());
  expect_finite_and_right(mesh, "sliver cone");
}

TEST(ExtremeStl, NearDegenerateFacesAreEitherValidOrRepairedToAValidMesh) {
  TriangleMesh mesh = load_mesh(asset("extreme_near_degenerate.stl"), 1e-3);
  EXPECT_EQ(mesh.triangles.size(), 128u);
  MeshValidation v = validate_mesh(mesh);
  if (!v.valid) {
    // Reported with a count, then repairable (edge collapses) without changing the solid.
    ASSERT_FALSE(v.errors.empty());
    repair_mesh(mesh);
    v = validate_mesh(mesh);
  }
  ASSERT_TRUE(v.valid) << (v.errors.empty() ? "" : v.errors.front());
  expect_finite_and_right(mesh, "near-degenerate cone");
}

TEST(ExtremeStl, CollapsedToALineIsRefusedWithAMessage) {
  // The near-degenerate cone squashed flat in y (all y = 0): zero volume, every face degenerate.
  TriangleMesh mesh = load_mesh(asset("extreme_near_degenerate.stl"), 1e-3);
  for (Vec3& p : mesh.vertices) p[1] = 0.0;
  const MeshValidation v = validate_mesh(mesh);
  EXPECT_FALSE(v.valid);
  EXPECT_THROW(require_valid_mesh(mesh, "squashed.stl"), InputError);
}

}  // namespace
}  // namespace mneedle
