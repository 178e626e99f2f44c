#pragma once
// The tissue constitutive laws mneedle knows, named once: scene files choose one per layer and
// the finite element models evaluate it (docs/model.md, "Tissue materials"). It sits in base/
// because both scene/ and fe/ use it and neither may include the other.

#include <string_view>

namespace mneedle {

enum class MaterialModel { Linear, StVenantKirchhoff, NeoHookean, MooneyRivlin };

/// "linear", "svk", "neo_hookean", "mooney_rivlin" (the names scene files use).
std::string_view to_string(MaterialModel m);

}  // namespace mneedle
