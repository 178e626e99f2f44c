#include "mneedle/fe/plane_strain_crack.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

constexpr double kPi = std::numbers::pi;

// Paper C §4: E 7 kPa, nu 0.475, w̄ 15 mm, r 4 mm, 640 mm block.
CrackOpeningProblem paper_case(double cells_across_slit = 300.0) {
  CrackOpeningProblem p;
  p.youngs_modulus_Pa = 7.0e3;
  p.poisson_ratio = 0.475;
  p.crack_width_m = 15e-3;
  p.needle_radius_m = 4e-3;
  p.block_size_m = 0.64;
  p.element_size_m = p.crack_width_m / cells_across_slit;
  return p;
}

// Paper C's value, and ours on a 4x finer mesh (w̄/1200, 56 689 nodes, traction-free edges,
// radial contact; measured separately: 73.368, 73.336, 73.312, 73.297, 73.289 mJ/m at w̄/75 ..
// w̄/1200, differences halving, so the limit is about 73.28 mJ/m).
constexpr double kPaperEnergy = 73.20e-3;
constexpr double kConvergedEnergy = 73.289e-3;

const CrackOpeningResult& paper_result() {
  static const CrackOpeningResult result = crack_opening_strain_energy(paper_case());
  return result;
}

TEST(PlaneStrainCrack, PressurisedSlitMatchesGriffithClosedForm) {
  // Uniform pressure p on a slit of half-width a in an infinite plane (plane strain):
  // opening 4 p (1 - nu^2) / E sqrt(a^2 - x^2), energy pi p^2 a^2 (1 - nu^2) / E.
  const CrackOpeningProblem p = paper_case(300.0);
  const double pressure = 100.0;
  const double a = 0.5 * p.crack_width_m;
  const double nu2 = 1.0 - p.poisson_ratio * p.poisson_ratio;
  const double exact_energy = kPi * pressure * pressure * a * a * nu2 / p.youngs_modulus_Pa;
  const double exact_opening = 4.0 * pressure * nu2 / p.youngs_modulus_Pa * a;
  double opening = 0.0;
  const double energy = pressurised_slit_strain_energy(p, pressure, &opening);
  // Measured energy errors -0.84, -0.42, -0.20, -0.089, -0.034 % at w̄/75 .. w̄/1200: first order
  // in h (the tip's sqrt singularity on a uniform mesh), the 640 mm block's own effect about
  // +0.06 % (-0.26 % at w̄/300 in a 1280 mm block). 0.4 % is twice the w̄/300 error: loose enough
  // for round-off and the block, tight enough that the w̄/150 mesh (-0.42 %) would fail it.
  EXPECT_NEAR(energy / exact_energy, 1.0, 4e-3);
  EXPECT_LT(energy, exact_energy);  // under load, a discretisation is too stiff
  // Centre opening: measured -0.09 % at w̄/300; 0.2 % is twice that.
  EXPECT_NEAR(opening / exact_opening, 1.0, 2e-3);
}

TEST(PlaneStrainCrack, EnergyScalesWithYoungsModulus) {
  // Linear elasticity with a geometric (displacement) constraint: the displacement field and the
  // contact set do not depend on E, the energy is proportional to it.
  CrackOpeningProblem p = paper_case(75.0);
  const CrackOpeningResult once = crack_opening_strain_energy(p);
  p.youngs_modulus_Pa *= 2.0;
  const CrackOpeningResult twice = crack_opening_strain_energy(p);
  EXPECT_EQ(twice.contact_nodes, once.contact_nodes);
  // Round-off of a direct solve of about 10^4 unknowns and 18 contact iterations.
  EXPECT_NEAR(twice.strain_energy_J_per_m / once.strain_energy_J_per_m, 2.0, 1e-9);
}

TEST(PlaneStrainCrack, PaperCaseStoresPublishedEnergy) {
  const CrackOpeningResult& r = paper_result();
  // Paper C §4: 73.20e-3 J/m. The 5 % band is the brief's; measured +0.15 % at w̄/300 and
  // +0.12 % at w̄/1200, nothing tuned.
  EXPECT_NEAR(r.strain_energy_J_per_m / kPaperEnergy, 1.0, 0.05);
  // Our own mesh-converged value (w̄/1200): the default mesh is within 0.03 % of it; 0.1 %
  // leaves room for round-off in the contact set.
  EXPECT_NEAR(r.strain_energy_J_per_m / kConvergedEnergy, 1.0, 1e-3);
}

TEST(PlaneStrainCrack, EnergyConvergesMonotonicallyWithMesh) {
  const double coarse = crack_opening_strain_energy(paper_case(75.0)).strain_energy_J_per_m;
  const double middle = crack_opening_strain_energy(paper_case(150.0)).strain_energy_J_per_m;
  const double fine = paper_result().strain_energy_J_per_m;
  // Displacement-driven: a coarser mesh is stiffer and stores more.
  EXPECT_GT(coarse, middle);
  EXPECT_GT(middle, fine);
  // Measured 0.034 % between w̄/150 and w̄/300; 0.1 % allows for a different factorisation order.
  EXPECT_NEAR(middle / fine, 1.0, 1e-3);
}

