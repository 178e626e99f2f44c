#include "mneedle/fe/indentation3d.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/base/memory.h"
#include "mneedle/fe/crack.h"
#include "mneedle/fe/solid3d.h"
#include "needle_meshes.h"
#include "small_skin.h"

namespace {

using namespace mneedle::fe;
using mneedle::MaterialModel;
using mneedle::test::bevel_needle;
using mneedle::test::cone_needle;
using mneedle::test::cylinder_needle;

// Homogeneous layer of thickness h on a rigid base, sides fixed, sized for a punch of radius a.
TissueBlockSpec homogeneous_block(MaterialModel model, double E, double nu, double half_width,
                                  double h) {
  TissueBlockSpec spec;
  spec.size_x = spec.size_y = 2 * half_width;
  spec.layers = {{"block", h, {model, E, nu, 0.0, 0.0}}};
  return spec;
}

TetMesh punch_mesh(const TissueBlockSpec& base, double radius, double depth, int order,
                   Fidelity fidelity) {
  TissueBlockSpec spec = base;
  spec.sites = {{0.0, 0.0, radius}};
  spec.order = order;
  spec.fidelity = fidelity;
  spec.insertion_depth = depth;
  return generate_tissue_mesh(spec);
}

// Hayes et al. 1972 correction for a flat punch on a bonded layer, nu = 0.45, a/h = 0.4.
constexpr double kHayesNu045Ratio04 = 1.599;
// Frictionless punch, docs/validation.md, "Frictionless flat punch vs Hayes": a displacement
// finite element solution is stiffer than the exact one, so F >= F_Hayes; the standard mesh
// before 2026-12-05 (57 um elements at the site; FrictionlessFlatPunchMatchesHayesLayerSolution
// keeps that mesh) reads 1.25 x Hayes (the rim singularity), falling under
// refinement (ExtremePoisson.Tet10FrictionlessPunchApproachesHayesFromAboveUnderRefinement).
// The upper bound is that reading plus 4 %: a change of the contact resolution moves it more.
constexpr double kFrictionlessPunchLowest = 1.0;
constexpr double kFrictionlessPunchHighest = 1.30;

// a = 90 um on a mesh graded for the punch: its half-integer node spacing keeps the grid lines'
// nodes off the rim, so the captured footprint does not hinge on round-off (docs/validation.md,
// "Rigid flat punch, bonded (sticking), vs Hayes et al. (1972)"). Checks what holds on any mesh
// and returns F / F_Hayes.
double bonded_punch_over_hayes(int order, Fidelity fidelity, double footprint) {
  const double E = 1e5, nu = 0.45, a = 90e-6, h = 225e-6, d = 2e-6;
  const TissueBlockSpec block = homogeneous_block(MaterialModel::Linear, E, nu, 675e-6, h);
  const TetMesh mesh = punch_mesh(block, a, d, order, fidelity);
  Indentation3d run(mesh, {{"punch", cylinder_needle(a, 1e-3), 0.0, 0.0}}, 2 * d);
  const Step3d step = run.advance_to(d);
  const double expected = 2 * a * E / (1 - nu * nu) * kHayesNu045Ratio04 * d;
  EXPECT_EQ(step.needles.size(), 1U);
  if (step.needles.size() != 1U) return 0.0;
  // Rim faces count by the fraction of their nodes held (`footprint` of pi a^2 on this grid). A
  // ring of nodes more or fewer is a strip about 2 pi a x (spacing / 2), 0.36 pi a^2 at 5.5
  // spacings per radius and more on coarser grids, so 3 % either way catches any change of the
  // captured footprint.
  EXPECT_NEAR(step.needles[0].contact_area_m2 / (std::numbers::pi * a * a), footprint, 0.03);
  EXPECT_LT(std::abs(step.needles[0].lateral_force_N[0]), 0.01 * step.needles[0].force_N);
  // Linear material and a flat punch: force proportional to depth, one factorisation.
  const Step3d deeper = run.advance_to(2 * d);
  EXPECT_NEAR(deeper.needles[0].force_N / step.needles[0].force_N, 2.0, 1e-9);
  EXPECT_EQ(run.timing().factorizations, 1);
  // Every captured node moved straight down by the depth: energy = F d / 2.
  EXPECT_NEAR(deeper.strain_energy_J, 0.5 * deeper.needles[0].force_N * 2 * d,
              1e-9 * deeper.strain_energy_J);
  return step.needles[0].force_N / expected;
}

// TET10 against Hayes at standard and fine within 5 % (measured 0.977 and 1.022, captured
// footprints 1.003 and 0.954 of pi a^2: the rim falls between nodes, and the far field decides
// the rest), and standard within 5 % of fine, the objective-value bound of a fidelity level
// (docs/validation.md, "The penetration criterion"): measured -4.4 %, both levels having 5.5 node
// spacings per radius at the rim. TET4 within 15 %: volumetric locking at nu = 0.45 keeps it
// about 10 % stiff (docs/validation.md, "Rigid flat punch, bonded").
TEST(Indentation3d, BondedFlatPunchOnQuadraticTetsMatchesHayesLayerSolution) {
  const double fine = bonded_punch_over_hayes(2, Fidelity::Fine, 0.954);
  EXPECT_NEAR(fine, 1.0, 0.05);
  const double standard = bonded_punch_over_hayes(2, Fidelity::Standard, 1.003);
  EXPECT_NEAR(standard, 1.0, 0.05);
  EXPECT_NEAR(standard / fine, 1.0, 0.05);
}

TEST(Indentation3d, BondedFlatPunchOnLinearTetsMatchesHayesLayerSolution) {
  EXPECT_NEAR(bonded_punch_over_hayes(1, Fidelity::Standard, 0.972), 1.0, 0.15);
}

TEST(Indentation3d, StVenantKirchhoffPunchReducesToLinearAtSmallDepth) {
  const double E = 1e5, nu = 0.4, a = 100e-6, h = 400e-6, d = 0.5e-6;
  double force[2];
  int k = 0;
  for (MaterialModel model : {MaterialModel::Linear, MaterialModel::StVenantKirchhoff}) {
    const TetMesh mesh =
        punch_mesh(homogeneous_block(model, E, nu, 600e-6, h), a, d, 1, Fidelity::Fast);
    Indentation3d run(mesh, {{"punch", cylinder_needle(a, 1e-3), 0.0, 0.0}}, d);
    force[k++] = run.advance_to(d).needles[0].force_N;
  }
  EXPECT_GT(force[0], 0.0);
  EXPECT_NEAR(force[1] / force[0], 1.0, 1e-2);
}

// Nonlinear sticking captures in depth order (docs/model.md, "Contact with the rigid needle
// (sticking)"): the neo-Hookean cone below, asked for 40 and 80 um in two calls, holds the nodes
// the four-call run holds and reads its forces. Before, the single 40 um step captured the
// footprint's nodes all at 40 um and read the shallow force about 25 % low.
TEST(Indentation3d, NonlinearStickingCapturesInDepthOrderWhateverTheStep) {
  const TetMesh mesh =
      punch_mesh(homogeneous_block(MaterialModel::NeoHookean, 1e5, 0.45, 450e-6, 300e-6), 100e-6,
                 80e-6, 1, Fidelity::Standard);
  std::vector<std::vector<Step3d>> runs;
  for (int calls : {2, 4}) {
    Indentation3d run(mesh, {{"cone", cone_needle(std::numbers::pi / 3, 150e-6, 1e-3), 0.0, 0.0}},
                      80e-6);
    std::vector<Step3d> steps;
    for (int k = 1; k <= calls; ++k) steps.push_back(run.advance_to(k * 80e-6 / calls));
    runs.push_back(steps);
  }
  for (int k = 0; k < 2; ++k) {
    const NeedleStep3d& two = runs[0][static_cast<std::size_t>(k)].needles[0];
    const NeedleStep3d& four = runs[1][static_cast<std::size_t>(2 * k + 1)].needles[0];
    EXPECT_EQ(two.captured_nodes, four.captured_nodes) << k;
    // Both runs solve the same depths with the same captures: Newton's tolerance (1e-8) apart.
    EXPECT_NEAR(two.force_N, four.force_N, 1e-6 * four.force_N) << k;
  }
}

TEST(Indentation3d, NeoHookeanConeFollowsTheLayersDepthLawWhenSteppedAlongItsPath) {
  // 60-degree cone, 150 um radius, on a 300 um layer meshed for 100 um. Sticking contact is
  // path dependent: a node keeps the place on the cone where it was captured, so the insertion
  // is stepped (20 um) as a real one is. Jumping to 40 um in one step captured the footprint's
  // nodes all at 40 um, gave a shallow force about 25 % low and a ratio F(80)/F(40) of 6.09.
  const TetMesh mesh =
      punch_mesh(homogeneous_block(MaterialModel::NeoHookean, 1e5, 0.45, 450e-6, 300e-6), 100e-6,
                 80e-6, 1, Fidelity::Standard);
  Indentation3d run(mesh, {{"cone", cone_needle(std::numbers::pi / 3, 150e-6, 1e-3), 0.0, 0.0}},
                    80e-6);
  Step3d shallow, deep;
  for (int k = 1; k <= 4; ++k) {
    const Step3d step = run.advance_to(k * 20e-6);
    if (k == 2) shallow = step;
    if (k == 4) deep = step;
  }
  ASSERT_GT(shallow.needles[0].force_N, 0.0);
  // Reference: the linear cone on this layer, fine mesh, stepped 10/20/40/80 um: 4.74 (Sneddon's
  // half-space gives 4; the footprint, 139 um at 80 um, is half the layer's thickness, and a
  // bonded layer stiffens as a/h grows, as in Hayes et al. 1972). At 27 % nominal strain a
  // neo-Hookean solid stays within 10 % of it (measured 4.55 here since captures are taken in
  // depth order, 4.59 before; 4.88 on the fine mesh; the spread is the ring-by-ring capture of
  // this TET4 grid).
  const double ratio = deep.needles[0].force_N / shallow.needles[0].force_N;
  EXPECT_NEAR(ratio / 4.74, 1.0, 0.10) << ratio;
  EXPECT_GT(deep.newton_iterations, 1);
  EXPECT_GT(deep.needles[0].captured_nodes, shallow.needles[0].captured_nodes);
  EXPECT_GT(deep.strain_energy_J, shallow.strain_energy_J);
}

TEST(Indentation3d, TwoNeedlesEachCarryTheirOwnForce) {
  const double a = 80e-6, d = 5e-6;
  TissueBlockSpec spec = homogeneous_block(MaterialModel::Linear, 1e5, 0.4, 800e-6, 400e-6);
  spec.sites = {{-300e-6, 0.0, a}, {300e-6, 0.0, a}};
  spec.order = 1;
  spec.fidelity = Fidelity::Fast;
  spec.insertion_depth = d;
  const TetMesh mesh = generate_tissue_mesh(spec);
  Indentation3d run(mesh,
                    {{"left", cylinder_needle(a, 1e-3), -300e-6, 0.0},
                     {"right", cylinder_needle(a, 1e-3), 300e-6, 0.0}},
                    d);
  const Step3d step = run.advance_to(d);
  ASSERT_EQ(step.needles.size(), 2U);
  EXPECT_EQ(step.needles[0].name, "left");
  EXPECT_GT(step.needles[0].force_N, 0.0);
  EXPECT_NEAR(step.needles[0].force_N, step.needles[1].force_N, 0.02 * step.needles[0].force_N);
  // Mirror-image sites: lateral forces come only from the split's asymmetry and stay small.
  for (const auto& needle : step.needles)
    EXPECT_LT(std::hypot(needle.lateral_force_N[0], needle.lateral_force_N[1]),
              0.02 * needle.force_N);
}

TEST(Indentation3d, WritesVtuThatNamesEveryField) {
  const double a = 100e-6, d = 2e-6;
  const TetMesh mesh = punch_mesh(
      homogeneous_block(MaterialModel::Linear, 1e5, 0.4, 400e-6, 300e-6), a, d, 2, Fidelity::Fast);
  Indentation3d run(mesh, {{"punch", cylinder_needle(a, 1e-3), 0.0, 0.0}}, d);
  run.advance_to(d);
  const auto path = std::filesystem::temp_directory_path() / "mneedle_test_indentation3d.vtu";
  run.write_vtu(path.string(), d);
  std::ifstream in(path);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (const char* field : {"displacement_m", "von_mises_Pa", "energy_density_J_per_m3", "layer"})
    EXPECT_NE(text.find(field), std::string::npos) << field;
  EXPECT_NE(text.find("NumberOfPoints=\"" + std::to_string(mesh.nodes.size()) + "\""),
            std::string::npos);
  std::filesystem::remove(path);
}

TEST(Indentation3d, RejectsShrinkingDepthAndMissingNeedles) {
  const TetMesh mesh =
      punch_mesh(homogeneous_block(MaterialModel::Linear, 1e5, 0.4, 400e-6, 300e-6), 100e-6, 2e-6,
                 1, Fidelity::Fast);
  EXPECT_THROW(Indentation3d(mesh, {}, 1e-6), mneedle::InputError);
  Indentation3d run(mesh, {{"punch", cylinder_needle(100e-6, 1e-3), 0.0, 0.0}}, 2e-6);
  run.advance_to(2e-6);
  EXPECT_THROW(run.advance_to(1e-6), mneedle::InputError);
}

// A soft linear block meshed for a 100 um punch, and a sample of its nodes to watch.
TetMesh soft_punch_block(Fidelity fidelity = Fidelity::Fast) {
  return punch_mesh(homogeneous_block(MaterialModel::Linear, 1e5, 0.4, 400e-6, 300e-6), 100e-6,
                    20e-6, 2, fidelity);
}

std::vector<int> every_seventh_node(const TetMesh& mesh) {
  std::vector<int> nodes;
  for (std::size_t n = 0; n < mesh.nodes.size(); n += 7) nodes.push_back(static_cast<int>(n));
  return nodes;
}

// Watched nodes (the stress probe's): their displacement from the kept rows of the compliance
// columns equals the whole field's rows to round-off (1e-10 of the largest) at every step with
// sticking contact, and is read from the field with frictionless contact; watching is set before
// the first depth or not at all.
TEST(Indentation3d, WatchedDisplacementEqualsTheFieldsRows) {
  const TetMesh mesh = soft_punch_block();
  const std::vector<int> nodes = every_seventh_node(mesh);
  for (ContactMode contact : {ContactMode::Sticking, ContactMode::Frictionless}) {
    Indentation3dOptions options;
    options.contact = contact;
    // A cone captures node after node with sticking contact; a punch touches at once with
    // frictionless contact (a sharp tip between its contact points would touch nothing here).
    const Needle3d needle =
        contact == ContactMode::Sticking
            ? Needle3d{"cone", cone_needle(std::numbers::pi / 6, 100e-6, 1e-3, 48), 0.0, 0.0}
            : Needle3d{"punch", cylinder_needle(100e-6, 1e-3), 0.0, 0.0};
    Indentation3d run(mesh, {needle}, 20e-6, options);
    run.watch_nodes(nodes);
    for (double depth : {5e-6, 12e-6, 20e-6}) {
      run.advance_to(depth);
      const Eigen::VectorXd u = run.displacement();
      const Eigen::VectorXd watched = run.watched_displacement();
      ASSERT_EQ(watched.size(), 3 * static_cast<Eigen::Index>(nodes.size()));
      double largest = 0.0, difference = 0.0;
      for (std::size_t w = 0; w < nodes.size(); ++w) {
        const Eigen::Vector3d field = u.segment<3>(3 * nodes[w]);
        largest = std::max(largest, field.norm());
        difference = std::max(
            difference, (watched.segment<3>(3 * static_cast<Eigen::Index>(w)) - field).norm());
      }
      EXPECT_GT(largest, 0.0) << "depth " << depth;
      EXPECT_LE(difference, 1e-10 * largest) << "depth " << depth;
    }
    EXPECT_THROW(run.watch_nodes(nodes), mneedle::InputError);
  }
  Indentation3d fresh(mesh, {{"punch", cylinder_needle(100e-6, 1e-3), 0.0, 0.0}}, 20e-6);
  EXPECT_THROW(fresh.watch_nodes({-1}), mneedle::InputError);
  EXPECT_THROW(fresh.watch_nodes({static_cast<int>(mesh.nodes.size())}), mneedle::InputError);
}

// The contact block (docs/performance.md, "The contact block") against compliance columns from
// sparse solves: the same forces, strain energy, field and watched rows at every depth, to the
// round-off of two factorisations in two orders (1e-9 relative), over a punch's capture events;
// the watched rows either way equal to the field's.
TEST(Indentation3d, TheContactBlockGivesWhatSparseSolvesGive) {
  // Standard's mesh: the punch takes more than kColumnChunkNodes (64) nodes, so the sparse path
  // solves its columns in chunks.
  const TetMesh mesh = soft_punch_block(Fidelity::Standard);
  const std::vector<int> nodes = every_seventh_node(mesh);
  // A punch takes its whole face at first contact, and more nodes as its rim sinks.
  for (const Needle3d& needle : {Needle3d{"punch", cylinder_needle(100e-6, 1e-3), 0.0, 0.0}}) {
    SCOPED_TRACE(needle.name);
    Indentation3dOptions sparse;
    sparse.contact_block = false;
    Indentation3d blocked(mesh, {needle}, 20e-6), plain(mesh, {needle}, 20e-6, sparse);
    blocked.watch_nodes(nodes);
    plain.watch_nodes(nodes);
    int captured = 0;
    for (double depth : {5e-6, 12e-6, 20e-6}) {
      const Step3d a = blocked.advance_to(depth), b = plain.advance_to(depth);
      SCOPED_TRACE(depth);
      ASSERT_GT(b.needles[0].force_N, 0.0);
      EXPECT_NEAR(a.needles[0].force_N, b.needles[0].force_N, 1e-9 * b.needles[0].force_N);
      EXPECT_NEAR(a.strain_energy_J, b.strain_energy_J, 1e-9 * b.strain_energy_J);
      EXPECT_EQ(a.needles[0].captured_nodes, b.needles[0].captured_nodes);
      captured = b.needles[0].captured_nodes;
      const Eigen::VectorXd u = plain.displacement();
      EXPECT_LE((blocked.displacement() - u).norm(), 1e-9 * u.norm());
      const Eigen::VectorXd wa = blocked.watched_displacement(), wb = plain.watched_displacement();
      EXPECT_LE((wa - wb).norm(), 1e-9 * wb.norm());
      for (std::size_t w = 0; w < nodes.size(); ++w)
        EXPECT_LE(
            (wb.segment<3>(3 * static_cast<Eigen::Index>(w)) - u.segment<3>(3 * nodes[w])).norm(),
            1e-10 * u.norm());
    }
    // The comparison covers capture events, the watched rows' switch past 16 nodes and the sparse
    // path's chunks of 64.
    EXPECT_GT(captured, 64);
    EXPECT_TRUE(blocked.uses_contact_block());
    EXPECT_FALSE(plain.uses_contact_block());
  }
}

// Past the kept rows (a punch's whole face captured), each depth's watched rows cost a back
// substitution; the states' trailing loads read together in one (more columns than one chunk of
// eight) give each depth's watched_displacement() to round-off (1e-12 of the largest: the same
// factor, summed per column or per block of columns). Before the punch touches, and on the kept
// rows, no back substitution is needed and none is offered.
TEST(Indentation3d, SeveralDepthsWatchedRowsReadInOneBackSubstitutionAreEachDepths) {
  const TetMesh mesh = soft_punch_block();
  const std::vector<int> nodes = every_seventh_node(mesh);
  Indentation3d run(mesh, {{"punch", cylinder_needle(100e-6, 1e-3), 0.0, 0.0}}, 20e-6);
  run.watch_nodes(nodes);
  EXPECT_FALSE(run.watched_by_back_solve());
  EXPECT_THROW(run.watched_trailing_loads(), mneedle::InputError);
  std::vector<Eigen::VectorXd> one_by_one;
  Eigen::MatrixXd loads;
  for (int k = 1; k <= 10; ++k) {
    run.advance_to(2e-6 * k);
    ASSERT_TRUE(run.watched_by_back_solve()) << "depth " << 2e-6 * k;
    const Eigen::VectorXd trailing = run.watched_trailing_loads();
    loads.conservativeResize(trailing.size(), k);
    loads.col(k - 1) = trailing;
    one_by_one.push_back(run.watched_displacement());
  }
  const Eigen::MatrixXd together = run.watched_displacements(loads);
  ASSERT_EQ(together.cols(), 10);
  for (int k = 0; k < 10; ++k) {
    const Eigen::VectorXd& alone = one_by_one[static_cast<std::size_t>(k)];
    ASSERT_GT(alone.norm(), 0.0);
    EXPECT_LE((together.col(k) - alone).norm(), 1e-12 * alone.norm()) << "depth " << k;
  }
  EXPECT_THROW(run.watched_displacements(loads.topRows(loads.rows() - 1)), mneedle::InputError);
  // A cone's few captures keep their rows: no back substitution.
  Indentation3d cone(
      mesh, {{"cone", cone_needle(std::numbers::pi / 6, 100e-6, 1e-3, 48), 0.0, 0.0}}, 20e-6);
  cone.watch_nodes(nodes);
  cone.advance_to(5e-6);
  EXPECT_FALSE(cone.watched_by_back_solve());
}

// The linear sticking path keeps each captured node's compliance columns densely: what a new
// capture would allocate beyond the memory left is refused first, in one line naming the nodes,
// what they need and what is left (docs/performance.md, "Memory"); over a blunt bevel's flat
// under a 3 um contact zone that was tens of GB and, under `ulimit -v`, a crash in CHOLMOD.
// Here a cone holds 1 node at 20 um and 21 at 100 um; each node its tip takes on the way needs
// unit loads, columns and CHOLMOD's copy, 3 x 3 x dofs doubles (1.4 MB on this mesh), above the
// 1 MiB the limit leaves.
TEST(Indentation3d, ContactColumnsThatCannotFitAreRefusedBeforeTheyAreAllocated) {
  const TetMesh mesh =
      punch_mesh(homogeneous_block(MaterialModel::Linear, 1e5, 0.4, 400e-6, 300e-6), 100e-6, 100e-6,
                 2, Fidelity::Standard);
  const Needle3d cone{"cone", mneedle::test::cone_needle(std::numbers::pi / 6, 100e-6, 1e-3, 48),
                      0.0, 0.0};
  Indentation3dOptions sparse;
  sparse.contact_block = false;
  Indentation3d run(mesh, {cone}, 100e-6, sparse);
  const int held = run.advance_to(20e-6).needles[0].captured_nodes;
  ASSERT_GT(held, 0);
  struct Budget {  // the process's limit, removed whatever the test does
    Budget() { mneedle::set_memory_limit_bytes(mneedle::resident_memory_bytes() + (1u << 20)); }
    ~Budget() { mneedle::set_memory_limit_bytes(std::nullopt); }
  };
  {
    const Budget budget;
    try {
      run.advance_to(100e-6);
      FAIL() << "expected a SolverError";
    } catch (const mneedle::OutOfMemoryError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("3-D solve: stopped at depth 20 um: 3-D contact: the dense compliance "
                           "of ",
                           0),
                0u)
          << what;
      EXPECT_NE(what.find(" surface nodes held by the needle needs "), std::string::npos) << what;
      EXPECT_NE(what.find("of memory left to this process; a coarser contact_zone"),
                std::string::npos)
          << what;
    }
  }
  // The same insertion with the memory there takes those nodes.
  Indentation3d fits(mesh, {cone}, 100e-6, sparse);
  fits.advance_to(20e-6);
  EXPECT_GT(fits.advance_to(100e-6).needles[0].captured_nodes, held);
}

