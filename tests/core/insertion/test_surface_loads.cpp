#include "mneedle/insertion/surface_loads.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "mneedle/base/error.h"
#include "needle_shapes.h"

namespace {

using mneedle::LoadConstants;
using mneedle::SurfaceLoadModel;
using mneedle::test::ShapeOptions;
constexpr double kPi = std::numbers::pi;
constexpr double kR = 115e-6;
constexpr double kK = 0.26e6;  // Pa, about silicone's E / (1 - nu^2)
constexpr double kS = 0.168;

LoadConstants fixed_k() {
  LoadConstants c;
  c.stiffness_Pa = kK;
  return c;
}

mneedle::LoadLayer layer(double thickness, double youngs_modulus, double poisson_ratio) {
  mneedle::LoadLayer l;
  l.thickness_m = thickness;
  l.youngs_modulus_Pa = youngs_modulus;
  l.poisson_ratio = poisson_ratio;
  return l;
}

double polygon_area(int n, double r) {
  return 0.5 * n * r * r * std::sin(2.0 * kPi / n);
}

double triangle_area(const std::array<mneedle::Vec3, 3>& t) {
  const mneedle::Vec3 a{t[1][0] - t[0][0], t[1][1] - t[0][1], t[1][2] - t[0][2]};
  const mneedle::Vec3 b{t[2][0] - t[0][0], t[2][1] - t[0][1], t[2][2] - t[0][2]};
  const double x = a[1] * b[2] - a[2] * b[1];
  const double y = a[2] * b[0] - a[0] * b[2];
  const double z = a[0] * b[1] - a[1] * b[0];
  return 0.5 * std::sqrt(x * x + y * y + z * z);
}

// For each of paper A's cases (0, 1 or 2 vertices on the tip) the pentahedron's volume must be
// the area times the mean vertex load, whatever the triangle and which vertices are unloaded.
TEST(SurfaceLoads, PentahedronVolumeIsAreaTimesMeanLoadInAllThreeCases) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-1e-4, 1e-4);
  std::uniform_real_distribution<double> load(1e3, 5e4);
  for (int unloaded = 0; unloaded <= 2; ++unloaded) {
    for (int trial = 0; trial < 50; ++trial) {
      std::array<mneedle::Vec3, 3> t;
      for (auto& p : t) p = {coord(rng), coord(rng), coord(rng)};
      std::array<double, 3> f{load(rng), load(rng), load(rng)};
      for (int k = 0; k < unloaded; ++k) f[(trial + k) % 3] = 0.0;
      const double expected = triangle_area(t) * (f[0] + f[1] + f[2]) / 3.0;
      EXPECT_NEAR(mneedle::pentahedron_load(t, f), expected, 1e-10 * expected)
          << "case with " << unloaded << " unloaded vertices, trial " << trial;
    }
  }
}

TEST(SurfaceLoads, PieceWithoutAreaCarriesNothingNotNaN) {
  // Collinear corners: a sliver that clipping at a rounded interface height leaves behind
  // (the shipped skin scene at 120 um gave "non-finite value NaN at curve[12].beta_N").
  const std::array<mneedle::Vec3, 3> line{mneedle::Vec3{0, 0, 0}, mneedle::Vec3{1e-5, 0, 0},
                                          mneedle::Vec3{2e-5, 0, 0}};
  EXPECT_EQ(mneedle::pentahedron_load(line, {1e3, 2e3, 1.35e-20}), 0.0);
  EXPECT_EQ(mneedle::pentahedron_load({line[0], line[0], line[0]}, {1e3, 1e3, 1e3}), 0.0);
}

TEST(SurfaceLoads, FlatCylinderCarriesKSTimesItsEndPlusCoulombFriction) {
  const ShapeOptions o;
  const SurfaceLoadModel model(mneedle::test::cylinder(o), fixed_k());
  const double depth = 300e-6;
  const auto s = model.at(depth);
  EXPECT_NEAR(s.alpha_N, kK * kS * polygon_area(o.segments, kR), 1e-12);
  EXPECT_DOUBLE_EQ(s.beta_N, 0.0);
  const double perimeter = o.segments * 2.0 * kR * std::sin(kPi / o.segments);
  EXPECT_NEAR(s.friction_N, 0.2 * kK * kS * perimeter * depth, 1e-12);
  EXPECT_DOUBLE_EQ(s.force_N, s.alpha_N + s.beta_N + s.friction_N);
}

