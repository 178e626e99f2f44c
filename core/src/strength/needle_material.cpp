#include "mneedle/strength/needle_material.h"

#include <cmath>
#include <sstream>

#include "mneedle/base/error.h"

namespace mneedle {

const std::vector<NeedleMaterial>& builtin_needle_materials() {
  static const std::vector<NeedleMaterial> materials = {
      {"silicon", 169e9, 0.064, 1.0e9, FailureMode::Fracture,
       "Hopcroft, Nix & Kenny, J. MEMS 19 (2010): E<110> = 169 GPa, nu = 0.064; fracture strength "
       "of "
       "etched MEMS silicon 1-3 GPa (Sharpe et al. 1997), lower end taken"},
      {"stainless_steel_304", 193e9, 0.29, 215e6, FailureMode::Yield,
       "ASM handbook, annealed AISI 304: E 193-200 GPa, nu 0.29, yield 215 MPa (ultimate 505 MPa)"},
      {"titanium_grade1", 105e9, 0.37, 170e6, FailureMode::Yield,
       "ASTM B348 grade 1 (CP Ti): E 105 GPa, nu 0.37, yield 170 MPa typical (138 MPa minimum)"},
      {"ti6al4v", 113.8e9, 0.342, 790e6, FailureMode::Yield,
       "ASTM F136 Ti-6Al-4V ELI: E 113.8 GPa, nu 0.342, yield 790 MPa"},
      {"pla", 3.5e9, 0.36, 50e6, FailureMode::Fracture,
       "Poly(L-lactic acid), Farah, Anderson & Langer, Adv. Drug Deliv. Rev. 107 (2016): E 3.5 "
       "GPa, "
       "tensile strength ~50 MPa"},
      {"pga", 7.0e9, 0.30, 70e6, FailureMode::Fracture,
       "Poly(glycolic acid), Middleton & Tipton, Biomaterials 21 (2000): E ~7 GPa, tensile "
       "strength "
       "~70 MPa"},
      {"plga", 2.0e9, 0.35, 45e6, FailureMode::Fracture,
       "PLGA 50:50, Middleton & Tipton, Biomaterials 21 (2000): E ~2 GPa, tensile strength 41-55 "
       "MPa"},
      {"cmc", 0.7e9, 0.30, 25e6, FailureMode::Fracture,
       "Carboxymethyl cellulose (dry, cast): Lee, Park & Prausnitz, Biomaterials 29 (2008) "
       "simulate CMC "
       "needles at 1/5 of PLA's buckling load, i.e. E = 0.7 GPa for PLA at 3.5 GPa; strength an "
       "estimate "
       "for dry cellulose-ether films"},
      {"polycarbonate", 2.4e9, 0.37, 62e6, FailureMode::Yield,
       "Bisphenol-A polycarbonate, manufacturers' data sheets (e.g. Lexan): E 2.3-2.4 GPa, nu "
       "0.37, "
       "tensile yield 62 MPa"},
  };
  return materials;
}

std::string_view failure_mode_name(FailureMode mode) {
  return mode == FailureMode::Yield ? "yield" : "fracture";
}

void validate_needle_material(const NeedleMaterial& m, std::string_view where) {
  auto fail = [&](const std::string& what) {
    throw InputError(std::string(where) + ": material '" + m.name + "': " + what);
  };
  if (!std::isfinite(m.youngs_modulus_pa) || m.youngs_modulus_pa <= 0.0)
    fail("E must be a positive pressure");
  if (!std::isfinite(m.strength_pa) || m.strength_pa <= 0.0)
    fail("strength must be a positive pressure");
  if (!std::isfinite(m.poisson_ratio) || m.poisson_ratio <= -1.0 || m.poisson_ratio >= 0.5)
    fail("nu must lie in (-1, 0.5)");
}

NeedleMaterial find_needle_material(std::string_view name,
                                    const std::vector<NeedleMaterial>& user) {
  for (const auto& m : user)
    if (m.name == name) {
      validate_needle_material(m, "user materials");
      return m;
    }
  for (const auto& m : builtin_needle_materials())
    if (m.name == name) return m;
  std::ostringstream known;
  for (const auto& m : user) known << m.name << ", ";
  for (const auto& m : builtin_needle_materials()) known << m.name << ", ";
  std::string list = known.str();
  if (list.size() >= 2) list.resize(list.size() - 2);
  throw InputError("unknown needle material '" + std::string(name) + "' (known: " + list + ")");
}

}  // namespace mneedle