TEST(Indentation3d, SimulateThreeDimensionalReportsMeshAndCurve) {
  TissueBlockSpec block;
  block.size_x = block.size_y = 1000e-6;
  block.layers = {{"stratum corneum", 15e-6, {MaterialModel::Linear, 1e9, 0.4, 0.0, 0.0}},
                  {"dermis", 500e-6, {MaterialModel::Linear, 0.08e6, 0.4, 0.0, 0.0}}};
  Simulation3dOptions options;
  options.fidelity = Fidelity::Fast;
  options.order = 1;
  options.depth = 20e-6;
  options.steps = 4;
  const Simulation3dResult result = simulate_3d(
      block, {{"cone", cone_needle(std::numbers::pi / 6, 115e-6, 1e-3), 0.0, 0.0}}, options);
  ASSERT_EQ(result.steps.size(), 4U);
  EXPECT_EQ(result.order, 1);
  EXPECT_GT(result.nodes, 0);
  for (std::size_t k = 1; k < result.steps.size(); ++k)
    EXPECT_GE(result.steps[k].needles[0].force_N, result.steps[k - 1].needles[0].force_N);
  EXPECT_GT(result.steps.back().needles[0].force_N, 0.0);
  EXPECT_GE(result.quality.min_dihedral_deg, kMinDihedralFloorDeg);
}

