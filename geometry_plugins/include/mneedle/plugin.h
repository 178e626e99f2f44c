/*
 * mneedle tip-shape plugin ABI (plain C; compiles as C99 and as C++).
 *
 * A plugin is a shared library that exports exactly one symbol, MNEEDLE_PLUGIN_ENTRY_NAME
 * ("mneedle_plugin_entry"): a function returning a pointer to a static mneedle_plugin
 * description that stays valid until the library is unloaded. Only plain C data crosses
 * the boundary. See docs/plugins.md for the full rules.
 *
 * Versioning: the host refuses a plugin whose abi_major differs from its own. A minor
 * version only ever appends fields at the END of the structs below; the host reads a field
 * introduced in minor m only when the plugin's abi_minor >= m.
 *
 * Units: every parameter value passed to a plugin is in SI (metres, radians, or 1 for
 * counts and ratios); generated coordinates are metres in the needle frame (tip lowest at
 * z = 0, body along +z, the needle axis is the z axis).
 *
 * Memory protocol (host-owned output): generate() computes its mesh, then calls
 * sink->allocate(sink, vertex_count, triangle_count) ONCE it knows the sizes. On success
 * the host has set sink->vertices (3 * vertex_count doubles, x y z per vertex) and
 * sink->triangles (3 * triangle_count uint32 vertex indices, counter-clockwise seen from
 * outside) to host-owned arrays, which the plugin fills before returning. Calling allocate
 * again discards the previous arrays. The plugin never frees or keeps these pointers.
 *
 * Errors: every function returns an mneedle_status. On failure it writes a one-line,
 * NUL-terminated message (truncated to message_size bytes) into the caller's buffer.
 * No exception, longjmp or abort may leave a plugin function: C++ plugins catch everything.
 *
 * Threading: if a shape sets thread_safe = 1 the host may call its functions from several
 * threads at once; otherwise the host serialises all calls to that shape.
 */
#ifndef MNEEDLE_PLUGIN_H
#define MNEEDLE_PLUGIN_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define MNEEDLE_PLUGIN_ABI_MAJOR 1
#define MNEEDLE_PLUGIN_ABI_MINOR 0
#define MNEEDLE_PLUGIN_ENTRY_NAME "mneedle_plugin_entry"

/* Marks the entry function as the library's one exported symbol. Build plugins with
 * -fvisibility=hidden so that nothing else is exported. */
#ifdef __cplusplus
#define MNEEDLE_PLUGIN_EXPORT extern "C" __attribute__((visibility("default")))
#else
#define MNEEDLE_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

typedef int32_t mneedle_status;
#define MNEEDLE_STATUS_OK 0
/* A parameter value or combination the shape cannot build (e.g. bore >= diameter). */
#define MNEEDLE_STATUS_INVALID_PARAMETER 1
/* allocate() failed or the plugin ran out of memory. */
#define MNEEDLE_STATUS_OUT_OF_MEMORY 2
/* Anything else that went wrong inside the plugin. */
#define MNEEDLE_STATUS_INTERNAL_ERROR 3

/* One parameter of a shape. unit is "m" (lengths), "rad" (angles) or "1" (counts, ratios).
 * default_value, min_value and max_value are in that unit; the host rejects values outside
 * [min_value, max_value] before calling the plugin. */
typedef struct mneedle_parameter {
  const char* name;
  const char* unit;
  double default_value;
  double min_value;
  double max_value;
  const char* help; /* one line */
} mneedle_parameter;

/* Host-owned output buffers; see "Memory protocol" above. */
typedef struct mneedle_mesh_sink mneedle_mesh_sink;
struct mneedle_mesh_sink {
  void* host_data; /* opaque to the plugin */
  mneedle_status (*allocate)(mneedle_mesh_sink* sink, size_t vertex_count, size_t triangle_count);
  double* vertices;    /* set by allocate(): 3 * vertex_count */
  uint32_t* triangles; /* set by allocate(): 3 * triangle_count */
};

/* One tip shape. params always holds parameter_count values, in the order of parameters[],
 * in SI. */
typedef struct mneedle_shape {
  const char* name; /* unique across all loaded plugins, [a-z0-9_] */
  const char* help; /* one line */
  const mneedle_parameter* parameters;
  size_t parameter_count;
  int32_t thread_safe; /* 1: callable from several threads at once; 0: host serialises */

  /* Required: a closed, manifold, outward-oriented triangle mesh in the needle frame. */
  mneedle_status (*generate)(const double* params, size_t param_count, mneedle_mesh_sink* out,
                             char* message, size_t message_size);

  /* Optional (NULL when absent): solid cross-section area (m^2) at height h (m) above the
   * tip, with hollow bores subtracted; 0 outside the needle. */
  mneedle_status (*section_area)(const double* params, size_t param_count, double h,
                                 double* area_m2, char* message, size_t message_size);

  /* Optional (NULL when absent): area (m^2) and the smaller principal second moment of
   * area about the section's centroid (m^4) at height h (m) above the tip. */
  mneedle_status (*section_properties)(const double* params, size_t param_count, double h,
                                       double* area_m2, double* i_min_m4, char* message,
                                       size_t message_size);
} mneedle_shape;

typedef struct mneedle_plugin {
  uint32_t abi_major;    /* MNEEDLE_PLUGIN_ABI_MAJOR; first so any host can check it */
  uint32_t abi_minor;    /* MNEEDLE_PLUGIN_ABI_MINOR the plugin was built against */
  const char* plugin_id; /* e.g. "org.example.pyramid" */
  const mneedle_shape* shapes;
  size_t shape_count;
} mneedle_plugin;

/* The one exported symbol. Must not fail; returns a pointer to static data. */
typedef const mneedle_plugin* (*mneedle_plugin_entry_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* MNEEDLE_PLUGIN_H */
