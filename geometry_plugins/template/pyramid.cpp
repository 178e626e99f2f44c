// Example mneedle tip-shape plugin: a square pyramid, apex at the origin, base at z = length.
//
// Copy this folder, rename the shape, and build it against an installed mneedle:
//   cmake -S . -B build -DCMAKE_PREFIX_PATH=<mneedle prefix> && cmake --build build
//   mneedle plugins describe pyramid --plugin-dir build
//   mneedle generate pyramid --plugin-dir build --set base_width=200um -o pyramid.stl
//
// The rules (docs/plugins.md): export only mneedle_plugin_entry; parameters arrive in SI in
// the order of the descriptor array; write the mesh into the host's buffers through
// sink->allocate; never let an exception leave a plugin function; report problems with a
// status and a one-line message.
#include <mneedle/plugin.h>

#include <cstring>
#include <exception>
#include <iterator>

namespace {

// Parameter descriptors: name, unit ("m", "rad" or "1"), default, min, max, help. The host
// checks the bounds before calling; cross-parameter checks are the plugin's job.
constexpr mneedle_parameter kParameters[] = {
    {"base_width", "m", 200e-6, 10e-6, 5e-3, "side of the square base"},
    {"length", "m", 600e-6, 10e-6, 20e-3, "height from the apex to the base"},
};
enum { kBaseWidth, kLength, kParameterCount = std::size(kParameters) };

void write_message(char* buffer, size_t size, const char* text) noexcept {
  if (buffer == nullptr || size == 0) return;
  std::strncpy(buffer, text, size - 1);
  buffer[size - 1] = '\0';
}

// Every entry point funnels through here so no exception crosses into the host.
template <class Body>
mneedle_status guarded(char* message, size_t message_size, Body&& body) noexcept {
  try {
    return body();
  } catch (const std::exception& e) {
    write_message(message, message_size, e.what());
  } catch (...) {
    write_message(message, message_size, "unknown error");
  }
  return MNEEDLE_STATUS_INTERNAL_ERROR;
}

mneedle_status generate(const double* p, size_t count, mneedle_mesh_sink* out, char* message,
                        size_t message_size) {
  return guarded(message, message_size, [&]() -> mneedle_status {
    if (count != kParameterCount) {
      write_message(message, message_size, "wrong parameter count");
      return MNEEDLE_STATUS_INVALID_PARAMETER;
    }
    const double half = p[kBaseWidth] / 2, top = p[kLength];
    // Vertex 0 is the apex; 1-4 the base corners counter-clockwise seen from +z.
    const double vertices[] = {0,   0,     0,    half, -half, top,   half, half,
                               top, -half, half, top,  -half, -half, top};
    // Counter-clockwise seen from outside: sides face outward, the base faces +z.
    const uint32_t triangles[] = {0, 2, 1, 0, 3, 2, 0, 4, 3, 0, 1, 4, 1, 2, 3, 1, 3, 4};
    const size_t vertex_count = std::size(vertices) / 3, triangle_count = std::size(triangles) / 3;
    // Memory protocol: ask the host for buffers of the final size, then fill them.
    if (const mneedle_status s = out->allocate(out, vertex_count, triangle_count);
        s != MNEEDLE_STATUS_OK) {
      return s;
    }
    std::memcpy(out->vertices, vertices, sizeof vertices);
    std::memcpy(out->triangles, triangles, sizeof triangles);
    return MNEEDLE_STATUS_OK;
  });
}

// Optional analytic hooks: the square section of side s = base_width·h/length at height h.
mneedle_status section_properties(const double* p, size_t count, double h, double* area_m2,
                                  double* i_min_m4, char* message, size_t message_size) {
  return guarded(message, message_size, [&]() -> mneedle_status {
    if (count != kParameterCount) return MNEEDLE_STATUS_INVALID_PARAMETER;
    const double side = (h < 0 || h > p[kLength]) ? 0 : p[kBaseWidth] * h / p[kLength];
    *area_m2 = side * side;
    if (i_min_m4 != nullptr) *i_min_m4 = side * side * side * side / 12;
    return MNEEDLE_STATUS_OK;
  });
}

mneedle_status section_area(const double* p, size_t count, double h, double* area_m2, char* message,
                            size_t message_size) {
  return section_properties(p, count, h, area_m2, nullptr, message, message_size);
}

constexpr mneedle_shape kShapes[] = {{
    "pyramid",
    "square pyramid, apex at the tip (template plugin)",
    kParameters,
    kParameterCount,
    1,  // thread safe: no shared state
    generate,
    section_area,
    section_properties,
}};

constexpr mneedle_plugin kPlugin{MNEEDLE_PLUGIN_ABI_MAJOR, MNEEDLE_PLUGIN_ABI_MINOR,
                                 "org.example.pyramid", kShapes, std::size(kShapes)};

}  // namespace

MNEEDLE_PLUGIN_EXPORT const mneedle_plugin* mneedle_plugin_entry(void) {
  return &kPlugin;
}
