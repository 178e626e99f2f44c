#include "plugin_glue.h"

#include <algorithm>
#include <cstring>

namespace mneedle::shape_kit {

TubeParameters read_tube_parameters(const double* params) {
  const TubeParameters tube{params[0] / 2, params[1], params[2] / 2, segment_count(params[3])};
  if (!(tube.radius_m > 0) || !(tube.length_m > 0)) {
    throw ParameterError("diameter and length must be positive");
  }
  if (!(tube.bore_radius_m >= 0) || tube.bore_radius_m >= tube.radius_m) {
    throw ParameterError("bore must be smaller than diameter");
  }
  return tube;
}

void write_message(char* buffer, std::size_t size, const char* text) noexcept {
  if (buffer == nullptr || size == 0) return;
  const std::size_t n = std::min(size - 1, std::strlen(text));
  std::memcpy(buffer, text, n);
  buffer[n] = '\0';
}

void check_parameter_count(std::size_t given, std::size_t expected) {
  if (given != expected) {
    throw ParameterError("expected " + std::to_string(expected) + " parameters, got " +
                         std::to_string(given));
  }
}

mneedle_status emit_mesh(const MeshBuilder& mesh, mneedle_mesh_sink* out) {
  if (out == nullptr || out->allocate == nullptr) return MNEEDLE_STATUS_INTERNAL_ERROR;
  const auto& vertices = mesh.vertices();
  const auto& triangles = mesh.triangles();
  const mneedle_status status = out->allocate(out, vertices.size(), triangles.size());
  if (status != MNEEDLE_STATUS_OK) return status;
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    out->vertices[3 * i] = vertices[i].x;
    out->vertices[3 * i + 1] = vertices[i].y;
    out->vertices[3 * i + 2] = vertices[i].z;
  }
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    std::copy(triangles[i].begin(), triangles[i].end(), out->triangles + 3 * i);
  }
  return MNEEDLE_STATUS_OK;
}

}  // namespace mneedle::shape_kit