// A run that ends by an exception part-way (here its on_step throws the SolverError a Newton
// stall would) still reports what its phases cost, once, and a finished run does not call it:
// `simulate` keeps what a stopped run reached, its timings included (InsertionRun::stopped).
TEST(Indentation3d, ARunThatStopsReportsItsPhaseTimingsAndAFinishedOneDoesNot) {
  TissueBlockSpec block;
  block.size_x = block.size_y = 1000e-6;
  block.layers = {{"stratum corneum", 15e-6, {MaterialModel::Linear, 1e9, 0.4, 0.0, 0.0}},
                  {"dermis", 500e-6, {MaterialModel::Linear, 0.08e6, 0.4, 0.0, 0.0}}};
  const std::vector<Needle3d> needles{
      {"cone", cone_needle(std::numbers::pi / 6, 115e-6, 1e-3), 0.0, 0.0}};
  Simulation3dOptions options;
  options.fidelity = Fidelity::Fast;
  options.order = 1;
  options.depth = 20e-6;
  options.steps = 3;
  options.half_model = options.mirror_x = true;  // a quarter: the cone is symmetric
  int calls = 0;
  Timing3d stopped;
  options.on_stop_timing = [&](const Timing3d& timing) {
    ++calls;
    stopped = timing;
  };
  int step = 0;
  options.on_step = [&](const Step3d&) {
    if (++step == 2) throw mneedle::SolverError("stalled at the second step");
    return true;
  };
  EXPECT_THROW(simulate_3d(block, needles, options), mneedle::SolverError);
  EXPECT_EQ(calls, 1);
  EXPECT_GT(stopped.meshing_s, 0.0);
  EXPECT_GE(stopped.factorizations, 1);
  EXPECT_GT(stopped.factorization_s, 0.0);
  EXPECT_GE(stopped.total_s, stopped.meshing_s + stopped.factorization_s);
  options.on_step = nullptr;
  calls = 0;
  EXPECT_EQ(simulate_3d(block, needles, options).steps.size(), 3U);
  EXPECT_EQ(calls, 0);
}

