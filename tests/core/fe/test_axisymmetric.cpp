#include "mneedle/fe/axisymmetric.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle::fe {
namespace {

constexpr double kPi = 3.14159265358979323846;

MaterialParameters material(MaterialModel model, double E, double nu) {
  MaterialParameters p;
  p.model = model;
  p.E = E;
  p.nu = nu;
  return p;
}

std::vector<AxisymmetricLayer> one_layer(double thickness, const MaterialParameters& m) {
  return {AxisymmetricLayer{thickness, m}};
}

// Prescribes u_r = a r, u_z = b z on the whole boundary of a two-layer cylinder.
void expect_patch_reproduced(MaterialModel model, double a, double b) {
  const MaterialParameters m = material(model, 1.0e5, 0.3);
  std::vector<AxisymmetricLayer> layers{{3e-4, m}, {7e-4, material(model, 3.0e5, 0.45)}};
  // Two materials: a homogeneous strain is still an exact solution only if the stresses match
  // across the interface, so keep one material for the patch test proper.
  layers[1].material = m;
  AxisymmetricMeshOptions o;
  o.radius_m = 1e-3;
  o.h_m = 1.5e-4;
  o.fine_radius_m = 3e-4;
  o.fine_depth_m = 3e-4;
  o.growth = 1.4;
  AxisymmetricModel fe(make_axisymmetric_mesh(layers, o), {m, m});
  const AxisymmetricMesh& mesh = fe.mesh();
  auto exact = [&](std::uint32_t node, int component) {
    const Eigen::Vector2d X = mesh.nodes[node];
    return component == 0 ? a * X.x() : b * X.y();
  };
  std::vector<std::uint32_t> dofs;
  std::vector<double> values;
  std::vector<char> on_boundary(mesh.nodes.size(), 0);
  for (const auto* set : {&mesh.fixed_nodes, &mesh.surface_nodes})
    for (std::uint32_t node : *set) on_boundary[node] = 1;
  for (std::uint32_t node : mesh.axis_nodes) {
    if (!on_boundary[node]) {
      dofs.push_back(2 * node);
      values.push_back(0.0);
    }
  }
  for (std::uint32_t node = 0; node < mesh.nodes.size(); ++node) {
    if (!on_boundary[node]) continue;
    for (int c = 0; c < 2; ++c) {
      dofs.push_back(2 * node + c);
      values.push_back(exact(node, c));
    }
  }
  const Equilibrium eq =
      fe.solve(dofs, Eigen::Map<const Eigen::VectorXd>(values.data(), values.size()),
               Eigen::VectorXd::Zero(fe.dof_count()));
  double worst = 0.0;
  for (std::uint32_t node = 0; node < mesh.nodes.size(); ++node)
    for (int c = 0; c < 2; ++c)
      worst = std::max(worst, std::abs(eq.displacement[2 * node + c] - exact(node, c)));
  // Interior displacements of order 1e-5 m (linear) to 1e-4 m: exact up to solver round-off.
  EXPECT_LT(worst, 1e-9 * std::max(std::abs(a), std::abs(b)) * 1e-3);
}

TEST(AxisymmetricPatch, LinearMaterialReproducesHomogeneousStrain) {
  expect_patch_reproduced(MaterialModel::Linear, 1e-3, -2e-3);
}

TEST(AxisymmetricPatch, NeoHookeanReproducesLargeHomogeneousStretch) {
  expect_patch_reproduced(MaterialModel::NeoHookean, 0.08, -0.15);
}

TEST(AxisymmetricPatch, MooneyRivlinReproducesLargeHomogeneousStretch) {
  expect_patch_reproduced(MaterialModel::MooneyRivlin, -0.05, 0.1);
}

// A 1 mm cylinder of elements h in its fine 0.5 mm corner: the model checks' small mesh.
AxisymmetricMeshOptions small_mesh(double h) {
  AxisymmetricMeshOptions o;
  o.radius_m = 1e-3;
  o.h_m = h;
  o.fine_radius_m = 5e-4;
  o.fine_depth_m = 5e-4;
  return o;
}

TEST(AxisymmetricModel, TangentMatchesFiniteDifferenceOfInternalForce) {
  const MaterialParameters m = material(MaterialModel::NeoHookean, 1e5, 0.45);
  const AxisymmetricMeshOptions o = small_mesh(2.5e-4);
  AxisymmetricModel fe(make_axisymmetric_mesh(one_layer(1e-3, m), o), {m});
  Eigen::VectorXd u = Eigen::VectorXd::Random(fe.dof_count()) * 2e-5;
  Eigen::SparseMatrix<double> K;
  fe.internal_force(u, nullptr, &K);
  const Eigen::VectorXd v = Eigen::VectorXd::Random(fe.dof_count()) * 1e-5;
  const double h = 1e-4;
  const Eigen::VectorXd numeric = (fe.internal_force(u + h * v, nullptr, nullptr) -
                                   fe.internal_force(u - h * v, nullptr, nullptr)) /
                                  (2 * h);
  const Eigen::VectorXd analytic = K * v;
  // Central difference on a smooth force: truncation ~ (h |v|/L)^2, far below 1e-6.
  EXPECT_LT((numeric - analytic).norm(), 1e-6 * analytic.norm());
}

// A ring crack's face pairs (docs/model.md, "Crack faces in contact"): a closed pair adds
// t = lambda + k g to the outer node's radial force and -t to the inner one, an open pair nothing,
// the tangent stays the derivative of the force, and the strain energy leaves the pairs out.
TEST(AxisymmetricModel, ClosedFacePairsPushTheirNodesApartAndOpenOnesCarryNothing) {
  const MaterialParameters m = material(MaterialModel::NeoHookean, 1e5, 0.45);
  AxisymmetricMeshOptions o = small_mesh(1e-4);
  o.radial_breaks_m = {2e-4};
  o.depth_breaks_m = {2e-4};
  std::vector<std::array<std::uint32_t, 2>> pairs;
  AxisymmetricModel fe(crack_axisymmetric_mesh(make_axisymmetric_mesh(one_layer(1e-3, m), o), 2e-4,
                                               2e-4, nullptr, &pairs),
                       {m});
  ASSERT_EQ(pairs.size(), 4u);
  EXPECT_THROW(fe.set_face_pairs({{0, static_cast<std::uint32_t>(fe.mesh().nodes.size())}}),
               InputError);
  fe.set_face_pairs(pairs);
  const Eigen::VectorXd k = fe.pair_penalties();
  ASSERT_EQ(k.size(), 4);
  EXPECT_GT(k.minCoeff(), 0.0);
  // Random displacements of 5 % of the 100 um elements: no element inverts.
  Eigen::VectorXd u = Eigen::VectorXd::Random(fe.dof_count()) * 5e-6;
  double open_energy = 0.0;
  const Eigen::VectorXd open = fe.internal_force(u, &open_energy, nullptr);
  EXPECT_EQ(fe.pair_forces(u).norm(), 0.0);  // every pair starts open
  std::vector<char> closed = {1, 0, 1, 1};
  Eigen::VectorXd lambda(4);
  lambda << -1e-3, -5e-3, 0.0, -2e-3;  // the open pair's multiplier is ignored
  fe.set_pair_state(closed, lambda);
  double closed_energy = 0.0;
  Eigen::SparseMatrix<double> K;
  const Eigen::VectorXd held = fe.internal_force(u, &closed_energy, &K);
  const Eigen::VectorXd t = fe.pair_forces(u);
  EXPECT_EQ(closed_energy, open_energy);
  for (std::size_t p = 0; p < pairs.size(); ++p) {
    const auto i = static_cast<Eigen::Index>(p);
    const double g = u[2 * pairs[p][1]] - u[2 * pairs[p][0]];
    const double expected = closed[p] ? lambda[i] + k[i] * g : 0.0;
    // The same sums in another order: round-off of |t| ~ 1e-3 N and of the nodal forces it joins.
    const double roundoff = 1e-12 * std::max(std::abs(expected), 1e-3);
    EXPECT_NEAR(t[i], expected, roundoff);
    EXPECT_NEAR(held[2 * pairs[p][1]] - open[2 * pairs[p][1]], t[i], roundoff);
    EXPECT_NEAR(held[2 * pairs[p][0]] - open[2 * pairs[p][0]], -t[i], roundoff);
  }
  // Only the pairs' radial dofs changed.
  Eigen::VectorXd rest = held - open;
  for (const auto& pair : pairs) rest[2 * pair[0]] = rest[2 * pair[1]] = 0.0;
  EXPECT_EQ(rest.norm(), 0.0);
  const Eigen::VectorXd v = Eigen::VectorXd::Random(fe.dof_count()) * 2.5e-6;
  const double h = 1e-4;
  const Eigen::VectorXd numeric = (fe.internal_force(u + h * v, nullptr, nullptr) -
                                   fe.internal_force(u - h * v, nullptr, nullptr)) /
                                  (2 * h);
  // As TangentMatchesFiniteDifferenceOfInternalForce: the pairs' force is linear in u.
  EXPECT_LT((numeric - K * v).norm(), 1e-6 * (K * v).norm());
  EXPECT_THROW(fe.set_pair_state({1, 0}, Eigen::VectorXd::Zero(2)), InputError);
}

// Flat punch radius a on a thick layer, sticking (bonded) contact.
double flat_punch_force(double nu, Fidelity fidelity, MaterialModel model, double depth,
                        std::size_t* nodes = nullptr) {
  const double E = 1e5, a = 1e-4;
  AxisymmetricProblem p;
  p.layers = one_layer(50 * a, material(model, E, nu));
  p.radius_m = 50 * a;
  p.needle = AxisymmetricNeedle::flat_punch(a);
  p.depth_m = depth;
  p.fidelity = fidelity;
  p.output_steps = 2;
  const InsertionResult r = simulate_axisymmetric(p);
  if (nodes) *nodes = r.nodes;
  return r.steps.back().force_N;
}

// Bonded rigid punch on a half-space (Mossakovskii): frictionless force times
// (1 - nu) ln(3 - 4 nu) / (1 - 2 nu); layer of thickness h = 50 a: Hayes factor ~1.02.
double bonded_punch_reference(double nu, double depth) {
  const double E = 1e5, a = 1e-4;
  const double frictionless = 2 * a * E / (1 - nu * nu) * depth;
  const double bonded = (1 - nu) * std::log(3 - 4 * nu) / (1 - 2 * nu);
  return frictionless * bonded;
}

TEST(AxisymmetricPunch, StickingFlatPunchMatchesBondedBoussinesq) {
  const double d = 1e-6;
  const double force = flat_punch_force(0.3, Fidelity::Standard, MaterialModel::Linear, d);
  const double reference = bonded_punch_reference(0.3, d);
  std::cout << "flat punch force " << force << " reference (half-space) " << reference << " ratio "
            << force / reference << "\n";
  EXPECT_NEAR(force / reference, 1.02, 0.03);
}

TEST(AxisymmetricPunch, FlatPunchErrorFallsWithRefinement) {
  const double d = 1e-6;
  // Reference: the finest mesh's answer extrapolated is unknown; use the bonded half-space
  // force times the Hayes factor ~1.02 estimated for a / h = 0.02 (docs: fe_axi_validation).
  const double reference = 1.02 * bonded_punch_reference(0.3, d);
  double previous_error = 1e9;
  for (Fidelity f : {Fidelity::Fast, Fidelity::Standard, Fidelity::Fine}) {
    std::size_t nodes = 0;
    const double force = flat_punch_force(0.3, f, MaterialModel::Linear, d, &nodes);
    const double error = std::abs(force / reference - 1.0);
    std::cout << "fidelity " << static_cast<int>(f) << " nodes " << nodes << " force " << force
              << " relative error " << error << "\n";
    EXPECT_LT(error, previous_error);
    previous_error = error;
  }
}

TEST(AxisymmetricPunch, NearlyIncompressibleSiliconeDoesNotLock) {
  const double d = 1e-6;
  const double force = flat_punch_force(0.49, Fidelity::Standard, MaterialModel::Linear, d);
  const double reference = bonded_punch_reference(0.49, d);
  std::cout << "nu 0.49 punch ratio " << force / reference << "\n";
  // Hayes at nu 0.5 and a/h = 0.02 adds ~2.3 %; locking would show as tens of percent.
  EXPECT_NEAR(force / reference, 1.023, 0.04);
}

TEST(AxisymmetricPunch, NonlinearMaterialsReduceToLinearAtSmallDepth) {
  const double d = 1e-8;  // strain ~ d / a = 1e-4
  const double linear = flat_punch_force(0.45, Fidelity::Fast, MaterialModel::Linear, d);
  for (MaterialModel m :
       {MaterialModel::StVenantKirchhoff, MaterialModel::NeoHookean, MaterialModel::MooneyRivlin}) {
    const double force = flat_punch_force(0.45, Fidelity::Fast, m, d);
    // Geometric and material nonlinearity are O(strain) = 1e-4 relative.
    EXPECT_NEAR(force / linear, 1.0, 1e-3) << "model " << static_cast<int>(m);
  }
}

TEST(AxisymmetricCone, StickingConeIsStifferThanSneddonAndQuadraticInDepth) {
  const double E = 1e5, nu = 0.3, alpha = kPi / 3.0, depth = 1e-4;
  AxisymmetricProblem p;
  p.layers = one_layer(5e-3, material(MaterialModel::Linear, E, nu));
  p.radius_m = 5e-3;
  p.needle = AxisymmetricNeedle::cone(alpha, 1e-3);
  p.depth_m = depth;
  p.fidelity = Fidelity::Fast;
  p.output_steps = 4;
  const InsertionResult r = simulate_axisymmetric(p);
  const double sneddon = 2.0 / kPi * E / (1 - nu * nu) * std::tan(alpha) * depth * depth;
  const double ratio = r.steps.back().force_N / sneddon;
  std::cout << "cone sticking / Sneddon " << ratio << "\n";
  // Bonded contact stiffens by ~3-10 % at nu = 0.3 (flat punch: 2.9 %; cone: measured 9.5 %
  // on the fine mesh); plus Sneddon's own error for a 60 deg cone (~1-2 %).
  EXPECT_GT(ratio, 1.0);
  EXPECT_LT(ratio, 1.15);
  const double half = r.steps[1].force_N / std::pow(r.steps[1].depth_m, 2);
  const double full = r.steps.back().force_N / std::pow(depth, 2);
  EXPECT_NEAR(half / full, 1.0, 0.05);
  // Contact area near Sneddon's pi a^2 with a = (2/pi) d tan(alpha), within one element ring.
  const double a = 2.0 / kPi * depth * std::tan(alpha);
  EXPECT_NEAR(r.steps.back().contact_area_m2 / (kPi * a * a), 1.0, 0.25);
}

TEST(AxisymmetricInsertion, RejectsNonPositiveDepthAndNonlinearFrictionless) {
  AxisymmetricProblem p;
  p.layers = one_layer(1e-3, material(MaterialModel::Linear, 1e5, 0.3));
  p.radius_m = 1e-3;
  p.needle = AxisymmetricNeedle::flat_punch(1e-4);
  p.depth_m = 0.0;
  EXPECT_THROW(simulate_axisymmetric(p), InputError);
  p.depth_m = 1e-5;
  p.contact = ContactMode::Frictionless;
  p.layers = one_layer(1e-3, material(MaterialModel::NeoHookean, 1e5, 0.3));
  EXPECT_THROW(simulate_axisymmetric(p), InputError);  // frictionless needs linear layers
}

// The message names the field and both values; the tip reaching the base and a cylinder no wider
// than the needle's footprint are refused before any meshing.
void expect_input_error(const AxisymmetricProblem& p, const std::string& field,
                        const std::string& value) {
  try {
    simulate_axisymmetric(p);
    ADD_FAILURE() << "no InputError for " << field;
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(field), std::string::npos) << what;
    EXPECT_NE(what.find(value), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

TEST(AxisymmetricInsertion, RejectsDepthThroughTheBaseAndCylinderNarrowerThanTheNeedle) {
  AxisymmetricProblem p;
  p.layers = {{4e-4, material(MaterialModel::Linear, 1e5, 0.3)},
              {6e-4, material(MaterialModel::Linear, 1e5, 0.3)}};
  p.radius_m = 1e-3;
  p.needle = AxisymmetricNeedle::flat_punch(1e-4);
  p.depth_m = 1e-3;  // exactly the total thickness: the tip is on the rigid base
  expect_input_error(p, "depth_m = 1000 um", "1000 um thick");
  p.depth_m = 1e-5;
  p.radius_m = 1e-4;  // as wide as the punch
  expect_input_error(p, "radius_m = 100 um", "section 100 um");
  // A cone only counts the section where it crosses the surface: 50 um at 50 um deep (45 deg).
  p.needle = AxisymmetricNeedle::cone(kPi / 4, 2e-3);
  p.depth_m = 5e-5;
  p.radius_m = 4e-5;
  expect_input_error(p, "radius_m = 40 um", "section 50 um");
  p.radius_m = 6e-5;
  EXPECT_NO_THROW(simulate_axisymmetric(p));
}

TEST(AxisymmetricInsertion, StiffSkinLayerCurveIsMonotoneAndEnergyConsistent) {
  AxisymmetricProblem p;
  p.layers = {{15e-6, material(MaterialModel::Linear, 1e9, 0.4)},
              {100e-6, material(MaterialModel::Linear, 0.134e6, 0.4)},
              {1035e-6, material(MaterialModel::Linear, 0.08e6, 0.4)}};
  p.radius_m = equal_area_radius(3e-3);
  p.needle = AxisymmetricNeedle::cone(std::atan(115.0 / 1000.0), 115e-6);
  p.depth_m = 200e-6;
  p.fidelity = Fidelity::Fast;
  p.output_steps = 8;
  const InsertionResult r = simulate_axisymmetric(p);
  double work = 0.0, previous_force = 0.0, previous_depth = 0.0;
  for (const InsertionStep& s : r.steps) {
    EXPECT_GT(s.force_N, previous_force);
    work += 0.5 * (s.force_N + previous_force) * (s.depth_m - previous_depth);
    previous_force = s.force_N;
    previous_depth = s.depth_m;
  }
  // Linear elastic: work of the needle = stored energy (trapezoid error small for F ~ linear).
  EXPECT_NEAR(work / r.steps.back().strain_energy_J, 1.0, 0.05);
}

TEST(AxisymmetricFrictionless, FlatPunchMatchesBoussinesqWithLayerCorrection) {
  const double E = 1e5, nu = 0.3, a = 1e-4, d = 1e-6;
  AxisymmetricProblem p;
  p.layers = one_layer(50 * a, material(MaterialModel::Linear, E, nu));
  p.radius_m = 50 * a;
  p.needle = AxisymmetricNeedle::flat_punch(a);
  p.depth_m = d;
  p.contact = ContactMode::Frictionless;
  p.output_steps = 2;
  const InsertionResult r = simulate_axisymmetric(p);
  const double ratio = r.steps.back().force_N / (2 * a * E / (1 - nu * nu) * d);
  std::cout << "frictionless flat punch / Boussinesq " << ratio << "\n";
  // Layer factor ~1.02 (a/h = 0.02), side clamp O(a/R), mesh ~1 %: same budget as sticking.
  EXPECT_NEAR(ratio, 1.02, 0.03);
  // And below the sticking punch, by about the bonded factor 1.029 at nu = 0.3.
  p.contact = ContactMode::Sticking;
  const double sticking = simulate_axisymmetric(p).steps.back().force_N;
  EXPECT_LT(r.steps.back().force_N, sticking);
}

TEST(AxisymmetricFrictionless, BluntConeMatchesSneddon) {
  const double E = 1e5, nu = 0.45, alpha = kPi / 3.0, depth = 1e-4;
  AxisymmetricProblem p;
  p.layers = one_layer(5e-3, material(MaterialModel::Linear, E, nu));
  p.radius_m = 5e-3;
  p.needle = AxisymmetricNeedle::cone(alpha, 1e-3);
  p.depth_m = depth;
  p.fidelity = Fidelity::Standard;
  p.contact = ContactMode::Frictionless;
  p.output_steps = 2;
  const InsertionResult r = simulate_axisymmetric(p);
  const double sneddon = 2.0 / kPi * E / (1 - nu * nu) * std::tan(alpha) * depth * depth;
  const double ratio = r.steps.back().force_N / sneddon;
  std::cout << "frictionless cone / Sneddon " << ratio << "\n";
  // The linear model solves Sneddon's small-strain problem; the 5 mm layer on its rigid base adds
  // Garcia's factor 1.026 (y = d tan(alpha) / h = 0.035). Measured 1.034 / 1.031 / 1.030 on the
  // fast / standard / fine meshes. (Hay, Bolshakov & Pharr put the real 60 deg cone 3 % above
  // Sneddon at nu = 0.45, from the radial displacement no linear model carries.)
  EXPECT_NEAR(ratio, 1.026, 0.02);
}
}  // namespace
}  // namespace mneedle::fe
