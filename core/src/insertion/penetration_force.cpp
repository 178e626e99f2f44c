// Steady mode-I penetration force of a sharp needle (docs/model.md, "Penetration criterion"):
// the wedged-crack strain energy tabulated once per Poisson's ratio, then minimised over the
// crack width in closed form.
#include "mneedle/insertion/penetration_force.h"

#include <cmath>
#include <map>
#include <mutex>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/fe/plane_strain_crack.h"

namespace mneedle {
namespace {

// The table is made for a unit needle in a unit-modulus block: U_ε / (E r²) is then U_ε itself.
// The block is 20 crack widths (the model asks for 10 or more; at 20 the free edges change U_ε
// by under 0.1 %, docs/validation.md "The plane-strain model"). Cells of w̄/150 along the slit:
// +0.06 % against w̄/1200 on paper C's case, at a quarter of the default mesh's time. Mesh and
// block are similar for every width, so the table is exact in E and r.
constexpr double kBlockWidths = 20.0;
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
    throw InputError(std::string("penetration force: ") + what + " must be finite");
}

}  // namespace

const std::vector<double>& wedged_crack_energy_table(double poisson_ratio) {
  require_finite(poisson_ratio, "Poisson's ratio");
  if (!(poisson_ratio >= 0.0 && poisson_ratio < 0.5))
    throw InputError("penetration force: Poisson's ratio must lie in [0, 0.5), got " +
                     std::to_string(poisson_ratio));
  static std::mutex mutex;
  static std::map<double, std::vector<double>> tables;  // never erased: references stay valid
  std::lock_guard<std::mutex> lock(mutex);
  auto it = tables.find(poisson_ratio);
  if (it == tables.end()) it = tables.emplace(poisson_ratio, compute_table(poisson_ratio)).first;
  return it->second;
}

PenetrationForce sharp_penetration_force(double youngs_modulus_Pa, double poisson_ratio,
                                         double toughness_J_per_m2, double radius_m) {
  require_finite(youngs_modulus_Pa, "Young's modulus");
  require_finite(toughness_J_per_m2, "the toughness");
  require_finite(radius_m, "the needle radius");
  if (!(youngs_modulus_Pa > 0.0))
    throw InputError("penetration force: Young's modulus must be positive");
  if (!(toughness_J_per_m2 > 0.0))
    throw InputError("penetration force: the toughness must be positive");
  if (radius_m < 0.0) throw InputError("penetration force: the needle radius must not be negative");
  const std::vector<double>& phi = wedged_crack_energy_table(poisson_ratio);
  PenetrationForce best;
  if (radius_m == 0.0) return best;
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