TEST(PlaneStrainCrack, OuterEdgesBarelyMatterInThePapersBlock) {
  CrackOpeningProblem p = paper_case(75.0);
  const double free_edges = crack_opening_strain_energy(p).strain_energy_J_per_m;
  p.outer_edges = OuterEdges::Pinned;
  const double pinned = crack_opening_strain_energy(p).strain_energy_J_per_m;
  // Pinned edges stiffen the block: measured +0.37 % at w̄/300 (the infinite plane lies between,
  // about +0.05 % above the traction-free value by extrapolation in 1/L^2 from a 1280 mm block).
  EXPECT_GT(pinned, free_edges);
  EXPECT_LT(pinned / free_edges - 1.0, 5e-3);
}

TEST(PlaneStrainCrack, FaceStaysOutsideNeedleAndTouchesItOnlyWithinItsRadius) {
  const CrackOpeningProblem p = paper_case();
  const CrackOpeningResult& r = paper_result();
  EXPECT_GT(r.contact_nodes, 0);
  EXPECT_LT(r.contact_extent_m, p.needle_radius_m);
  // Radial contact holds each contact node on the exact circle: the penetration left is the
  // normal iteration's tolerance (1e-10) times r, measured ~1e-18 m.
  EXPECT_LE(r.max_penetration_m, 1e-9 * p.needle_radius_m);
  // The face does not cross its mirror image (the slit's lower face).
  EXPECT_GT(r.min_face_opening_m, 0.0);
  EXPECT_GT(r.active_set_iterations, 1);
}

TEST(PlaneStrainCrack, VerticalGapReportsItsPenetration) {
  // The linearised vertical gap ignores the nodes' sliding in x: the deformed face ends inside
  // the circle (measured 82 um = 2 % of r at w̄/300) and stores more energy (+4.7 %).
  CrackOpeningProblem p = paper_case(75.0);
  p.contact_gap = CrackContactGap::Vertical;
  const CrackOpeningResult vertical = crack_opening_strain_energy(p);
  p.contact_gap = CrackContactGap::Radial;
  const CrackOpeningResult radial = crack_opening_strain_energy(p);
  EXPECT_GT(vertical.max_penetration_m, 0.005 * p.needle_radius_m);
  EXPECT_LT(vertical.max_penetration_m, 0.05 * p.needle_radius_m);
  EXPECT_GT(vertical.strain_energy_J_per_m, radial.strain_energy_J_per_m);
}

void expect_input_error(const std::function<void(CrackOpeningProblem&)>& spoil,
                        const std::string& field) {
  CrackOpeningProblem p = paper_case(75.0);
  spoil(p);
  try {
    crack_opening_strain_energy(p);
    ADD_FAILURE() << "no InputError for " << field;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
  }
}

TEST(PlaneStrainCrack, BadInputNamesTheField) {
  expect_input_error([](auto& p) { p.youngs_modulus_Pa = 0.0; }, "youngs_modulus_Pa");
  expect_input_error([](auto& p) { p.youngs_modulus_Pa = NAN; }, "youngs_modulus_Pa");
  expect_input_error([](auto& p) { p.youngs_modulus_Pa = INFINITY; }, "youngs_modulus_Pa");
  expect_input_error([](auto& p) { p.poisson_ratio = 0.5; }, "poisson_ratio");
  expect_input_error([](auto& p) { p.poisson_ratio = -0.1; }, "poisson_ratio");
  expect_input_error([](auto& p) { p.crack_width_m = 0.0; }, "crack_width_m");
  expect_input_error([](auto& p) { p.needle_radius_m = 0.0; }, "needle_radius_m");
  // A needle as wide as the slit would have to extend the crack.
  expect_input_error([](auto& p) { p.needle_radius_m = 7.5e-3; }, "needle_radius_m");
  expect_input_error([](auto& p) { p.block_size_m = 0.1; }, "block_size_m");
  expect_input_error([](auto& p) { p.element_size_m = -1e-4; }, "element_size_m");
  expect_input_error([](auto& p) { p.element_size_m = 5e-3; }, "element_size_m");
  // Rejected before any allocation: about 10^9 nodes.
  expect_input_error([](auto& p) { p.element_size_m = 1e-7; }, "element_size_m");
  expect_input_error([](auto& p) { p.element_size_m = 1e-15; }, "element_size_m");
  EXPECT_THROW(pressurised_slit_strain_energy(paper_case(75.0), NAN), InputError);
}

}  // namespace
}  // namespace mneedle::fe