TEST(SurfaceLoads, BoreWallsCarryNoFriction) {
  ShapeOptions hollow;
  hollow.bore = 45e-6;
  const double depth = 400e-6;
  const double solid =
      SurfaceLoadModel(mneedle::test::cylinder({}), fixed_k()).at(depth).friction_N;
  const auto s = SurfaceLoadModel(mneedle::test::cylinder(hollow), fixed_k()).at(depth);
  EXPECT_NEAR(s.friction_N, solid, 1e-12 * solid);
  const double annulus = polygon_area(64, kR) - polygon_area(64, 45e-6);
  EXPECT_NEAR(s.alpha_N, kK * kS * annulus, 1e-12);
}

TEST(SurfaceLoads, SubmergedConeCarriesTwoThirdsOfAFlat) {
  ShapeOptions o;
  o.segments = 128;
  const double half = kPi / 12.0;
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::none;
  const SurfaceLoadModel model(mneedle::test::cone(o, half, 16), c);
  const double expected = 2.0 / 3.0 * kK * kS * kPi * kR * kR;
  const auto s = model.at(kR / std::tan(half) + 10e-6);
  EXPECT_NEAR(s.beta_N, expected, 0.01 * expected);
  EXPECT_DOUBLE_EQ(s.friction_N, 0.0);
}

TEST(SurfaceLoads, SubmergedSharpBevelCarriesAsMuchAsAFlat) {
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::none;
  const double bevel = kPi / 6.0;
  const SurfaceLoadModel model(mneedle::test::sharp_bevel({}, bevel), c);
  const double expected = kK * kS * kPi * kR * kR;
  EXPECT_NEAR(model.at(2.0 * kR / std::tan(bevel) + 1e-6).beta_N, expected, 0.01 * expected);
}

TEST(SurfaceLoads, ForceIsContinuousAcrossVertexHeights) {
  const double half = kPi / 12.0;
  const SurfaceLoadModel model(mneedle::test::cone({}, half, 4), fixed_k());
  const double cone_height = kR / std::tan(half);
  for (int k = 1; k <= 4; ++k) {
    const double h = cone_height * k / 4.0;
    const double below = model.at(h - 1e-12).force_N;
    const double above = model.at(h + 1e-12).force_N;
    EXPECT_NEAR(below, above, 1e-6 * above) << "ring " << k;
  }
}

TEST(SurfaceLoads, ForceIsInvariantUnderRigidMotion) {
  const auto needle = mneedle::test::blunt_bevel({}, 25.0 * kPi / 180.0, 40e-6);
  const mneedle::Vec3 axis{0.0, 0.6, 0.8};
  const double angle = 2.3;
  const auto moved = mneedle::test::moved(needle, axis, angle, {-1e-3, 4e-3, 2e-3});
  const auto d = mneedle::test::rigid_motion({0, 0, -1}, axis, angle, {0, 0, 0});
  const SurfaceLoadModel a(needle, fixed_k());
  const SurfaceLoadModel b(moved, fixed_k(), d);
  for (double depth : {20e-6, 150e-6, 600e-6}) {
    const auto sa = a.at(depth);
    const auto sb = b.at(depth);
    EXPECT_NEAR(sa.alpha_N, sb.alpha_N, 1e-9 * sa.force_N);
    EXPECT_NEAR(sa.beta_N, sb.beta_N, 1e-9 * sa.force_N);
    EXPECT_NEAR(sa.friction_N, sb.friction_N, 1e-9 * sa.force_N);
  }
}

TEST(SurfaceLoads, TenTimesFinerTessellationChangesForceByLessThanOnePercent) {
  const double bevel = kPi / 6.0;
  ShapeOptions fine;
  fine.segments = 640;
  fine.rings = 80;
  const SurfaceLoadModel coarse_model(mneedle::test::sharp_bevel({}, bevel), fixed_k());
  const SurfaceLoadModel fine_model(mneedle::test::sharp_bevel(fine, bevel), fixed_k());
  for (double depth : {30e-6, 120e-6, 250e-6, 700e-6}) {
    const double coarse = coarse_model.at(depth).force_N;
    const double refined = fine_model.at(depth).force_N;
    EXPECT_NEAR(coarse, refined, 0.01 * refined) << "depth " << depth;
  }
}