// A soft two-layer block for the options tests: small enough for a fraction of a second.
using mneedle::test::small_skin;

Simulation3dOptions small_options() {
  Simulation3dOptions options;
  options.fidelity = Fidelity::Fast;
  options.order = 2;
  options.depth = 30e-6;
  options.steps = 3;
  return options;
}

// The half mesh is exactly the y >= 0 half of the full mesh and a bevel is mirror-symmetric
// about y = 0, so the two models solve the same problem: only round-off (and a capture decision
// flipped by it) may differ.
TEST(Indentation3d, HalfModelMatchesFullModelOnSymmetricBevel) {
  const std::vector<Needle3d> needles{
      {"bevel", bevel_needle(60e-6, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};
  Simulation3dOptions options = small_options();
  options.depth = 60e-6;
  const Simulation3dResult full = simulate_3d(small_skin(), needles, options);
  ASSERT_GT(full.steps.back().needles[0].force_N, 0.0);
  options.half_model = true;
  const Simulation3dResult half = simulate_3d(small_skin(), needles, options);
  EXPECT_LT(half.nodes, 0.6 * full.nodes);
  ASSERT_EQ(half.steps.size(), full.steps.size());
  for (std::size_t k = 0; k < full.steps.size(); ++k) {
    const NeedleStep3d& f = full.steps[k].needles[0];
    const NeedleStep3d& h = half.steps[k].needles[0];
    if (f.force_N == 0.0) {  // the bevel's tip has not captured a node yet
      EXPECT_EQ(h.force_N, 0.0);
      continue;
    }
    EXPECT_NEAR(h.force_N / f.force_N, 1.0, 1e-6) << "step " << k;
    EXPECT_NEAR(h.lateral_force_N[0], f.lateral_force_N[0], 1e-6 * f.force_N);
    EXPECT_EQ(h.lateral_force_N[1], 0.0);
    EXPECT_NEAR(half.steps[k].strain_energy_J / full.steps[k].strain_energy_J, 1.0, 1e-6);
    EXPECT_NEAR(h.contact_area_m2 / f.contact_area_m2, 1.0, 1e-6);
  }
}

// The stress criterion's peak averaged stress is the same on the half model as on the full one:
// the probe cuts each element in a corner order its mirror image keeps (docs/model.md, "Tip
// stress and cracked meshes"). In each element's own order the two read up to 0.3 % apart, which
// moved paper A's blunt bevel in skin between 85.81 (half) and 85.74 um (full). 1e-9: round-off
// of the solution, which the forces above show at 1e-6 at worst.
TEST(Indentation3d, HalfModelReadsTheFullModelsTipStress) {
  const std::vector<Needle3d> needles{
      {"bevel", bevel_needle(60e-6, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};
  Simulation3dOptions options = small_options();
  options.depth = 60e-6;
  options.stress_average_length_m = 10e-6;
  const Simulation3dResult full = simulate_3d(small_skin(), needles, options);
  options.half_model = true;
  const Simulation3dResult half = simulate_3d(small_skin(), needles, options);
  ASSERT_EQ(half.steps.size(), full.steps.size());
  int compared = 0;
  for (std::size_t k = 0; k < full.steps.size(); ++k) {
    const double f = full.steps[k].needles[0].tip_stress_Pa;
    if (f == 0.0) continue;
    EXPECT_NEAR(half.steps[k].needles[0].tip_stress_Pa / f, 1.0, 1e-9) << "step " << k;
    ++compared;
  }
  EXPECT_GE(compared, 2);
}

// Compares every needle of the reduced run with the same needle of the full run: exact by
// symmetry up to round-off (and a capture decision flipped by it).
void expect_same_needles(const Simulation3dResult& reduced, const Simulation3dResult& full) {
  ASSERT_EQ(reduced.steps.size(), full.steps.size());
  for (std::size_t k = 0; k < full.steps.size(); ++k) {
    ASSERT_EQ(reduced.steps[k].needles.size(), full.steps[k].needles.size());
    for (std::size_t n = 0; n < full.steps[k].needles.size(); ++n) {
      const NeedleStep3d& f = full.steps[k].needles[n];
      const NeedleStep3d& r = reduced.steps[k].needles[n];
      EXPECT_EQ(r.name, f.name);
      const double scale = std::max(f.force_N, 1e-12);
      EXPECT_NEAR(r.force_N, f.force_N, 1e-6 * scale) << f.name << " step " << k;
      EXPECT_NEAR(r.lateral_force_N[0], f.lateral_force_N[0], 1e-6 * scale) << f.name;
      EXPECT_NEAR(r.lateral_force_N[1], f.lateral_force_N[1], 1e-6 * scale) << f.name;
      EXPECT_NEAR(r.contact_area_m2, f.contact_area_m2, 1e-6 * f.contact_area_m2) << f.name;
    }
    EXPECT_NEAR(reduced.steps[k].strain_energy_J, full.steps[k].strain_energy_J,
                1e-6 * full.steps[k].strain_energy_J);
  }
}

TEST(Indentation3d, QuarterModelOfATwoByTwoConeArrayMatchesTheFullModel) {
  const auto cone = cone_needle(std::numbers::pi / 6, 40e-6, 1e-3);
  const std::vector<Needle3d> needles{{"a", cone, -120e-6, -120e-6},
                                      {"b", cone, 120e-6, -120e-6},
                                      {"c", cone, -120e-6, 120e-6},
                                      {"d", cone, 120e-6, 120e-6}};
  Simulation3dOptions options = small_options();
  options.steps = 2;
  options.overrides.tip_size_m = 20e-6;  // coarse: four fine zones in the full model
  const Simulation3dResult full = simulate_3d(small_skin(), needles, options);
  ASSERT_GT(full.steps.back().needles[0].force_N, 0.0);
  // The full mesh is itself symmetric: opposite corners feel opposite lateral forces.
  const auto& last = full.steps.back().needles;
  ASSERT_GT(std::abs(last[3].lateral_force_N[0]), 1e-3 * last[3].force_N);
  EXPECT_NEAR(last[0].lateral_force_N[0], -last[3].lateral_force_N[0], 1e-6 * last[3].force_N);
  EXPECT_NEAR(last[0].lateral_force_N[1], -last[3].lateral_force_N[1], 1e-6 * last[3].force_N);
  options.half_model = options.mirror_x = true;
  const Simulation3dResult quarter = simulate_3d(small_skin(), needles, options);
  EXPECT_LT(quarter.nodes, 0.35 * full.nodes);
  expect_same_needles(quarter, full);
}

TEST(Indentation3d, HalfModelOfBevelsOffTheMirrorPlaneMatchesTheFullModel) {
  const auto bevel = bevel_needle(40e-6, std::numbers::pi / 6, 1e-3);
  const std::vector<Needle3d> needles{{"lower", bevel, 0.0, -150e-6},
                                      {"upper", bevel, 0.0, 150e-6}};
  Simulation3dOptions options = small_options();
  options.steps = 2;
  const Simulation3dResult full = simulate_3d(small_skin(), needles, options);
  ASSERT_GT(full.steps.back().needles[0].force_N, 0.0);
  options.half_model = true;
  const Simulation3dResult half = simulate_3d(small_skin(), needles, options);
  EXPECT_LT(half.nodes, 0.6 * full.nodes);
  expect_same_needles(half, full);
}

// The grid has a line through a bevel's tip, so a node sits on the needle's wall right at the
// tip. It must be anchored at the tip (the face that swept it), not held where it was touched:
// held there it carried no force for a whole step.
TEST(Indentation3d, BevelTipNodeCarriesForceFromTheStepThatCapturesIt) {
  const auto bevel = bevel_needle(60e-6, std::numbers::pi / 6, 1e-3);
  Simulation3dOptions options = small_options();
  options.steps = 3;
  const Simulation3dResult r = simulate_3d(small_skin(), {{"bevel", bevel, 0.0, 0.0}}, options);
  ASSERT_GE(r.steps.front().needles[0].captured_nodes, 1);
  EXPECT_GT(r.steps.front().needles[0].force_N, 0.0);
  // Linear tissue, contact on the same node: the force grows about linearly from zero. The
  // check needs the same captured nodes in both steps; it is asserted, so a grid change that
  // moves the second capture cannot silently skip it.
  const double f1 = r.steps[0].needles[0].force_N, f2 = r.steps[1].needles[0].force_N;
  ASSERT_EQ(r.steps[1].needles[0].captured_nodes, r.steps[0].needles[0].captured_nodes);
  // F = k (d - d0) with d0 where the node was taken: F(2d)/F(d) = 2 + d0 / (d - d0). Measured
  // 2 + 1.1e-5 (the tip node is taken at the surface to round-off of the grid); 1e-4 allows
  // that, while a node taken a step late or a force carried from the wrong step is off by 0.5+.
  EXPECT_NEAR(f2 / f1, 2.0, 1e-4);
}

// The half model of one needle pressed to `depth` in two output steps and in `many`: the runs'
// needle steps at the two depths they share (depth / 2 and depth), coarse first.
std::vector<std::pair<NeedleStep3d, NeedleStep3d>> two_steps_against_many(
    const TissueBlockSpec& block, const Needle3d& needle, double depth, int many) {
  Simulation3dOptions options = small_options();
  options.depth = depth;
  options.half_model = true;
  options.steps = 2;
  const Simulation3dResult coarse = simulate_3d(block, {needle}, options);
  options.steps = many;
  const Simulation3dResult fine = simulate_3d(block, {needle}, options);
  EXPECT_EQ(coarse.steps.size(), 2U);
  EXPECT_EQ(fine.steps.size(), static_cast<std::size_t>(many));
  return {
      {coarse.steps[0].needles[0], fine.steps[static_cast<std::size_t>(many / 2 - 1)].needles[0]},
      {coarse.steps[1].needles[0], fine.steps.back().needles[0]}};
}

// Sticking contact captures nodes in the order the needle reaches them, so the output steps
// only choose where the curve is sampled, to within the grouping length of 0.01 R
// (docs/model.md, "Contact with the rigid needle (sticking)"). The case that showed it: a stiff
// top layer (1 GPa, as skin's stratum corneum) under a bevel. Captured only at the ends of the
// steps, the 30 um first step took a second node of the undeformed surface under the face, which
// six steps never take, and the force read 9.8 % (30 um) and 4.4 % (60 um) low; in paper A's skin
// the force at 100 um read 56 % low at 20 um steps.
TEST(Indentation3d, StickingForceDoesNotDependOnTheDepthStepsUnderAStiffTopLayer) {
  mneedle::fe::TissueBlockSpec block = small_skin();
  block.layers[0].material.E = 1e9;
  const auto pairs = two_steps_against_many(
      block, {"bevel", bevel_needle(60e-6, std::numbers::pi / 6, 1e-3), 0.0, 0.0}, 60e-6, 6);
  // The tip node is taken at first contact in both runs and nothing else is reached, so the same
  // captures and the same condensed solve: 1e-6 is far above its round-off and far below the
  // former 4-10 %.
  for (const auto& [coarse, fine] : pairs) {
    ASSERT_GT(fine.force_N, 0.0);
    EXPECT_EQ(coarse.captured_nodes, fine.captured_nodes);
    EXPECT_NEAR(coarse.force_N / fine.force_N, 1.0, 1e-6);
  }
}

// The same with captures inside the steps: a blunt cone in a soft homogeneous block takes ring
// after ring of surface nodes as it goes down, most of them between output depths, so the
// entry depths found by bisection decide the answer.
TEST(Indentation3d, ConeCapturesInsideTheStepsAtTheDepthsTheyAreReached) {
  const auto pairs = two_steps_against_many(
      homogeneous_block(MaterialModel::Linear, 0.1e6, 0.45, 400e-6, 300e-6),
      {"cone", cone_needle(std::numbers::pi / 3, 100e-6, 1e-3), 0.0, 0.0}, 120e-6, 12);
  ASSERT_GT(pairs.back().second.captured_nodes, 3);
  for (const auto& [coarse, fine] : pairs) {
    EXPECT_EQ(coarse.captured_nodes, fine.captured_nodes);
    // Entry depths are bisected to 1e-5 of the radius and no capture group here straddles an
    // output depth of the 12-step run (a group would put the runs up to 0.01 R apart): the
    // forces agree to about the bisection length (measured 8e-8). Captured at the steps' ends
    // instead, 2 steps held 13 nodes at 60 um against 6 and read +1.6 % at 120 um.
    EXPECT_NEAR(coarse.force_N / fine.force_N, 1.0, 1e-5);
  }
}

TEST(Indentation3d, HalfModelRejectsNeedlesOffTheMirrorPlaneOrAsymmetric) {
  Simulation3dOptions options = small_options();
  options.half_model = true;
  const auto bevel = bevel_needle(60e-6, std::numbers::pi / 6, 1e-3);
  EXPECT_THROW(simulate_3d(small_skin(), {{"off", bevel, 0.0, 100e-6}}, options),
               mneedle::InputError);
  mneedle::TriangleMesh turned = bevel;  // bevel face turned to face +y: no longer symmetric
  for (auto& v : turned.vertices) v = {-v[1], v[0], v[2]};
  EXPECT_THROW(simulate_3d(small_skin(), {{"turned", turned, 0.0, 0.0}}, options),
               mneedle::InputError);
  options.half_model = false;
  options.mirror_x = true;  // a bevel is not symmetric about x = 0
  EXPECT_THROW(simulate_3d(small_skin(), {{"bevel", bevel, 0.0, 0.0}}, options),
               mneedle::InputError);
  const auto cone = cone_needle(std::numbers::pi / 6, 40e-6, 1e-3);
  options.crack_depth_m = 10e-6;  // the crack under a needle on x = 0 would lie on the plane
  EXPECT_THROW(simulate_3d(small_skin(), {{"cone", cone, 0.0, 0.0}}, options), mneedle::InputError);
}

TEST(Indentation3d, OnStepReturningFalseStopsTheInsertion) {
  Simulation3dOptions options = small_options();
  options.steps = 5;
  int calls = 0;
  options.on_step = [&](const Step3d& step) {
    ++calls;
    return step.depth_m < 11e-6;
  };
  const Simulation3dResult result = simulate_3d(
      small_skin(), {{"cone", cone_needle(std::numbers::pi / 6, 60e-6, 1e-3), 0, 0}}, options);
  ASSERT_EQ(result.steps.size(), 2U);  // 6 um goes on, 12 um stops
  EXPECT_EQ(calls, 2);
  EXPECT_NEAR(result.steps.back().depth_m, 12e-6, 1e-12);
}

TEST(Indentation3d, FidelityOverridesChangeTheMeshAndSteps) {
  const std::vector<Needle3d> needles{
      {"cone", cone_needle(std::numbers::pi / 6, 60e-6, 1e-3), 0.0, 0.0}};
  Simulation3dOptions options = small_options();
  options.steps = 1;
  options.order = 1;  // TET4 keeps the five meshes cheap
  const Simulation3dResult base = simulate_3d(small_skin(), needles, options);
  options.overrides.tip_size_m = 20e-6;  // the fast TET4 level picks 8.7 um for this cone
  const Simulation3dResult coarser = simulate_3d(small_skin(), needles, options);
  EXPECT_LT(coarser.nodes, base.nodes);
  options.overrides = {};
  options.overrides.order = 2;
  options.overrides.steps = 2;
  const Simulation3dResult quadratic = simulate_3d(small_skin(), needles, options);
  EXPECT_EQ(quadratic.order, 2);
  EXPECT_EQ(quadratic.steps.size(), 2U);
  options.overrides = {};
  options.overrides.elements_through_top = 5;
  options.overrides.growth = 1.5;
  const Simulation3dResult layered = simulate_3d(small_skin(), needles, options);
  EXPECT_GT(layered.nodes, base.nodes);
  options.overrides = {};
  options.overrides.domain_scale = 2.0;
  const Simulation3dResult wider = simulate_3d(small_skin(), needles, options);
  EXPECT_GT(wider.nodes, base.nodes);
  options.overrides = {};
  options.overrides.tip_size_m = -1.0;
  EXPECT_THROW(simulate_3d(small_skin(), needles, options), mneedle::InputError);
}

// Frictionless flat punch on the Hayes layer of the sticking test (a/h = 0.4, ν = 0.45, κ =
// 1.599): the footprint is resolved at surface quadrature points (24 per face), so the punch
// rim no longer hinges on where the nodes fall (docs/validation.md, "Frictionless flat punch vs
// Hayes").
TEST(Indentation3d, FrictionlessFlatPunchMatchesHayesLayerSolution) {
  const double E = 1e5, nu = 0.45, a = 90e-6, h = 225e-6, d = 2e-6;
  const TissueBlockSpec block = homogeneous_block(MaterialModel::Linear, E, nu, 675e-6, h);
  // The mesh the reading above was taken on (the standard level before 2026-12-05: 3.5 node
  // spacings per site radius, growth 1.6, the plain grid); the level's own mesh now resolves the
  // rim 1.6 times finer and costs this test 8 times the time.
  TissueBlockSpec spec = block;
  spec.sites = {{0.0, 0.0, 100e-6}};
  spec.order = 2;
  spec.fidelity = Fidelity::Standard;
  spec.insertion_depth = d;
  spec.overrides.tip_size_m = 2 * 100e-6 / 3.5;
  spec.overrides.growth = 1.6;
  spec.overrides.refinement_levels = 0;
  const TetMesh mesh = generate_tissue_mesh(spec);
  Indentation3dOptions options;
  options.contact = ContactMode::Frictionless;
  Indentation3d run(mesh, {{"punch", cylinder_needle(a, 1e-3), 0.0, 0.0}}, 2 * d, options);
  const Step3d step = run.advance_to(d);
  const double expected = 2 * a * E / (1 - nu * nu) * kHayesNu045Ratio04 * d;
  ASSERT_EQ(step.needles.size(), 1U);
  EXPECT_GE(step.needles[0].force_N / expected, kFrictionlessPunchLowest);
  EXPECT_LE(step.needles[0].force_N / expected, kFrictionlessPunchHighest);
  // Contact area: quadrature points with positive pressure; the rim singularity makes the
  // pressure oscillate on quadratic faces, so part of the punch face reads as separated.
  EXPECT_GT(step.needles[0].contact_area_m2, 0.1 * std::numbers::pi * a * a);
  EXPECT_LT(step.needles[0].contact_area_m2, 1.1 * std::numbers::pi * a * a);
  EXPECT_LT(std::abs(step.needles[0].lateral_force_N[0]), 0.01 * step.needles[0].force_N);
  const Step3d deeper = run.advance_to(2 * d);
  EXPECT_NEAR(deeper.needles[0].force_N / step.needles[0].force_N, 2.0, 0.01);
  EXPECT_EQ(run.timing().factorizations, 1);  // linear layers: one factorisation
  EXPECT_NEAR(deeper.strain_energy_J, 0.5 * deeper.needles[0].force_N * 2 * d,
              0.01 * deeper.strain_energy_J);
}

// Neo-Hookean layers take the Newton path with the penalty tangent; at 0.5 % strain they give
// the linear answer.
TEST(Indentation3d, FrictionlessNeoHookeanPunchReducesToLinearAtSmallDepth) {
  const double E = 1e5, nu = 0.4, a = 90e-6, h = 300e-6, d = 0.5e-6;
  double force[2];
  int k = 0;
  for (MaterialModel model : {MaterialModel::Linear, MaterialModel::NeoHookean}) {
    const TetMesh mesh =
        punch_mesh(homogeneous_block(model, E, nu, 450e-6, h), 100e-6, d, 2, Fidelity::Fast);
    Indentation3dOptions options;
    options.contact = ContactMode::Frictionless;
    Indentation3d run(mesh, {{"punch", cylinder_needle(a, 1e-3), 0.0, 0.0}}, d, options);
    force[k++] = run.advance_to(d).needles[0].force_N;
  }
  EXPECT_GT(force[0], 0.0);
  EXPECT_NEAR(force[1] / force[0], 1.0, 1e-2);
}

// The puncture criteria's inputs: the averaged tip stress (fe::averaged_max_principal_stress) and
// G from a cracked copy run in lock-step (fe::crack_mesh). At fixed needle displacement the crack
// can only release energy, so G > 0; the crack is the meshed part of a half-disc of radius c.
TEST(Indentation3d, TipStressAndEnergyReleaseRateAreReportedWhenRequested) {
  Simulation3dOptions options = small_options();
  options.steps = 1;
  options.stress_average_length_m = 20e-6;
  options.crack_depth_m = 60e-6;
  const Simulation3dResult result = simulate_3d(
      small_skin(), {{"cone", cone_needle(std::numbers::pi / 6, 60e-6, 1e-3), 0.0, 0.0}}, options);
  const NeedleStep3d& needle = result.steps.back().needles[0];
  EXPECT_TRUE(std::isfinite(needle.tip_stress_Pa));
  EXPECT_NE(needle.tip_stress_Pa, 0.0);
  EXPECT_GT(needle.energy_release_rate_J_per_m2, 0.0);
  const double half_disc = 0.5 * std::numbers::pi * 60e-6 * 60e-6;
  EXPECT_GT(needle.crack_area_m2, 0.3 * half_disc);
  EXPECT_LT(needle.crack_area_m2, 1.5 * half_disc);
  options.crack_depth_m = -1.0;
  EXPECT_THROW(
      simulate_3d(small_skin(), {{"cone", cone_needle(0.5, 60e-6, 1e-3), 0.0, 0.0}}, options),
      mneedle::InputError);
}

// A punch's tip stress read with the look-ahead (its whole face captured: the remaining depths
// advanced first and read in one back substitution) equals the step-by-step reading, which a VTU
// directory keeps (each depth writes its field), to round-off (1e-9 of the stress: the same
// factor, summed per column or per block of columns); a caller's stop after the second depth
// ends the steps there, the look-ahead's depths past it unreported.
TEST(Indentation3d, TheLookAheadOfThePunchsTipStressChangesNoStepAndHonoursTheStop) {
  Simulation3dOptions options = small_options();
  options.steps = 6;
  options.stress_average_length_m = 20e-6;
  const std::vector<Needle3d> punch{{"punch", cylinder_needle(60e-6, 1e-3), 0.0, 0.0}};
  const Simulation3dResult ahead = simulate_3d(small_skin(), punch, options);
  options.vtu_directory = (std::filesystem::temp_directory_path() / "mneedle_look_ahead").string();
  const Simulation3dResult stepwise = simulate_3d(small_skin(), punch, options);
  std::filesystem::remove_all(options.vtu_directory);
  ASSERT_EQ(ahead.steps.size(), 6u);
  ASSERT_EQ(stepwise.steps.size(), 6u);
  for (std::size_t k = 0; k < 6; ++k) {
    const double expected = stepwise.steps[k].needles[0].tip_stress_Pa;
    ASSERT_GT(expected, 0.0) << "step " << k;
    EXPECT_NEAR(ahead.steps[k].needles[0].tip_stress_Pa, expected, 1e-9 * expected) << k;
    EXPECT_NEAR(ahead.steps[k].needles[0].force_N, stepwise.steps[k].needles[0].force_N,
                1e-9 * stepwise.steps[k].needles[0].force_N);
  }
  options.vtu_directory.clear();
  int seen = 0;
  options.on_step = [&seen](const Step3d&) { return ++seen < 2; };
  const Simulation3dResult stopped = simulate_3d(small_skin(), punch, options);
  ASSERT_EQ(stopped.steps.size(), 2u);
  EXPECT_EQ(seen, 2);
  EXPECT_EQ(stopped.steps[1].needles[0].tip_stress_Pa, ahead.steps[1].needles[0].tip_stress_Pa);
}

// Paper A's silicone (E 0.2 MPa, nu 0.49) under a 30 deg bevel of radius 115 um, with a crack
// 100 um deep under its tip (11 node pairs on the faces): both meshes, the pairs (normal x) and
// each cracked node's node in the intact mesh.
struct CrackUnderBevel {
  TetMesh mesh, cracked;
  std::vector<int> original;
  std::vector<CrackFacePair> pairs;
};
CrackUnderBevel crack_under_bevel(MaterialModel material, double depth) {
  const double R = 115e-6;
  TissueBlockSpec spec = homogeneous_block(material, 0.2e6, 0.49, 450e-6, 450e-6);
  spec.sites = {{0.0, 0.0, R, Eigen::Vector2d(-R, 0.0)}};
  spec.fidelity = Fidelity::Fast;
  spec.overrides.tip_size_m = 60e-6;
  spec.insertion_depth = depth;
  spec.half_y = true;
  CrackUnderBevel c;
  c.mesh = generate_tissue_mesh(spec);
  PlanarCrack crack;
  crack.origin_m = crack_origin_under(c.mesh, {0.0, 0.0}, {-R, 0.0});
  crack.depth_m = 100e-6;
  c.cracked = crack_mesh(c.mesh, crack, nullptr, &c.original);
  for (std::size_t n = c.mesh.nodes.size(); n < c.cracked.nodes.size(); ++n)
    c.pairs.push_back({c.original[n], static_cast<int>(n), Eigen::Vector3d::UnitX()});
  return c;
}

// The largest internal force at a face node below the surface (there, the contact force on it).
double largest_face_force(const CrackUnderBevel& c, const Eigen::VectorXd& force) {
  double largest = 0.0;
  for (const CrackFacePair& p : c.pairs)
    if (c.cracked.nodes[static_cast<std::size_t>(p.positive_node)].z() < 0.0)
      largest = std::max(largest, force.segment<3>(3 * p.positive_node).norm());
  return largest;
}

// Crack faces in contact (docs/model.md, "Crack faces in contact"). A bevel pushes the tissue
// beside its tip sideways, so the crack under the tip closes on one side: with free faces the
// two faces pass through each other by micrometres. In contact they must not, at any node pair
// of the displacement field (not only as the run reports it); the contact force of each pair is
// normal (frictionless), compressive and equal and opposite on the two faces; and the contact can
// only stiffen the cracked block, so U_free <= U_contact <= U_intact.
TEST(Indentation3d, CrackFacesUnderABevelDoNotPassThroughEachOther) {
  const double R = 115e-6, depth = 150e-6, tolerance = 1e-13;  // m; see below for the tolerance
  const CrackUnderBevel c = crack_under_bevel(MaterialModel::Linear, depth);
  const TetMesh& mesh = c.mesh;
  const TetMesh& cracked = c.cracked;
  const std::vector<int>& original = c.original;
  const std::vector<CrackFacePair>& pairs = c.pairs;
  ASSERT_EQ(crack_origin_under(mesh, {0.0, 0.0}, {-R, 0.0}).x(), -R);  // under the tip
  ASSERT_GT(pairs.size(), 8U);
  const std::vector<Needle3d> bevel = {
      {"bevel", bevel_needle(R, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};

  auto gaps_of = [&](const Eigen::VectorXd& u) {
    std::vector<double> gaps;
    for (const CrackFacePair& p : pairs)
      gaps.push_back(u(3 * p.positive_node) - u(3 * p.negative_node));
    return gaps;
  };
  // Advanced in three steps: the contact set carries over from depth to depth while captures
  // are added (some on the crack's mouth, whose pairs the needle then holds).
  Indentation3d intact(mesh, bevel, depth);
  Indentation3d free_twin(cracked, bevel, depth), twin(cracked, bevel, depth);
  free_twin.hold_contact_of(intact, original);
  free_twin.set_crack_faces(pairs, false);
  twin.hold_contact_of(intact, original);
  twin.set_crack_faces(pairs, true);
  const SolidModel model(cracked);
  for (double at : {depth / 3, 2 * depth / 3, depth}) {
    const double intact_energy = intact.advance_to(at).strain_energy_J;
    const Step3d free_step = free_twin.advance_to(at);
    const std::vector<double> free_gaps = gaps_of(free_twin.displacement());
    const double free_min = *std::min_element(free_gaps.begin(), free_gaps.end());
    // The defect contact removes: free faces overlap (by 52 um at 150 um).
    EXPECT_LT(free_min, -1e-6) << "at " << at;
    EXPECT_NEAR(free_step.crack_face_overlap_m, -free_min, 1e-9 * -free_min);
    EXPECT_EQ(free_step.crack_face_contacts, 0);

    const Step3d step = twin.advance_to(at);
    const Eigen::VectorXd u = twin.displacement();
    const std::vector<double> gaps = gaps_of(u);
    // In contact: no overlap beyond round-off. The active set closes a pair whose faces
    // overlap by more than 1e-10 x depth (<= 1.5e-14 m here); 1e-13 m is 2e-9 of the free one.
    EXPECT_GE(*std::min_element(gaps.begin(), gaps.end()), -tolerance) << "at " << at;
    EXPECT_LE(step.crack_face_overlap_m, tolerance);
    EXPECT_GT(step.crack_face_contacts, 0);
    // Contact forces from the field itself: the internal force K u at a face node below the
    // surface is the contact force on it (mouth nodes on z = 0 may also carry the needle's).
    Eigen::VectorXd force;
    model.assemble(u, nullptr, &force);
    const double largest = largest_face_force(c, force);
    ASSERT_GT(largest, 0.0);
    // Round-off of an assembled force: 1e-9 of the largest contact force.
    const double floor = 1e-9 * largest;
    int pressed = 0;
    for (std::size_t k = 0; k < pairs.size(); ++k) {
      const CrackFacePair& p = pairs[k];
      if (cracked.nodes[static_cast<std::size_t>(p.positive_node)].z() == 0.0) continue;
      const Eigen::Vector3d plus = force.segment<3>(3 * p.positive_node);
      const Eigen::Vector3d minus = force.segment<3>(3 * p.negative_node);
      const bool on_mirror = cracked.nodes[static_cast<std::size_t>(p.positive_node)].y() == 0.0;
      EXPECT_GE(plus.x(), -floor) << "pair " << k << ": the contact pulls";
      EXPECT_NEAR(plus.x() + minus.x(), 0.0, floor) << "pair " << k;
      EXPECT_NEAR(plus.z(), 0.0, floor) << "pair " << k << ": friction on the faces";
      if (!on_mirror) {  // on y = 0 the y force is the mirror plane's reaction
        EXPECT_NEAR(plus.y(), 0.0, floor) << "pair " << k;
      }
      if (gaps[k] > tolerance) {
        EXPECT_NEAR(plus.x(), 0.0, floor) << "open pair " << k;
      }
      pressed += plus.x() > floor;
    }
    EXPECT_GT(pressed, 0) << "at " << at;
    EXPECT_LT(free_step.strain_energy_J, step.strain_energy_J) << "at " << at;
    EXPECT_LT(step.strain_energy_J, intact_energy) << "at " << at;
  }
}

// The same on neo-Hookean tissue (paper A's silicone as neo-Hookean), where the faces are held
// by an augmented Lagrangian inside Newton (docs/model.md, "Crack faces in contact"): free faces
// overlap by micrometres, held ones by no more than the multiplier update's tolerance (Newton's
// 1e-8 x the depth, 1.5e-12 m at 150 um); the held pairs press (a pair latched closed may pull by
// up to that tolerance x the largest pair force, so the floor is 1e-6 of the largest); and the
// held faces stiffen the cracked block, U_free < U_held < U_intact, so G_held < G_free.
// (Measured: three pairs below the surface pressed, 15-39 uN; free faces overlap by > 1 um.)
TEST(Indentation3d, NeoHookeanCrackFacesUnderABevelDoNotPassThroughEachOther) {
  const double R = 115e-6, depth = 150e-6;
  const CrackUnderBevel c = crack_under_bevel(MaterialModel::NeoHookean, depth);
  const TetMesh& cracked = c.cracked;
  const std::vector<CrackFacePair>& pairs = c.pairs;
  const std::vector<Needle3d> bevel = {
      {"bevel", bevel_needle(R, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};
  Indentation3d intact(c.mesh, bevel, depth);
  Indentation3d free_twin(cracked, bevel, depth), twin(cracked, bevel, depth);
  free_twin.hold_contact_of(intact, c.original);
  free_twin.set_crack_faces(pairs, false);
  twin.hold_contact_of(intact, c.original);
  twin.set_crack_faces(pairs, true);
  const SolidModel model(cracked);
  const double tolerance = 1e-8 * depth;
  // At the full depth only: at half of it only the crack's mouth is held (measured).
  for (double at : {depth}) {
    const double intact_energy = intact.advance_to(at).strain_energy_J;
    const Step3d free_step = free_twin.advance_to(at);
    EXPECT_GT(free_step.crack_face_overlap_m, 1e-6) << "at " << at;
    const Step3d step = twin.advance_to(at);
    const Eigen::VectorXd u = twin.displacement();
    double smallest = 0.0;
    for (const CrackFacePair& p : pairs)
      smallest = std::min(smallest, u(3 * p.positive_node) - u(3 * p.negative_node));
    EXPECT_GE(smallest, -tolerance) << "at " << at;
    EXPECT_LE(step.crack_face_overlap_m, tolerance);
    EXPECT_GT(step.crack_face_contacts, 0);
    // The held pairs' forces from the field: the internal force at a face node below the
    // surface is the contact force on it.
    Eigen::VectorXd force;
    model.assemble(u, nullptr, &force);
    const double largest = largest_face_force(c, force);
    ASSERT_GT(largest, 0.0);
    const double floor = 1e-6 * largest;
    int pressed = 0;
    for (const CrackFacePair& p : pairs) {
      if (cracked.nodes[static_cast<std::size_t>(p.positive_node)].z() == 0.0) continue;
      const Eigen::Vector3d plus = force.segment<3>(3 * p.positive_node);
      EXPECT_GE(plus.x(), -floor) << "the contact pulls";
      EXPECT_NEAR(plus.x() + force(3 * p.negative_node), 0.0, floor);
      pressed += plus.x() > floor;
    }
    EXPECT_GT(pressed, 0) << "at " << at;
    EXPECT_LT(free_step.strain_energy_J, step.strain_energy_J) << "at " << at;
    EXPECT_LT(step.strain_energy_J, intact_energy) << "at " << at;
  }
}

// simulate_3d puts the cracked twin's faces in contact unless told not to (the comparison
// option): the same bevel as above, through the one-call entry point.
TEST(Indentation3d, SimulateKeepsTheCrackFacesInContactUnlessToldNotTo) {
  Simulation3dOptions options;
  options.depth = 150e-6;
  options.steps = 1;
  options.half_model = true;
  options.fidelity = Fidelity::Fast;
  options.overrides.tip_size_m = 60e-6;
  options.crack_depth_m = 100e-6;
  const TissueBlockSpec block =
      homogeneous_block(MaterialModel::Linear, 0.2e6, 0.49, 450e-6, 450e-6);
  const std::vector<Needle3d> bevel = {
      {"bevel", bevel_needle(115e-6, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};
  const Step3d in_contact = simulate_3d(block, bevel, options).steps.back();
  options.crack_face_contact = false;
  const Step3d free_faces = simulate_3d(block, bevel, options).steps.back();
  EXPECT_LE(in_contact.crack_face_overlap_m, 1e-13);  // as in the test above
  EXPECT_GT(in_contact.crack_face_contacts, 0);
  EXPECT_GT(free_faces.crack_face_overlap_m, 1e-6);
  EXPECT_EQ(in_contact.needles[0].force_N, free_faces.needles[0].force_N);  // the intact run's
  EXPECT_GT(in_contact.needles[0].energy_release_rate_J_per_m2, 0.0);
  EXPECT_LT(in_contact.needles[0].energy_release_rate_J_per_m2,
            free_faces.needles[0].energy_release_rate_J_per_m2);
}

}  // namespace
