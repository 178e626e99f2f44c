#pragma once
// Quantities with units at the edges of mneedle (scene files, --set key=value, --unit), SI inside.
// Every text with a unit is parsed here; the rest of the code only ever sees SI doubles.

#include <string>
#include <string_view>

namespace mneedle {

/// The physical dimension of a quantity. Toughness (J/m^2) and Stiffness (N/m) share the SI unit
/// N/m, so a value written in either unit is accepted where the other is expected.
enum class Dimension {
  Dimensionless,
  Length,     ///< m
  Angle,      ///< rad
  Pressure,   ///< Pa (also moduli and strengths)
  Force,      ///< N
  Speed,      ///< m/s
  Time,       ///< s
  Toughness,  ///< N/m = J/m^2 (fracture toughness, energy per crack area)
  Density,    ///< kg/m^3
  Viscosity,  ///< Pa s
  Stiffness,  ///< N/m (force per displacement)
  Energy,     ///< J (work, strain energy, dissipated energy)
};

/// "dimensionless", "length", "angle", "pressure", "force", "speed", "time", "toughness",
/// "density", "viscosity", "stiffness", "energy".
std::string_view dimension_name(Dimension d);

/// The units a value of dimension `d` may be written in, ASCII spellings: "nm, um, mm, cm, m".
std::string unit_names(Dimension d);

/// The SI unit of a dimension as written in output ("m", "rad", "Pa", "N/m", ...; "" if none).
std::string_view si_unit(Dimension d);

/// True when a value of dimension `given` may stand where `expected` is asked for
/// (equal, or the Toughness/Stiffness pair that share N/m).
bool dimensions_compatible(Dimension given, Dimension expected);

struct Quantity {
  double value_si;
  Dimension dimension;
};

/// Parses "230 um", "230um", "0.2 MPa", "30 deg", "1 mm/s", "0.019 N/mm", "19 J/m^2", "1e-3".
/// A plain number is SI and Dimensionless. Throws InputError("\"<text>\": unknown unit 'xx' ...")
/// for an unknown unit, and InputError for an empty text, a missing number, NaN or infinity.
Quantity parse_quantity(std::string_view text);

/// Same, but the unit must be of dimension `expected`. A plain number is accepted only where a
/// plain number is expected (and 0 everywhere): "20" for a length is an InputError that lists
/// the accepted units. Returns the value in SI. Throws InputError naming the text, the unit's
/// dimension and the expected one.
double parse_quantity(std::string_view text, Dimension expected);

/// Converts an already parsed quantity to SI in `expected`, with the same rules and message as
/// parse_quantity(text, expected); `what` names the value in the message (a key, a parameter).
double quantity_in(const Quantity& q, Dimension expected, std::string_view what);

/// Metres per unit for the `--unit` of mesh files: "um" | "mm" | "m". Anything else throws
/// InputError naming the unit and the accepted ones.
double length_unit_scale(std::string_view unit);

/// A readable text of an SI value in a unit chosen by magnitude, e.g. 2.3e-4 m -> "230 um",
/// 8e4 Pa -> "80 kPa", 0.5236 rad -> "30 deg". For messages and summaries, not for parsing back
/// losslessly (6 significant digits).
std::string format_quantity(double value_si, Dimension d);

}  // namespace mneedle
