#include "mneedle/base/units.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <system_error>

#include "mneedle/base/error.h"
#include "mneedle/base/text.h"

namespace mneedle {
namespace {

struct UnitDef {
  std::string_view symbol;
  double to_si;  // factor to SI
  Dimension dimension;
};

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kPsi = 6894.757293168361;  // Pa per lbf/in^2 (exact by definition of lbf, in)

// Spellings that users type; the ASCII ones come first because messages list only those.
constexpr std::array kUnits{
    UnitDef{"nm", 1e-9, Dimension::Length},
    UnitDef{"um", 1e-6, Dimension::Length},
    UnitDef{"mm", 1e-3, Dimension::Length},
    UnitDef{"cm", 1e-2, Dimension::Length},
    UnitDef{"m", 1.0, Dimension::Length},
    UnitDef{"\xC2\xB5m", 1e-6, Dimension::Length},  // micro sign
    UnitDef{"\xCE\xBCm", 1e-6, Dimension::Length},  // Greek mu
    UnitDef{"deg", kDegree, Dimension::Angle},
    UnitDef{"rad", 1.0, Dimension::Angle},
    UnitDef{"mrad", 1e-3, Dimension::Angle},
    UnitDef{"\xC2\xB0", kDegree, Dimension::Angle},
    UnitDef{"Pa", 1.0, Dimension::Pressure},
    UnitDef{"kPa", 1e3, Dimension::Pressure},
    UnitDef{"MPa", 1e6, Dimension::Pressure},
    UnitDef{"GPa", 1e9, Dimension::Pressure},
    UnitDef{"psi", kPsi, Dimension::Pressure},
    UnitDef{"N", 1.0, Dimension::Force},
    UnitDef{"mN", 1e-3, Dimension::Force},
    UnitDef{"uN", 1e-6, Dimension::Force},
    UnitDef{"kN", 1e3, Dimension::Force},
    UnitDef{"\xC2\xB5N", 1e-6, Dimension::Force},
    UnitDef{"\xCE\xBCN", 1e-6, Dimension::Force},
    // Energy per unit length (paper C's strain energy per unit crack length) is a force.
    UnitDef{"J/m", 1.0, Dimension::Force},
    UnitDef{"mJ/m", 1e-3, Dimension::Force},
    UnitDef{"m/s", 1.0, Dimension::Speed},
    UnitDef{"mm/s", 1e-3, Dimension::Speed},
    UnitDef{"um/s", 1e-6, Dimension::Speed},
    UnitDef{"\xC2\xB5m/s", 1e-6, Dimension::Speed},
    UnitDef{"\xCE\xBCm/s", 1e-6, Dimension::Speed},
    UnitDef{"s", 1.0, Dimension::Time},
    UnitDef{"ms", 1e-3, Dimension::Time},
    UnitDef{"J/m^2", 1.0, Dimension::Toughness},
    UnitDef{"J/m2", 1.0, Dimension::Toughness},
    UnitDef{"kJ/m^2", 1e3, Dimension::Toughness},
    UnitDef{"kJ/m2", 1e3, Dimension::Toughness},
    UnitDef{"mJ/m^2", 1e-3, Dimension::Toughness},
    UnitDef{"mJ/m2", 1e-3, Dimension::Toughness},
    UnitDef{"J/m\xC2\xB2", 1.0, Dimension::Toughness},
    UnitDef{"J", 1.0, Dimension::Energy},
    UnitDef{"mJ", 1e-3, Dimension::Energy},
    UnitDef{"uJ", 1e-6, Dimension::Energy},
    UnitDef{"\xC2\xB5J", 1e-6, Dimension::Energy},
    UnitDef{"\xCE\xBCJ", 1e-6, Dimension::Energy},
    UnitDef{"N/m", 1.0, Dimension::Stiffness},
    UnitDef{"N/mm", 1e3, Dimension::Stiffness},
    UnitDef{"kg/m^3", 1.0, Dimension::Density},
    UnitDef{"kg/m3", 1.0, Dimension::Density},
    UnitDef{"g/cm^3", 1e3, Dimension::Density},
    UnitDef{"g/cm3", 1e3, Dimension::Density},
    UnitDef{"kg/m\xC2\xB3", 1.0, Dimension::Density},
    UnitDef{"Pa s", 1.0, Dimension::Viscosity},
    UnitDef{"Pa*s", 1.0, Dimension::Viscosity},
    UnitDef{"Pa.s", 1.0, Dimension::Viscosity},
    UnitDef{"mPa s", 1e-3, Dimension::Viscosity},
    UnitDef{"mPa*s", 1e-3, Dimension::Viscosity},
    UnitDef{"mPa.s", 1e-3, Dimension::Viscosity},
};

bool is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

// "Pa   s" and "Pa s" are the same unit: runs of blanks count as one.
std::string collapse_blanks(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (is_space(c)) {
      if (!out.empty() && out.back() != ' ') out.push_back(' ');
    } else {
      out.push_back(c);
    }
  }
  return out;
}

bool is_ascii(std::string_view s) {
  for (char c : s) {
    if (static_cast<unsigned char>(c) > 127) return false;
  }
  return true;
}

std::optional<UnitDef> find_unit(std::string_view symbol) {
  for (const auto& u : kUnits) {
    if (u.symbol == symbol) return u;
  }
  return std::nullopt;
}

// The units accepted for `d`, e.g. "nm, um, mm, cm, m"; Toughness and Stiffness list both.
std::string unit_list(Dimension d) {
  std::string out;
  for (const auto& u : kUnits) {
    if (!dimensions_compatible(u.dimension, d) || !is_ascii(u.symbol)) continue;
    if (!out.empty()) out += ", ";
    out += u.symbol;
  }
  return out;
}

std::string quoted(std::string_view text) {
  std::string out(1, '"');
  out += text;
  out += '"';
  return out;
}

std::string_view article_for(std::string_view word) {
  return (!word.empty() && std::string_view("aeiou").find(word.front()) != std::string_view::npos)
             ? "an"
             : "a";
}

struct Parsed {
  double number;
  std::string unit;  // blanks collapsed; empty for a plain number
};

// number × factor, except for a submultiple whose inverse is a whole number (um, mm, mN): there
// number ÷ inverse, which IEEE rounds correctly, so "10 um" is the double nearest 1e-5 — the value
// a plugin's bound "10e-6" holds — not 10 × 1e-6 = 9.999…e-6.
double to_si(double number, double factor) {
  if (factor < 1.0) {
    const double inverse = std::round(1.0 / factor);
    if (std::abs(1.0 / factor - inverse) <= 1e-9 * inverse) return number / inverse;
  }
  return number * factor;
}

Parsed split_number_and_unit(std::string_view text) {
  const std::string_view t = trim(text);
  if (t.empty()) {
    throw InputError("empty quantity; expected a number with a unit such as \"230 um\"");
  }
  std::string_view digits = t;
  if (digits.front() == '+') digits.remove_prefix(1);
  double number = 0.0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), number);
  if (ec == std::errc::result_out_of_range) {
    throw InputError(quoted(text) + ": number out of range");
  }
  if (ec != std::errc() || end == digits.data()) {
    throw InputError(quoted(text) + ": expected a number first, such as \"230 um\"");
  }
  if (!std::isfinite(number)) {
    throw InputError(quoted(text) + ": not a finite number");
  }
  const auto consumed = static_cast<std::size_t>(end - digits.data());
  return {number, collapse_blanks(trim(digits.substr(consumed)))};
}

}  // namespace

