#pragma once
// Glue between the C ABI (mneedle/plugin.h) and the C++ shape code of the built-in plugins:
// shared parameter descriptors, exception-free entry wrappers and mesh output.

#include <mneedle/plugin.h>

#include <cmath>
#include <cstddef>
#include <exception>
#include <new>
#include <string>

#include "shape_kit.h"

namespace mneedle::shape_kit {

// Parameters every built-in shape takes, in this order, first. Defaults are paper A's needle.
inline constexpr mneedle_parameter kDiameterParameter{
    "diameter", "m", 230e-6, 10e-6, 10e-3, "outer diameter of the shaft"};
inline constexpr mneedle_parameter kLengthParameter{
    "length", "m", 1000e-6, 20e-6, 100e-3, "needle length from the tip to the base"};
inline constexpr mneedle_parameter kBoreParameter{
    "bore", "m", 0.0, 0.0, 10e-3, "diameter of the bore along the axis; 0 = solid needle"};
// 64 sides keep the polygon's area within 0.17% of the circle's.
inline constexpr mneedle_parameter kResolutionParameter{
    "resolution", "1", 64, 8, 2048, "polygon segments around the circumference"};
inline constexpr std::size_t kCommonParameterCount = 4;

/// The common parameters, read from the start of a parameter vector (SI).
struct TubeParameters {
  double radius_m;
  double length_m;
  double bore_radius_m;
  int segments;
};
TubeParameters read_tube_parameters(const double* params);

/// The bevelled tube of `tube`, its cut at atan(tan_angle) to the axis, every edge of the cut
/// rounded to tip_radius; with flat_width > 0 the blunt bevel's flat (shape_kit's RoundedBevel).
inline RoundedBevel rounded_bevel_of(const TubeParameters& tube, double tan_angle,
                                     double tip_radius, double flat_width = 0.0) {
  return {.outer_radius_m = tube.radius_m,
          .bore_radius_m = tube.bore_radius_m,
          .tan_angle = tan_angle,
          .edge_radius_m = tip_radius,
          .length_m = tube.length_m,
          .segments = tube.segments,
          .flat_width_m = flat_width};
}

void write_message(char* buffer, std::size_t size, const char* text) noexcept;

/// Runs body() and turns every exception into a status and a message: nothing may unwind
/// across the C boundary.
template <class Body>
mneedle_status guarded(char* message, std::size_t message_size, Body&& body) noexcept {
  try {
    return body();
  } catch (const ParameterError& e) {
    write_message(message, message_size, e.what());
    return MNEEDLE_STATUS_INVALID_PARAMETER;
  } catch (const std::bad_alloc&) {
    write_message(message, message_size, "out of memory");
    return MNEEDLE_STATUS_OUT_OF_MEMORY;
  } catch (const std::exception& e) {
    write_message(message, message_size, e.what());
    return MNEEDLE_STATUS_INTERNAL_ERROR;
  } catch (...) {
    write_message(message, message_size, "unknown error");
    return MNEEDLE_STATUS_INTERNAL_ERROR;
  }
}

void check_parameter_count(std::size_t given, std::size_t expected);

/// Copies a finished mesh into the host's buffers (allocate once, then fill).
mneedle_status emit_mesh(const MeshBuilder& mesh, mneedle_mesh_sink* out);

/// A shape's generator: parameters (SI) to mesh.
using MeshFunction = MeshBuilder (*)(const double* params);
/// A shape's analytic section at height h above the tip.
using SectionFunction = SectionProperties (*)(const double* params, double h_m);

template <MeshFunction Make, std::size_t ParameterCount>
mneedle_status generate_hook(const double* params, std::size_t count, mneedle_mesh_sink* out,
                             char* message, std::size_t message_size) {
  return guarded(message, message_size, [&] {
    check_parameter_count(count, ParameterCount);
    return emit_mesh(Make(params), out);
  });
}

template <SectionFunction Section, std::size_t ParameterCount>
mneedle_status section_area_hook(const double* params, std::size_t count, double h, double* area_m2,
                                 char* message, std::size_t message_size) {
  return guarded(message, message_size, [&] {
    check_parameter_count(count, ParameterCount);
    if (!std::isfinite(h)) throw ParameterError("height must be finite");
    *area_m2 = Section(params, h).area_m2;
    return MNEEDLE_STATUS_OK;
  });
}

template <SectionFunction Section, std::size_t ParameterCount>
mneedle_status section_properties_hook(const double* params, std::size_t count, double h,
                                       double* area_m2, double* i_min_m4, char* message,
                                       std::size_t message_size) {
  return guarded(message, message_size, [&] {
    check_parameter_count(count, ParameterCount);
    if (!std::isfinite(h)) throw ParameterError("height must be finite");
    const SectionProperties s = Section(params, h);
    *area_m2 = s.area_m2;
    *i_min_m4 = s.i_min_m4;
    return MNEEDLE_STATUS_OK;
  });
}

}  // namespace mneedle::shape_kit
