#include "mneedle/plugin_host.h"

#include <dlfcn.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>
#include <system_error>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/needle/mesh.h"
#include "mneedle/needle/mesh_validation.h"
#include "mneedle/plugin.h"
#include "plugin_descriptor.h"

#ifndef MNEEDLE_BUILTIN_PLUGIN_DIR
#error "MNEEDLE_BUILTIN_PLUGIN_DIR must name the build tree's plugin folder"
#endif
#ifndef MNEEDLE_INSTALLED_PLUGIN_RELDIR
#error "MNEEDLE_INSTALLED_PLUGIN_RELDIR must name the plugin folder relative to the prefix"
#endif

namespace mneedle {

namespace fs = std::filesystem;

namespace {

// Largest needle length (m) the metre contract allows: a plugin that writes micrometres as
// metres makes needles of hundreds of metres.
constexpr double kLongestNeedle = 1.0;

// The plugin contract's frame (docs/plugins.md): metres, the tip the lowest point at z = 0. A
// mesh outside it was used as it came (strength read its sections from the wrong heights).
void require_needle_frame(const TriangleMesh& mesh, const std::string& source) {
  const BoundingBox box = bounding_box(mesh);
  const double length = box.max[2] - box.min[2];
  if (std::abs(box.min[2]) > 1e-9 * length)
    throw InputError(source + ": the mesh's lowest point is at z = " +
                     format_quantity(box.min[2], Dimension::Length) +
                     ", not 0: the plugin contract puts the tip at the origin (docs/plugins.md)");
  if (length > kLongestNeedle)
    throw InputError(source + ": the needle is " + format_quantity(length, Dimension::Length) +
                     " long: the plugin contract is metres (a length in micrometres or "
                     "millimetres given as metres?)");
}

// Far beyond any needle mesh; guards the host against a plugin asking for absurd buffers.
constexpr std::size_t kMaxMeshElements = std::size_t{1} << 26;
constexpr std::size_t kMessageSize = 512;

struct ShapeEntry {
  const mneedle_shape* shape;
  std::shared_ptr<void> library;          // keeps the code of `shape` mapped
  std::shared_ptr<std::mutex> serialise;  // for shapes that are not thread safe
};

// One lock per shape in the process: two registries that load the same library (the Python
// module keeps one per plugin folder list) reach the same code, and a shape that is not thread
// safe must never run twice at once through either.
std::shared_ptr<std::mutex> shape_lock(const mneedle_shape* shape) {
  static std::mutex guard;
  static std::map<const mneedle_shape*, std::weak_ptr<std::mutex>> locks;
  const std::lock_guard<std::mutex> hold(guard);
  std::shared_ptr<std::mutex> lock = locks[shape].lock();
  if (!lock) {
    lock = std::make_shared<std::mutex>();
    locks[shape] = lock;
  }
  return lock;
}

struct HostBuffers {
  std::vector<double> vertices;
  std::vector<std::uint32_t> triangles;
  bool allocated = false;
};

mneedle_status allocate_buffers(mneedle_mesh_sink* sink, std::size_t vertex_count,
                                std::size_t triangle_count) {
  auto* buffers = static_cast<HostBuffers*>(sink->host_data);
  if (vertex_count > kMaxMeshElements || triangle_count > kMaxMeshElements) {
    return MNEEDLE_STATUS_OUT_OF_MEMORY;
  }
  try {
    buffers->vertices.assign(3 * vertex_count, 0.0);
    buffers->triangles.assign(3 * triangle_count, 0);
  } catch (...) {
    return MNEEDLE_STATUS_OUT_OF_MEMORY;
  }
  buffers->allocated = true;
  sink->vertices = buffers->vertices.data();
  sink->triangles = buffers->triangles.data();
  return MNEEDLE_STATUS_OK;
}

std::string status_name(mneedle_status status) {
  switch (status) {
    case MNEEDLE_STATUS_INVALID_PARAMETER:
      return "invalid parameter";
    case MNEEDLE_STATUS_OUT_OF_MEMORY:
      return "out of memory";
    case MNEEDLE_STATUS_INTERNAL_ERROR:
      return "internal error";
    default:
      return "status " + std::to_string(status);
  }
}

Dimension dimension_of_unit(const std::string& unit) {
  if (unit == "m") return Dimension::Length;
  if (unit == "rad") return Dimension::Angle;
  return Dimension::Dimensionless;
}

std::string join(const std::vector<std::string>& items, std::string_view separator) {
  std::string out;
  for (const auto& item : items) {
    if (!out.empty()) out += separator;
    out += item;
  }
  return out;
}

std::shared_ptr<void> open_library(const fs::path& library) {
  dlerror();
  void* handle = dlopen(library.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (handle == nullptr) {
    const char* why = dlerror();
    throw InputError(library.string() +
                     ": cannot load plugin: " + (why != nullptr ? why : "unknown dlopen error"));
  }
  return {handle, [](void* h) { dlclose(h); }};
}

const mneedle_plugin& plugin_description(void* handle, const fs::path& library) {
  dlerror();
  void* symbol = dlsym(handle, MNEEDLE_PLUGIN_ENTRY_NAME);
  if (symbol == nullptr) {
    throw InputError(library.string() + ": not an mneedle plugin (no symbol " +
                     MNEEDLE_PLUGIN_ENTRY_NAME + ")");
  }
  const auto entry = reinterpret_cast<mneedle_plugin_entry_fn>(symbol);
  return check_plugin_descriptor(entry(), library);
}

std::vector<fs::path> plugin_files(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (entry.is_regular_file(ec) && entry.path().extension() == ".so") {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<fs::path> plugin_path_from_environment(std::vector<std::string>& warnings) {
  std::vector<fs::path> dirs;
  const char* value = std::getenv("MNEEDLE_PLUGIN_PATH");
  if (value == nullptr) return dirs;
  std::stringstream entries(value);
  std::string entry;
  while (std::getline(entries, entry, ':')) {
    if (entry.empty()) continue;
    // A relative entry would depend on the current directory, which is never searched.
    if (fs::path(entry).is_relative()) {
      warnings.push_back("MNEEDLE_PLUGIN_PATH: ignoring relative folder '" + entry + "'");
      continue;
    }
    dirs.emplace_back(entry);
  }
  return dirs;
}

std::string format_value(double value, const std::string& unit) {
  if (unit == "1") {
    std::ostringstream out;
    out << value;
    return out.str();
  }
  return format_quantity(value, dimension_of_unit(unit));
}

}  // namespace

struct PluginRegistry::Impl {
  std::vector<PluginShapeInfo> infos;
  std::vector<ShapeEntry> entries;  // parallel to infos
  std::vector<std::string> warnings;
  std::vector<std::string> searched;  // the folders discover() looked in, in order

  std::size_t index_of(std::string_view name) const {
    for (std::size_t i = 0; i < infos.size(); ++i) {
      if (infos[i].name == name) return i;
    }
    std::vector<std::string> known;
    for (const auto& info : infos) known.push_back(info.name);
    std::string message = "unknown tip shape '" + std::string(name) +
                          "' (known: " + (known.empty() ? std::string("none") : join(known, ", ")) +
                          ")";
    if (!searched.empty())
      message += "; looked in " + join(searched, ", ") +
                 " (add a folder with --plugin-dir DIR or MNEEDLE_PLUGIN_PATH)";
    if (!warnings.empty()) message += "; plugin problems: " + join(warnings, "; ");
    throw InputError(message);
  }

  // Runs a plugin call under the shape's lock when it is not thread safe.
  template <class Call>
  mneedle_status call(std::size_t index, Call&& body) const {
    const ShapeEntry& entry = entries[index];
    if (entry.serialise) {
      std::lock_guard lock(*entry.serialise);
      return body(*entry.shape);
    }
    return body(*entry.shape);
  }

  void check_status(std::size_t index, mneedle_status status, const char* message,
                    std::string_view action) const {
    if (status == MNEEDLE_STATUS_OK) return;
    const PluginShapeInfo& info = infos[index];
    std::string text = info.library.string() + ": shape '" + info.name + "' " +
                       std::string(action) + " failed (" + status_name(status) + ")";
    if (message[0] != '\0') {
      // One line, as every error (docs/cli.md, "Exit status"): line breaks become spaces.
      std::string said(message);
      std::replace_if(
          said.begin(), said.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
      text += ": " + said;
    }
    if (status == MNEEDLE_STATUS_INVALID_PARAMETER) throw InvalidShapeError(text);
    throw InputError(text);
  }
};

PluginRegistry::PluginRegistry() : impl_(std::make_unique<Impl>()) {}
PluginRegistry::~PluginRegistry() = default;
PluginRegistry::PluginRegistry(PluginRegistry&&) noexcept = default;
PluginRegistry& PluginRegistry::operator=(PluginRegistry&&) noexcept = default;

fs::path PluginRegistry::builtin_plugin_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / MNEEDLE_INSTALLED_PLUGIN_RELDIR;
    if (fs::is_directory(installed, ec)) return installed;
  }
  return fs::path(MNEEDLE_BUILTIN_PLUGIN_DIR);
}

PluginRegistry PluginRegistry::discover(const std::vector<fs::path>& extra_dirs) {
  return discover_from(builtin_plugin_dir(), extra_dirs);
}

PluginRegistry PluginRegistry::discover_from(const fs::path& builtin_dir,
                                             const std::vector<fs::path>& extra_dirs) {
  PluginRegistry registry;
  auto& warnings = registry.impl_->warnings;
  std::vector<fs::path> dirs{builtin_dir};
  const auto from_environment = plugin_path_from_environment(warnings);
  dirs.insert(dirs.end(), from_environment.begin(), from_environment.end());
  for (const auto& dir : extra_dirs) {
    if (!fs::is_directory(dir)) throw InputError("plugin folder '" + dir.string() + "' not found");
    dirs.push_back(dir);
  }
  for (const auto& dir : dirs) {
    registry.impl_->searched.push_back(dir.string());
    if (!fs::is_directory(dir)) {
      warnings.push_back("plugin folder '" + dir.string() + "' not found");
      continue;
    }
    for (const auto& file : plugin_files(dir)) {
      try {
        registry.load_library(file);
      } catch (const InputError& e) {
        warnings.emplace_back(e.what());
      }
    }
  }
  return registry;
}

void PluginRegistry::load_library(const fs::path& library) {
  std::shared_ptr<void> handle = open_library(library);
  const mneedle_plugin& plugin = plugin_description(handle.get(), library);
  // Check every shape before registering any, so a bad library adds nothing.
  std::vector<PluginShapeInfo> infos = read_plugin_shapes(plugin, library);
  for (const auto& info : infos)
    for (const auto& known : impl_->infos)
      if (known.name == info.name)
        throw InputError(library.string() + ": shape '" + known.name + "' is already provided by " +
                         known.library.string());
  for (std::size_t i = 0; i < infos.size(); ++i) {
    const mneedle_shape* shape = &plugin.shapes[i];
    impl_->entries.push_back({shape, handle, shape->thread_safe ? nullptr : shape_lock(shape)});
    impl_->infos.push_back(std::move(infos[i]));
  }
}

const std::vector<PluginShapeInfo>& PluginRegistry::shapes() const {
  return impl_->infos;
}

const PluginShapeInfo& PluginRegistry::shape(std::string_view name) const {
  return impl_->infos[impl_->index_of(name)];
}

const std::vector<std::string>& PluginRegistry::warnings() const {
  return impl_->warnings;
}

std::vector<double> PluginRegistry::resolve_parameters(
    std::string_view shape_name, const std::map<std::string, double>& si) const {
  const PluginShapeInfo& info = shape(shape_name);
  const std::string where = "shape '" + info.name + "'";
  std::vector<std::string> names;
  for (const auto& p : info.parameters) names.push_back(p.name);
  for (const auto& [name, value] : si) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      throw InputError(where + ": unknown parameter '" + name +
                       "' (parameters: " + join(names, ", ") + ")");
    }
  }
  std::vector<double> values;
  for (const auto& p : info.parameters) {
    const auto given = si.find(p.name);
    const double value = given == si.end() ? p.default_value : given->second;
    const std::string here = where + ": parameter '" + p.name + "' = " +
                             (std::isfinite(value) ? format_value(value, p.unit) : "non-finite");
    if (!std::isfinite(value)) throw InputError(here + " must be a finite number");
    if (value < p.min)
      throw InputError(here + " is below the minimum " + format_value(p.min, p.unit));
    if (value > p.max)
      throw InputError(here + " is above the maximum " + format_value(p.max, p.unit));
    values.push_back(value);
  }
  return values;
}

TriangleMesh PluginRegistry::generate(std::string_view shape_name,
                                      const std::map<std::string, double>& si) const {
  const std::size_t index = impl_->index_of(shape_name);
  const PluginShapeInfo& info = impl_->infos[index];
  const std::vector<double> params = resolve_parameters(shape_name, si);
  HostBuffers buffers;
  mneedle_mesh_sink sink{&buffers, allocate_buffers, nullptr, nullptr};
  std::array<char, kMessageSize> message{};
  const mneedle_status status = impl_->call(index, [&](const mneedle_shape& s) {
    return s.generate(params.data(), params.size(), &sink, message.data(), message.size());
  });
  message.back() = '\0';
  impl_->check_status(index, status, message.data(), "generate");
  const std::string source = info.library.string() + ": shape '" + info.name + "'";
  if (!buffers.allocated) throw InputError(source + ": generate returned no mesh");

  TriangleMesh mesh;
  const std::size_t vertex_count = buffers.vertices.size() / 3;
  for (std::size_t i = 0; i < vertex_count; ++i) {
    mesh.vertices.push_back(
        {buffers.vertices[3 * i], buffers.vertices[3 * i + 1], buffers.vertices[3 * i + 2]});
  }
  for (std::size_t i = 0; i < buffers.triangles.size(); i += 3) {
    const Triangle t{buffers.triangles[i], buffers.triangles[i + 1], buffers.triangles[i + 2]};
    for (const auto v : t) {
      if (v >= vertex_count) {
        throw InputError(source + ": triangle " + std::to_string(i / 3) + " uses vertex " +
                         std::to_string(v) + " of " + std::to_string(vertex_count));
      }
    }
    mesh.triangles.push_back(t);
  }
  require_valid_mesh(mesh, source);
  require_needle_frame(mesh, source);
  return mesh;
}

std::optional<double> PluginRegistry::section_area(std::string_view shape_name,
                                                   const std::map<std::string, double>& si,
                                                   double h_m) const {
  const std::size_t index = impl_->index_of(shape_name);
  if (!impl_->infos[index].has_section_area) return std::nullopt;
  const std::vector<double> params = resolve_parameters(shape_name, si);
  if (!std::isfinite(h_m)) throw InputError("section height must be finite");
  double area = 0;
  std::array<char, kMessageSize> message{};
  const mneedle_status status = impl_->call(index, [&](const mneedle_shape& s) {
    return s.section_area(params.data(), params.size(), h_m, &area, message.data(), message.size());
  });
  message.back() = '\0';
  impl_->check_status(index, status, message.data(), "section_area");
  if (!std::isfinite(area) || area < 0) {
    throw InputError(impl_->infos[index].library.string() + ": shape '" + std::string(shape_name) +
                     "' section_area returned a negative or non-finite area");
  }
  return area;
}

std::optional<PluginRegistry::SectionProperties> PluginRegistry::section_properties(
    std::string_view shape_name, const std::map<std::string, double>& si, double h_m) const {
  const std::size_t index = impl_->index_of(shape_name);
  if (!impl_->infos[index].has_section_properties) return std::nullopt;
  const std::vector<double> params = resolve_parameters(shape_name, si);
  if (!std::isfinite(h_m)) throw InputError("section height must be finite");
  SectionProperties result{0, 0};
  std::array<char, kMessageSize> message{};
  const mneedle_status status = impl_->call(index, [&](const mneedle_shape& s) {
    return s.section_properties(params.data(), params.size(), h_m, &result.area_m2,
                                &result.i_min_m4, message.data(), message.size());
  });
  message.back() = '\0';
  impl_->check_status(index, status, message.data(), "section_properties");
  if (!std::isfinite(result.area_m2) || result.area_m2 < 0 || !std::isfinite(result.i_min_m4) ||
      result.i_min_m4 < 0) {
    throw InputError(impl_->infos[index].library.string() + ": shape '" + std::string(shape_name) +
                     "' section_properties returned a negative or non-finite value");
  }
  return result;
}

}  // namespace mneedle