std::string unit_names(Dimension d) {
  return unit_list(d);
}

std::string_view dimension_name(Dimension d) {
  switch (d) {
    case Dimension::Dimensionless:
      return "dimensionless";
    case Dimension::Length:
      return "length";
    case Dimension::Angle:
      return "angle";
    case Dimension::Pressure:
      return "pressure";
    case Dimension::Force:
      return "force";
    case Dimension::Speed:
      return "speed";
    case Dimension::Time:
      return "time";
    case Dimension::Toughness:
      return "toughness";
    case Dimension::Density:
      return "density";
    case Dimension::Viscosity:
      return "viscosity";
    case Dimension::Stiffness:
      return "stiffness";
    case Dimension::Energy:
      return "energy";
  }
  return "unknown";
}

std::string_view si_unit(Dimension d) {
  switch (d) {
    case Dimension::Dimensionless:
      return "";
    case Dimension::Length:
      return "m";
    case Dimension::Angle:
      return "rad";
    case Dimension::Pressure:
      return "Pa";
    case Dimension::Force:
      return "N";
    case Dimension::Speed:
      return "m/s";
    case Dimension::Time:
      return "s";
    case Dimension::Toughness:
      return "J/m^2";
    case Dimension::Density:
      return "kg/m^3";
    case Dimension::Viscosity:
      return "Pa s";
    case Dimension::Stiffness:
      return "N/m";
    case Dimension::Energy:
      return "J";
  }
  return "";
}