TEST(SurfaceLoads, EachLayerLoadsWithItsOwnStiffness) {
  LoadConstants c;
  c.friction = mneedle::ShaftFriction::none;
  c.layers = {layer(100e-6, 1e6, 0.0), layer(0.0, 0.2e6, 0.4)};
  const SurfaceLoadModel model(mneedle::test::cylinder({}), c);
  const double end = polygon_area(64, kR);
  EXPECT_NEAR(model.at(50e-6).alpha_N, 1e6 * kS * end, 1e-12);
  EXPECT_NEAR(model.at(150e-6).alpha_N, 0.2e6 / (1 - 0.16) * kS * end, 1e-12);
}

// Each layer's share (at(depth, &by_layer)) is what that layer's faces carry: the shares sum to
// the total (round-off), the total is at(depth)'s, and a layer the tip has not reached carries
// nothing.
TEST(SurfaceLoads, EachLayersSharesSumToTheTotalAndAnUnreachedLayerCarriesNothing) {
  LoadConstants c;
  c.layers = {layer(20e-6, 1e9, 0.4), layer(100e-6, 0.134e6, 0.4), layer(0.0, 0.08e6, 0.4)};
  for (const auto& mesh : {mneedle::test::cylinder({}), mneedle::test::cone({}, 0.3)}) {
    const SurfaceLoadModel model(mesh, c);
    for (double depth : {10e-6, 20e-6, 50e-6, 300e-6}) {
      std::vector<mneedle::LoadSample> shares;
      const mneedle::LoadSample total = model.at(depth, &shares);
      ASSERT_EQ(shares.size(), 3u);
      mneedle::LoadSample sum;
      for (const auto& s : shares) {
        EXPECT_NEAR(s.force_N, s.alpha_N + s.beta_N + s.friction_N, 1e-15);
        sum.alpha_N += s.alpha_N;
        sum.beta_N += s.beta_N;
        sum.friction_N += s.friction_N;
      }
      EXPECT_NEAR(sum.alpha_N, total.alpha_N, 1e-12 * total.force_N) << depth;
      EXPECT_NEAR(sum.beta_N, total.beta_N, 1e-12 * total.force_N) << depth;
      EXPECT_NEAR(sum.friction_N, total.friction_N, 1e-12 * total.force_N) << depth;
      EXPECT_NEAR(model.at(depth).force_N, total.force_N, 1e-12 * total.force_N) << depth;
      if (depth < 20e-6) {
        EXPECT_EQ(shares[1].force_N, 0.0) << depth;
      }
      if (depth <= 120e-6) {
        EXPECT_EQ(shares[2].force_N, 0.0) << depth;
      }
      if (depth > 20e-6) {
        EXPECT_GT(shares[1].force_N, 0.0) << depth;
      }
    }
  }
}

TEST(SurfaceLoads, FlatEndExactlyOnALayerInterfaceIsLoadedByTheDeeperLayer) {
  // A face across the axis has no height extent: at a depth sample on an interface it belonged
  // to neither slab and carried nothing (half the force on a split gel). It lies in the deeper
  // layer, as a depth on an interface does for the scene (docs/model.md, "Pressure scale").
  LoadConstants c;
  c.friction = mneedle::ShaftFriction::none;
  c.layers = {layer(100e-6, 1e6, 0.0), layer(0.0, 0.2e6, 0.4)};
  const SurfaceLoadModel model(mneedle::test::cylinder({}), c);
  const double end = polygon_area(64, kR);
  EXPECT_NEAR(model.at(100e-6).alpha_N, 0.2e6 / (1 - 0.16) * kS * end, 1e-12);
}

TEST(SurfaceLoads, OneMaterialSplitIntoIdenticalLayersLoadsAsOneLayerAtEveryDepth) {
  // Depth samples on the interfaces included; no tolerance beyond rounding of the same sums.
  LoadConstants one;
  one.layers = {layer(0.0, 0.2e6, 0.4)};
  LoadConstants split;
  split.layers = {layer(50e-6, 0.2e6, 0.4), layer(100e-6, 0.2e6, 0.4), layer(0.0, 0.2e6, 0.4)};
  for (const auto& mesh : {mneedle::test::cylinder({}), mneedle::test::cone({}, 0.3)}) {
    const SurfaceLoadModel a(mesh, one), b(mesh, split);
    for (double depth : {25e-6, 50e-6, 100e-6, 150e-6, 151e-6, 300e-6}) {
      const auto x = a.at(depth), y = b.at(depth);
      EXPECT_NEAR(y.alpha_N, x.alpha_N, 1e-12 * x.force_N) << depth;
      EXPECT_NEAR(y.beta_N, x.beta_N, 1e-12 * x.force_N) << depth;
      EXPECT_NEAR(y.friction_N, x.friction_N, 1e-12 * x.force_N) << depth;
    }
  }
}

