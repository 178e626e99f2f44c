#pragma once
// Needle materials: stiffness and strength of what a microneedle is made of (docs/materials.md).

#include <string>
#include <string_view>
#include <vector>

namespace mneedle {

enum class FailureMode {
  Yield,     // ductile metals: the section yields
  Fracture,  // silicon, glassy and brittle polymers: the section breaks
};

struct NeedleMaterial {
  std::string name;
  double youngs_modulus_pa = 0.0;
  double poisson_ratio = 0.0;
  double strength_pa = 0.0;  // yield or fracture strength, by `failure`
  FailureMode failure = FailureMode::Yield;
  std::string source;  // where the numbers come from
};

/// The built-in library, in a fixed order.
const std::vector<NeedleMaterial>& builtin_needle_materials();

/// Looks a material up by name among `user` first, then the built-in ones; InputError listing the
/// known names when none matches. Also validates E > 0, strength > 0, -1 < nu < 0.5.
NeedleMaterial find_needle_material(std::string_view name,
                                    const std::vector<NeedleMaterial>& user = {});

/// Throws InputError naming `where` when a user material's values are not physical.
void validate_needle_material(const NeedleMaterial& m, std::string_view where);

std::string_view failure_mode_name(FailureMode mode);

}  // namespace mneedle
