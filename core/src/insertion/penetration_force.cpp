// Steady mode-I penetration force of a sharp needle (docs/model.md, "Penetration criterion"):
// the wedged-crack strain energy tabulated once per Poisson's ratio, then minimised over the
// crack width in closed form.
#include "mneedle/insertion/penetration_force.h"

#include <cmath>
#include <future>
#include <map>
#include <mutex>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/fe/plane_strain_crack.h"

namespace mneedle {
namespace {

// The table is made for a unit needle in a unit-modulus block: U_ε / (E r²) is then U_ε itself.
// The block is 40 crack widths: the free edges' effect falls as 1/L² and is −0.05 % at 43 w̄
// (docs/validation.md "The plane-strain model"), so about −0.06 % here. Cells of w̄/150 along the
// slit: +0.06 % against w̄/1200 on paper C's case, at a quarter of the default mesh's time. Mesh and
// block are similar for every width, so the table is exact in E and r.
constexpr double kBlockWidths = 40.0;
constexpr double kCellsAlongSlit = 150.0;

std::vector<double> compute_table(double nu) {
  std::vector<double> table;
  table.reserve(kWedgeWidthRatios.size());
  for (double s : kWedgeWidthRatios) {
    fe::CrackOpeningProblem p;
    p.youngs_modulus_Pa = 1.0;
    p.poisson_ratio = nu;
    p.needle_radius_m = 1.0;
    p.crack_width_m = 2.0 * s;
    p.block_size_m = kBlockWidths * p.crack_width_m;
    p.element_size_m = p.crack_width_m / kCellsAlongSlit;
    table.push_back(fe::crack_opening_strain_energy(p).strain_energy_J_per_m);
  }
  return table;
}

void require_finite(double v, const char* what) {
  if (!std::isfinite(v))
    throw InputError(std::string("penetration force: ") + what + " must be finite, got " +
                     std::to_string(v));
}

}  // namespace

const std::vector<double>& wedged_crack_energy_table(double poisson_ratio) {
  require_finite(poisson_ratio, "Poisson's ratio");
  if (!(poisson_ratio >= 0.0 && poisson_ratio < 0.5))
    throw InputError("penetration force: Poisson's ratio must lie in [0, 0.5), got " +
                     std::to_string(poisson_ratio));
  // One entry per ν, never erased (the references handed out stay valid). The 3 s computation
  // runs outside the lock, so threads asking for a table already made never wait for a new one;
  // threads asking for the one being made wait on its future.
  static std::mutex mutex;
  static std::map<double, std::shared_future<std::vector<double>>> tables;
  std::packaged_task<std::vector<double>()> task;
  std::shared_future<std::vector<double>> table;
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = tables.find(poisson_ratio);
    if (it == tables.end()) {
      task = std::packaged_task<std::vector<double>()>(
          [poisson_ratio] { return compute_table(poisson_ratio); });
      it = tables.emplace(poisson_ratio, task.get_future().share()).first;
    }
    table = it->second;
  }
  if (task.valid()) task();
  return table.get();
}

PenetrationForce sharp_penetration_force(double youngs_modulus_Pa, double poisson_ratio,
                                         double toughness_J_per_m2, double radius_m) {
  require_finite(youngs_modulus_Pa, "Young's modulus");
  require_finite(toughness_J_per_m2, "the toughness");
  require_finite(radius_m, "the needle radius");
  if (!(youngs_modulus_Pa > 0.0))
    throw InputError("penetration force: Young's modulus must be positive, got " +
                     std::to_string(youngs_modulus_Pa) + " Pa");
  if (!(toughness_J_per_m2 > 0.0))
    throw InputError("penetration force: the toughness must be positive, got " +
                     std::to_string(toughness_J_per_m2) + " J/m^2");
  if (radius_m < 0.0)
    throw InputError("penetration force: the needle radius must not be negative, got " +
                     std::to_string(radius_m) + " m");
  PenetrationForce best;
  if (radius_m == 0.0) return best;
  const std::vector<double>& phi = wedged_crack_energy_table(poisson_ratio);
  const double energy_scale = youngs_modulus_Pa * radius_m * radius_m;
  std::size_t arg = 0;
  for (std::size_t k = 0; k < phi.size(); ++k) {
    const double width = 2.0 * radius_m * kWedgeWidthRatios[k];
    const double strain = energy_scale * phi[k];
    const double fracture = toughness_J_per_m2 * width;
    if (k == 0 || strain + fracture < best.force_N) {
      best.force_N = strain + fracture;
      best.crack_width_m = width;
      best.strain_energy_J_per_m = strain;
      best.fracture_work_J_per_m = fracture;
      arg = k;
    }
  }
  best.at_narrowest_crack = arg == 0;
  best.at_widest_crack = arg + 1 == phi.size();
  return best;
}

}  // namespace mneedle
