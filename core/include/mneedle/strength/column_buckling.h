#pragma once
// Elastic buckling of a needle as a column of varying section (docs/model.md, "Needle strength").

#include <functional>
#include <string_view>

namespace mneedle {

/// How the needle is held. The base is clamped to its backing plate; the tip is either held
/// laterally by the tissue it is pressing into (fixed-pinned, K ≈ 0.7) or free (fixed-free, K = 2).
/// Pinned-pinned (K = 1: a needle on a compliant backing) completes the classical cases.
enum class EndCondition { FixedPinned, FixedFree, PinnedPinned };

/// The effective length factor K of Euler's formula for a constant section, P = π²EI/(KL)².
double effective_length_factor(EndCondition end);

EndCondition parse_end_condition(
    std::string_view text);  // "fixed-pinned" | "fixed-free" | "pinned-pinned"
std::string_view end_condition_name(EndCondition end);

/// Lowest elastic critical load [N] of a column of length L [m] whose flexural rigidity EI(h) [N
/// m²] varies with the height h above the tip (h = 0 tip, h = L clamped base). Solved as the beam
/// eigenproblem K u = P K_G u on cubic Hermite elements; `elements` sets the discretisation.
double critical_buckling_load(const std::function<double(double)>& flexural_rigidity, double length,
                              EndCondition end, int elements = 120);

/// Johnson's parabola: the inelastic critical load from the elastic one. With σ_E = P_E / A the
/// Euler stress and σ_y the material strength, σ_cr = σ_E when σ_E ≤ σ_y/2, otherwise
/// σ_y (1 − σ_y / (4 σ_E)). Returns σ_cr · A [N].
double johnson_critical_load(double elastic_load, double area, double strength);

}  // namespace mneedle