TEST(SurfaceLoads, AGivenPressureScaleReplacesTheDerivedOneAndKeepsItsSource) {
  LoadConstants c;
  c.friction = mneedle::ShaftFriction::none;
  c.layers = {layer(100e-6, 1e6, 0.0), layer(0.0, 0.2e6, 0.4)};
  c.layers[1].pressure_scale_Pa = 5e4;
  c.layers[1].pressure_scale_source = "fitted to curve.csv";
  const SurfaceLoadModel model(mneedle::test::cylinder({}), c);
  EXPECT_DOUBLE_EQ(model.layers()[0].pressure_scale_Pa, 1e6 * kS);
  EXPECT_NE(model.layers()[0].source.find("derived"), std::string::npos);
  EXPECT_EQ(model.layers()[1].source, "fitted to curve.csv");
  EXPECT_NEAR(model.at(150e-6).alpha_N, 5e4 * polygon_area(64, kR), 1e-12);
}

TEST(SurfaceLoads, APressureScaleWithoutItsSourceIsAnInputError) {
  LoadConstants c;
  c.layers = {layer(0.0, 0.2e6, 0.4)};
  c.layers[0].pressure_scale_Pa = 5e4;
  EXPECT_THROW(SurfaceLoadModel(mneedle::test::cylinder({}), c), mneedle::InputError);
}

// Lame: the hoop stress at a pressurised hole equals the wall pressure, so a layer presses on
// the shaft with at most its tensile strength (docs/model.md, "Wall pressure cap").
TEST(SurfaceLoads, FrictionNormalStressIsCappedAtTheLayerStrength) {
  const ShapeOptions o;
  LoadConstants c;
  c.layers = {layer(0.0, 1e9, 0.4)};
  c.layers[0].tensile_strength_Pa = 21.6e6;
  const SurfaceLoadModel model(mneedle::test::cylinder(o), c);
  const double depth = 300e-6;
  const auto s = model.at(depth);
  const double perimeter = o.segments * 2.0 * kR * std::sin(kPi / o.segments);
  EXPECT_NEAR(s.friction_N, 0.2 * 21.6e6 * perimeter * depth, 1e-12 * s.friction_N);
  // The flat end is not a hole wall: it keeps q.
  EXPECT_NEAR(s.alpha_N, 1e9 / (1 - 0.16) * kS * polygon_area(o.segments, kR), 1e-12 * s.alpha_N);
}

// A cone of half-angle a: f = q r / l with r = h tan a. Below r_c = cap l / q it is linear,
// above it uniform: F = (2/3) pi q r_c^3 / l + cap pi (R^2 - r_c^2). Tolerance as for the
// uncapped cone: 1 % for 128 facets around.
TEST(SurfaceLoads, BetaLoadAboveTheCapIsUniformAndTheResultantStaysClosedForm) {
  ShapeOptions o;
  o.segments = 128;
  const double half = kPi / 12.0;
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::none;
  c.stiffness_Pa.reset();
  c.layers = {layer(0.0, kK * (1 - 0.16), 0.4)};
  const double q = kK * kS;
  const double cap = 0.5 * q;
  c.layers[0].tensile_strength_Pa = cap;
  const SurfaceLoadModel model(mneedle::test::cone(o, half, 16), c);
  const double l = model.beta_length_m();
  EXPECT_NEAR(l, std::sqrt(polygon_area(128, kR) / kPi), 1e-15);
  const double rc = cap * l / q;
  const double expected = 2.0 / 3.0 * kPi * q * rc * rc * rc / l + cap * kPi * (kR * kR - rc * rc);
  EXPECT_NEAR(model.at(kR / std::tan(half) + 10e-6).beta_N, expected, 0.01 * expected);
}

TEST(SurfaceLoads, HalvingTheBetaLengthDoublesTheBetaLoad) {
  ShapeOptions o;
  o.segments = 128;
  const double half = kPi / 12.0;
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::none;
  const auto mesh = mneedle::test::cone(o, half, 16);
  const SurfaceLoadModel reference(mesh, c);
  c.beta_length_m = 0.5 * reference.beta_length_m();
  const SurfaceLoadModel halved(mesh, c);
  const double depth = 0.6 * kR / std::tan(half);
  EXPECT_NEAR(halved.at(depth).beta_N, 2.0 * reference.at(depth).beta_N,
              1e-12 * reference.at(depth).beta_N);
}