bool dimensions_compatible(Dimension given, Dimension expected) {
  if (given == expected) return true;
  const auto newton_per_metre = [](Dimension d) {
    return d == Dimension::Toughness || d == Dimension::Stiffness;
  };
  return newton_per_metre(given) && newton_per_metre(expected);
}

Quantity parse_quantity(std::string_view text) {
  const Parsed p = split_number_and_unit(text);
  if (p.unit.empty()) return {p.number, Dimension::Dimensionless};
  const auto unit = find_unit(p.unit);
  if (!unit) throw InputError(quoted(text) + ": unknown unit '" + p.unit + "'");
  const double si = to_si(p.number, unit->to_si);
  if (!std::isfinite(si)) throw InputError(quoted(text) + ": value overflows in SI units");
  return {si, unit->dimension};
}

double parse_quantity(std::string_view text, Dimension expected) {
  const Parsed p = split_number_and_unit(text);
  if (!p.unit.empty() && !find_unit(p.unit)) {
    std::string msg = quoted(text) + ": unknown unit '" + p.unit + "'";
    if (expected != Dimension::Dimensionless) {
      msg += " (" + std::string(dimension_name(expected)) + " units: " + unit_list(expected) + ")";
    } else {
      msg += " (expected a plain number)";
    }
    throw InputError(msg);
  }
  return quantity_in(parse_quantity(text), expected, quoted(text));
}

double quantity_in(const Quantity& q, Dimension expected, std::string_view what) {
  // A plain number where a unit is needed is a guess about the unit (was "20" metres or
  // micrometres?): refused, except 0, which is 0 in every unit.
  if (q.dimension == Dimension::Dimensionless && expected != Dimension::Dimensionless &&
      q.value_si != 0.0) {
    throw InputError(std::string(what) +
                     " needs a unit: " + std::string(article_for(dimension_name(expected))) + " " +
                     std::string(dimension_name(expected)) + " (" + unit_list(expected) + ")");
  }
  if (q.dimension == Dimension::Dimensionless || dimensions_compatible(q.dimension, expected)) {
    return q.value_si;
  }
  const std::string_view given = dimension_name(q.dimension);
  std::string msg = std::string(what) + " is " + std::string(article_for(given)) + " " +
                    std::string(given) + "; expected ";
  if (expected == Dimension::Dimensionless) {
    msg += "a plain number";
  } else {
    const std::string_view want = dimension_name(expected);
    msg +=
        std::string(article_for(want)) + " " + std::string(want) + " (" + unit_list(expected) + ")";
  }
  throw InputError(msg);
}

double length_unit_scale(std::string_view unit) {
  if (unit == "um") return 1e-6;
  if (unit == "mm") return 1e-3;
  if (unit == "m") return 1.0;
  throw InputError("unknown length unit '" + std::string(unit) + "'; expected um, mm or m");
}

std::string format_quantity(double value_si, Dimension d) {
  struct Scale {
    double below;  // use this unit when |value| < below
    double factor;
    std::string_view symbol;
  };
  const double a = std::fabs(value_si);
  const auto pick = [a](std::initializer_list<Scale> scales) {
    for (const auto& s : scales) {
      if (a < s.below) return s;
    }
    return *(scales.end() - 1);
  };
  Scale s{0, 1.0, si_unit(d)};
  constexpr double kInf = std::numeric_limits<double>::infinity();
  switch (d) {
    case Dimension::Length:
      if (a > 0)
        s = pick({{1e-6, 1e-9, "nm"}, {1e-3, 1e-6, "um"}, {1.0, 1e-3, "mm"}, {kInf, 1, "m"}});
      break;
    case Dimension::Pressure:
      s = pick({{1e3, 1, "Pa"}, {1e6, 1e3, "kPa"}, {1e9, 1e6, "MPa"}, {kInf, 1e9, "GPa"}});
      break;
    case Dimension::Force:
      if (a > 0) s = pick({{1e-3, 1e-6, "uN"}, {1.0, 1e-3, "mN"}, {kInf, 1, "N"}});
      break;
    case Dimension::Speed:
      if (a > 0) s = pick({{1e-3, 1e-6, "um/s"}, {1.0, 1e-3, "mm/s"}, {kInf, 1, "m/s"}});
      break;
    case Dimension::Time:
      if (a > 0) s = pick({{1.0, 1e-3, "ms"}, {kInf, 1, "s"}});
      break;
    case Dimension::Angle:
      s = {0, kDegree, "deg"};
      break;
    default:
      break;
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", value_si / s.factor);
  std::string out = buf;
  if (!s.symbol.empty()) {
    out += ' ';
    out += s.symbol;
  }
  return out;
}

}  // namespace mneedle
