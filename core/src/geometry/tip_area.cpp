#include "mneedle/geometry/tip_area.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "mneedle/base/error.h"

namespace mneedle {
namespace {

void require(bool ok, const std::string& problem) {
  if (!ok) throw InputError("tip area: " + problem);
}

void check_angle(double angle, const char* field) {
  require(angle > 0.0 && angle < std::numbers::pi / 2.0,
          std::string(field) + " = " + std::to_string(angle) + " rad is outside (0, pi/2)");
}

void check_geometry(const TipGeometry& g) {
  require(g.radius_m > 0.0 && std::isfinite(g.radius_m), "radius must be positive");
  require(g.bore_radius_m >= 0.0 && g.bore_radius_m < g.radius_m,
          "bore radius must lie in [0, radius)");
  if (g.shape == TipShape::sharp_bevel || g.shape == TipShape::blunt_bevel) {
    check_angle(g.bevel_angle_rad, "bevel_angle");
  }
  if (g.shape == TipShape::blunt_bevel) {
    require(g.flat_width_m >= 0.0 && g.flat_width_m <= 2.0 * g.radius_m,
            "flat_width must lie in [0, diameter]");
  }
  if (g.shape == TipShape::cone) {
    check_angle(g.half_angle_rad, "half_angle");
    require(g.tip_radius_m >= 0.0, "tip_radius must not be negative");
  }
}

// The bevel plane cuts both the shaft and the bore along the same chord.
double bevel_area(const TipGeometry& g, double h) {
  const double b = g.radius_m - h * std::tan(g.bevel_angle_rad);
  const double bore = g.bore_radius_m > 0.0 ? circular_segment_area(g.bore_radius_m, b) : 0.0;
  return circular_segment_area(g.radius_m, b) - bore;
}

double cone_section_radius(const TipGeometry& g, double h) {
  const double c = g.tip_radius_m;
  const double alpha = g.half_angle_rad;
  const double tangent_height = c * (1.0 - std::sin(alpha));
  double rho = 0.0;
  if (h <= tangent_height) {
    rho = std::sqrt(std::max(0.0, 2.0 * c * h - h * h));
  } else {
    // The capped cone's virtual apex sits c / sin(alpha) - c below the cap's lowest point.
    rho = (h + c / std::sin(alpha) - c) * std::tan(alpha);
  }
  return std::min(rho, g.radius_m);
}

}  // namespace

double circular_segment_area(double radius, double chord_distance) {
  const double ratio = std::clamp(chord_distance / radius, -1.0, 1.0);
  const double b = ratio * radius;
  return radius * radius * std::acos(ratio) - b * std::sqrt(std::max(0.0, radius * radius - b * b));
}

double full_section_area(const TipGeometry& g) {
  return std::numbers::pi * (g.radius_m * g.radius_m - g.bore_radius_m * g.bore_radius_m);
}

double tip_area(const TipGeometry& g, double height_m) {
  check_geometry(g);
  if (!(height_m >= 0.0)) return 0.0;
  switch (g.shape) {
    case TipShape::cylinder:
      return full_section_area(g);
    case TipShape::sharp_bevel:
      return bevel_area(g, height_m);
    case TipShape::blunt_bevel:
      return bevel_area(g, height_m + g.flat_width_m / std::tan(g.bevel_angle_rad));
    case TipShape::cone: {
      const double rho = cone_section_radius(g, height_m);
      const double bore = std::min(g.bore_radius_m, rho);
      return std::numbers::pi * (rho * rho - bore * bore);
    }
  }
  return 0.0;
}

}  // namespace mneedle