// Paper A, paragraph on Fig. 17: "tissue toughness" 1.043e-7 and 2.607e-7 (N/um^2) for E = 0.2
// and 0.5 MPa on a phantom 44.107 mm across and 21.145 mm high. K = E D / (4 H) gives both to
// the four digits printed (half a unit of the last digit: 5e-4 relative).
TEST(SurfaceLoads, PaperAFig17ModeTakesKFromThePhantomAndAOneMicrometreBetaLength) {
  for (const auto& [modulus, paper_k] : {std::pair{0.2e6, 1.043e-7}, std::pair{0.5e6, 2.607e-7}}) {
    LoadConstants c;
    c.mode = mneedle::LoadModelMode::paper_a_fig17;
    c.specimen_diameter_m = 44.107e-3;
    c.specimen_height_m = 21.145e-3;
    c.layers = {layer(0.0, modulus, 0.49)};
    const SurfaceLoadModel model(mneedle::test::cylinder({}), c);
    const double k_N_per_um2 = model.layers()[0].pressure_scale_Pa / kS * 1e-12;
    EXPECT_NEAR(k_N_per_um2, paper_k, 5e-4 * paper_k) << "E = " << modulus;
    EXPECT_DOUBLE_EQ(model.beta_length_m(), 1e-6);
  }
}

TEST(SurfaceLoads, PaperAFig17ModeWithoutThePhantomSizeIsAnInputError) {
  LoadConstants c;
  c.mode = mneedle::LoadModelMode::paper_a_fig17;
  c.layers = {layer(0.0, 0.2e6, 0.49)};
  EXPECT_THROW(SurfaceLoadModel(mneedle::test::cylinder({}), c), mneedle::InputError);
}

// Past the tissue's bottom the tip is out of the sample: the end carries nothing and friction
// stops growing at the wetted length of the whole thickness.
TEST(SurfaceLoads, ANeedleThroughTheSampleLosesItsTipLoadAndKeepsFrictionOfTheThickness) {
  const ShapeOptions o;
  LoadConstants c = fixed_k();
  c.tissue_depth_m = 400e-6;
  const SurfaceLoadModel model(mneedle::test::cylinder(o), c);
  const auto through = model.at(600e-6);
  EXPECT_DOUBLE_EQ(through.alpha_N, 0.0);
  const double perimeter = o.segments * 2.0 * kR * std::sin(kPi / o.segments);
  EXPECT_NEAR(through.friction_N, 0.2 * kK * kS * perimeter * 400e-6, 1e-12);
  EXPECT_NEAR(model.at(300e-6).alpha_N, kK * kS * polygon_area(o.segments, kR), 1e-12);
}

TEST(SurfaceLoads, LinearGrowthFrictionSaturatesAtItsDepth) {
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::linear_growth;
  c.friction_max_force_N = 0.05;
  c.friction_saturation_depth_m = 500e-6;
  const SurfaceLoadModel model(mneedle::test::cylinder({}), c);
  EXPECT_NEAR(model.at(250e-6).friction_N, 0.025, 1e-15);
  EXPECT_NEAR(model.at(900e-6).friction_N, 0.05, 1e-15);
}

TEST(SurfaceLoads, AboveTheSurfaceThereIsNoLoad) {
  const auto s = mneedle::surface_load(mneedle::test::cylinder({}), fixed_k(), -10e-6);
  EXPECT_DOUBLE_EQ(s.force_N, 0.0);
}

TEST(SurfaceLoads, MissingStiffnessAndLayersIsAnInputError) {
  EXPECT_THROW(SurfaceLoadModel(mneedle::test::cylinder({}), LoadConstants{}), mneedle::InputError);
}

TEST(SurfaceLoads, LinearGrowthWithoutItsConstantsIsAnInputError) {
  LoadConstants c = fixed_k();
  c.friction = mneedle::ShaftFriction::linear_growth;
  EXPECT_THROW(SurfaceLoadModel(mneedle::test::cylinder({}), c), mneedle::InputError);
}

TEST(SurfaceLoads, NanDepthIsAnInputError) {
  const SurfaceLoadModel model(mneedle::test::cylinder({}), fixed_k());
  EXPECT_THROW(model.at(std::nan("")), mneedle::InputError);
}

}  // namespace
