// Test plugin: shapes that misbehave in every way the loader must survive and report.
#include <mneedle/plugin.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <thread>

namespace {

constexpr mneedle_parameter kParameters[] = {
    {"size", "m", 1e-3, 1e-4, 1e-2, "edge length"},
};

void write_message(char* buffer, size_t size, const char* text) {
  if (size == 0) return;
  std::strncpy(buffer, text, size - 1);
  buffer[size - 1] = '\0';
}

// A closed, outward tetrahedron of edge scale `size`, tip (0,0,0) lowest.
mneedle_status emit_tetrahedron(double size, mneedle_mesh_sink* out, bool close) {
  const double v[] = {0, 0, 0, size, 0, size, 0, size, size, -size, -size, size};
  const uint32_t t[] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  const size_t triangles = close ? 4 : 3;
  if (const mneedle_status s = out->allocate(out, 4, triangles); s != MNEEDLE_STATUS_OK) return s;
  std::memcpy(out->vertices, v, sizeof v);
  std::memcpy(out->triangles, t, triangles * 3 * sizeof(uint32_t));
  return MNEEDLE_STATUS_OK;
}

mneedle_status failing(const double*, size_t, mneedle_mesh_sink*, char* message, size_t size) {
  write_message(message, size, "this shape always fails");
  return MNEEDLE_STATUS_INVALID_PARAMETER;
}

// The exception is thrown and caught inside the plugin, as the ABI demands.
mneedle_status throwing(const double*, size_t, mneedle_mesh_sink*, char* message, size_t size) {
  try {
    throw std::runtime_error("thrown inside the plugin");
  } catch (const std::exception& e) {
    write_message(message, size, e.what());
    return MNEEDLE_STATUS_INTERNAL_ERROR;
  }
}

mneedle_status open_mesh(const double* p, size_t, mneedle_mesh_sink* out, char*, size_t) {
  return emit_tetrahedron(p[0], out, false);
}

mneedle_status bad_index(const double* p, size_t, mneedle_mesh_sink* out, char*, size_t) {
  const mneedle_status s = emit_tetrahedron(p[0], out, true);
  if (s == MNEEDLE_STATUS_OK) out->triangles[5] = 99;
  return s;
}

mneedle_status no_mesh(const double*, size_t, mneedle_mesh_sink*, char*, size_t) {
  return MNEEDLE_STATUS_OK;
}

mneedle_status tetrahedron(const double* p, size_t, mneedle_mesh_sink* out, char*, size_t) {
  return emit_tetrahedron(p[0], out, true);
}

// Declared not thread safe: fails if the host ever lets two calls overlap.
std::atomic<int> g_in_flight{0};
mneedle_status serial_only(const double* p, size_t, mneedle_mesh_sink* out, char* message,
                           size_t size) {
  const bool overlapped = g_in_flight.fetch_add(1) != 0;
  std::this_thread::sleep_for(std::chrono::milliseconds(5));
  g_in_flight.fetch_sub(1);
  if (overlapped) {
    write_message(message, size, "called concurrently");
    return MNEEDLE_STATUS_INTERNAL_ERROR;
  }
  return emit_tetrahedron(p[0], out, true);
}

// The tetrahedron 50 um above the origin: outside the needle frame's contract.
mneedle_status lifted(const double* p, size_t, mneedle_mesh_sink* out, char*, size_t) {
  const mneedle_status s = emit_tetrahedron(p[0], out, true);
  if (s == MNEEDLE_STATUS_OK)
    for (int v = 0; v < 4; ++v) out->vertices[3 * v + 2] += 50e-6;
  return s;
}

// A needle given in micrometres as if they were metres: 600 "m" long.
mneedle_status micrometres(const double*, size_t, mneedle_mesh_sink* out, char*, size_t) {
  return emit_tetrahedron(600.0, out, true);
}

// A message over two lines.
mneedle_status two_lines(const double*, size_t, mneedle_mesh_sink*, char* message, size_t size) {
  write_message(message, size, "line one\nline two");
  return MNEEDLE_STATUS_INVALID_PARAMETER;
}

mneedle_status negative_area(const double*, size_t, double, double* area, char*, size_t) {
  *area = -1;
  return MNEEDLE_STATUS_OK;
}

constexpr mneedle_shape Shape(const char* name, decltype(mneedle_shape::generate) generate,
                              int thread_safe = 1) {
  return {name,        "test shape", kParameters, std::size(kParameters),
          thread_safe, generate,     nullptr,     nullptr};
}

constexpr mneedle_shape kShapes[] = {
    Shape("failing", failing),
    Shape("throwing", throwing),
    Shape("open_mesh", open_mesh),
    Shape("bad_index", bad_index),
    Shape("no_mesh", no_mesh),
    Shape("serial_only", serial_only, 0),
    Shape("lifted", lifted),
    Shape("micrometres", micrometres),
    Shape("two_lines", two_lines),
    {"negative_area", "test shape", kParameters, 1, 1, tetrahedron, negative_area, nullptr},
};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "test.bad_shapes", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
