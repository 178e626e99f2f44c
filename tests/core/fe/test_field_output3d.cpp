// The 3-D field files (docs/cli.md, "Fields"): the tissue written as the whole block whatever
// part was meshed, contact forces that add up to the reported needle force, the needles where
// the step put them, and the collection that indexes them by depth.
#include "fe/field_output3d.h"

#include <gtest/gtest.h>

#include <unistd.h>
#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "fe/vtu_reader.h"
#include "needle_meshes.h"
#include "small_skin.h"

namespace {

namespace fs = std::filesystem;
using namespace mneedle::fe;
using mneedle::MaterialModel;
using mneedle::test::read_vtu;
using mneedle::test::VtuRead;

using mneedle::test::small_skin;

struct FieldRun {
  Simulation3dResult result;
  fs::path dir;
};

// A bevel (mirror-symmetric about y = 0) 60 um into the two-layer block in 3 steps.
FieldRun bevel_run(const std::string& name, bool half) {
  FieldRun r;
  r.dir = fs::temp_directory_path() / ("mneedle_fields_" + name + std::to_string(::getpid()));
  fs::remove_all(r.dir);
  Simulation3dOptions o;
  o.fidelity = Fidelity::Fast;
  o.order = 2;
  o.depth = 60e-6;
  o.steps = 3;
  o.half_model = half;
  o.vtu_directory = r.dir.string();
  o.vtu_comment = "test " + name;
  const std::vector<Needle3d> needles{
      {"bevel", mneedle::test::bevel_needle(60e-6, std::numbers::pi / 6, 1e-3), 0.0, 0.0}};
  r.result = simulate_3d(small_skin(), needles, o);
  return r;
}

double component_sum(const VtuRead& f, const std::string& name, int component) {
  const auto& a = f.arrays.at(name);
  double sum = 0.0;
  for (std::size_t i = static_cast<std::size_t>(component); i < a.values.size(); i += 3)
    sum += a.values[i];
  return sum;
}

// position (rounded to 1 nm) -> point index
std::map<std::array<long long, 3>, std::size_t> point_index(const VtuRead& f) {
  std::map<std::array<long long, 3>, std::size_t> index;
  const auto& p = f.arrays.at("Points").values;
  for (std::size_t i = 0; i < f.points; ++i)
    index[{std::llround(p[3 * i] * 1e9), std::llround(p[3 * i + 1] * 1e9),
           std::llround(p[3 * i + 2] * 1e9)}] = i;
  return index;
}

// Each run is made once per test process (ctest runs every test in its own process), and only
// by the tests that read it.
struct RemoveAtExit {
  fs::path dir;
  ~RemoveAtExit() { fs::remove_all(dir); }
};
const FieldRun& full_run() {
  static const FieldRun run = bevel_run("full", false);
  static const RemoveAtExit remove{run.dir};
  return run;
}
const FieldRun& half_run() {
  static const FieldRun run = bevel_run("half", true);
  static const RemoveAtExit remove{run.dir};
  return run;
}

// The nodal forces a needle exerts on the tissue are the reported force's reaction: internal
// forces and the solver's contact forces agree to its residual (1e-8 of the force, the
// tolerance of Indentation3dOptions).
TEST(FieldOutput3d, ContactForcesAddUpToTheReportedNeedleForceInBothModels) {
  for (const FieldRun* run : {&full_run(), &half_run()}) {
    const VtuRead f = read_vtu((run->dir / "step_3.vtu").string());
    const double force = run->result.steps.back().needles[0].force_N;
    ASSERT_GT(force, 0.0);
    EXPECT_NEAR(-component_sum(f, "contact_force_N", 2), force, 1e-7 * force);
    EXPECT_NEAR(-component_sum(f, "contact_force_N", 0),
                run->result.steps.back().needles[0].lateral_force_N[0], 1e-7 * force);
  }
}

// The half model reflected across y = 0 is the full model's file: the same points, cells and
// fields (the two models solve the same problem; docs/validation.md, half and quarter models).
TEST(FieldOutput3d, HalfModelIsWrittenAsTheWholeBlock) {
  const VtuRead full = read_vtu((full_run().dir / "step_3.vtu").string());
  const VtuRead half = read_vtu((half_run().dir / "step_3.vtu").string());
  ASSERT_EQ(half.points, full.points);
  ASSERT_EQ(half.cells, full.cells);
  const auto index = point_index(full);
  const auto& p = half.arrays.at("Points").values;
  const auto& uf = full.arrays.at("displacement_m").values;
  const auto& uh = half.arrays.at("displacement_m").values;
  const auto& pf = full.arrays.at("contact_pressure_Pa").values;
  const auto& ph = half.arrays.at("contact_pressure_Pa").values;
  double u_max = 0.0, p_max = 0.0;
  for (double v : uf) u_max = std::max(u_max, std::abs(v));
  for (double v : pf) p_max = std::max(p_max, std::abs(v));
  ASSERT_GT(p_max, 0.0);
  for (std::size_t i = 0; i < half.points; ++i) {
    const auto it = index.find({std::llround(p[3 * i] * 1e9), std::llround(p[3 * i + 1] * 1e9),
                                std::llround(p[3 * i + 2] * 1e9)});
    ASSERT_NE(it, index.end()) << "point " << i << " of the reflected half is not in the full";
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(uh[3 * i + c], uf[3 * it->second + c], 1e-6 * u_max) << "point " << i;
    ASSERT_NEAR(ph[i], pf[it->second], 1e-6 * p_max) << "point " << i;
  }
  // Every TET10 of the reflected file, mirror images included: positive corner volume, and each
  // mid-edge node at the middle of its edge in VTK's order (01 12 20 03 13 23) — a wrong
  // permutation of the mirrored cells fails here.
  const auto& conn = half.arrays.at("connectivity").values;
  auto at = [&](double node) {
    const auto i = static_cast<std::size_t>(node);
    return Eigen::Vector3d(p[3 * i], p[3 * i + 1], p[3 * i + 2]);
  };
  constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (std::size_t e = 0; e < half.cells; ++e) {
    const double* c = &conn[10 * e];
    const Eigen::Vector3d a = at(c[0]), b = at(c[1]), d = at(c[2]), t = at(c[3]);
    ASSERT_GT((b - a).cross(d - a).dot(t - a), 0.0) << "cell " << e;
    for (int k = 0; k < 6; ++k)
      ASSERT_LT((at(c[4 + k]) - 0.5 * (at(c[kEdge[k][0]]) + at(c[kEdge[k][1]]))).norm(), 1e-12)
          << "cell " << e << " mid-edge " << k;
  }
  EXPECT_NE(half.header.find("test half"), std::string::npos);
}

// Pressure is compressive under the needle and zero away from it; principal stresses are
// ordered and von Mises is the one of the same tensor (bounded by the spread of the principals).
TEST(FieldOutput3d, FieldsNeedlesAndCollectionOfOneRun) {
  const VtuRead f = read_vtu((full_run().dir / "step_3.vtu").string());
  const auto& pressure = f.arrays.at("contact_pressure_Pa").values;
  const auto& force = f.arrays.at("contact_force_N").values;
  double positive = 0.0;
  for (std::size_t i = 0; i < f.points; ++i) {
    if (force[3 * i] == 0.0 && force[3 * i + 1] == 0.0 && force[3 * i + 2] == 0.0) {
      EXPECT_EQ(pressure[i], 0.0);
    }
    positive = std::max(positive, pressure[i]);
  }
  EXPECT_GT(positive, 0.0);
  const auto& s = f.arrays.at("principal_stress_Pa").values;
  const auto& vm = f.arrays.at("von_mises_Pa").values;
  for (std::size_t e = 0; e < f.cells; ++e) {
    ASSERT_GE(s[3 * e], s[3 * e + 1]);
    ASSERT_GE(s[3 * e + 1], s[3 * e + 2]);
    // sqrt(3)/2 (s1 - s3) <= von Mises <= s1 - s3 for any stress
    const double spread = s[3 * e] - s[3 * e + 2];
    ASSERT_LE(vm[e], spread * (1 + 1e-9) + 1e-9);
    ASSERT_GE(vm[e], 0.5 * std::sqrt(3.0) * spread * (1 - 1e-9) - 1e-9);
  }

  // the needles stand where step 2 of 3 (to 60 um) put them
  const VtuRead needles = read_vtu((full_run().dir / "needles_2.vtu").string());
  const auto& p = needles.arrays.at("Points").values;
  double lowest = 1.0;
  for (std::size_t i = 2; i < p.size(); i += 3) lowest = std::min(lowest, p[i]);
  EXPECT_NEAR(lowest, -40e-6, 1e-12);
  EXPECT_EQ(needles.arrays.at("depth_m").values[0], 40e-6);
  EXPECT_EQ(needles.arrays.at("needle").type, "Int32");

  // the collection lists tissue and needles at every depth
  std::ifstream in(full_run().dir / "steps.pvd");
  std::stringstream text;
  text << in.rdbuf();
  const std::string pvd = text.str();
  int entries = 0;
  for (std::size_t at = pvd.find("<DataSet"); at != std::string::npos;
       at = pvd.find("<DataSet", at + 1))
    ++entries;
  EXPECT_EQ(entries, 6);
  EXPECT_NE(pvd.find("timestep=\"2e-05\" group=\"\" part=\"0\" file=\"step_1.vtu\""),
            std::string::npos)
      << pvd;
  EXPECT_NE(pvd.find("timestep=\"6e-05\" group=\"\" part=\"1\" file=\"needles_3.vtu\""),
            std::string::npos)
      << pvd;
}

}  // namespace
