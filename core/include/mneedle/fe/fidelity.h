#pragma once
// The speed–accuracy levels every FE model offers; each model maps them to its own mesh sizes.

namespace mneedle::fe {

enum class Fidelity { Fast, Standard, Fine };

}  // namespace mneedle::fe
