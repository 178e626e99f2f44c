#pragma once
// Host side of the tip-shape plugin ABI (mneedle/plugin.h): finds plugin libraries, loads
// them with dlopen, checks them, and calls their shapes with validated SI parameters.

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mneedle/base/error.h"
#include "mneedle/needle/mesh.h"

namespace mneedle {

/// A plugin refused a parameter combination as no valid shape (MNEEDLE_STATUS_INVALID_PARAMETER,
/// e.g. a bevel longer than the needle): a property of the design, which a search treats as
/// infeasible rather than as a failure of the run.
class InvalidShapeError : public InputError {
 public:
  using InputError::InputError;
};

struct PluginParameter {
  std::string name;
  std::string unit;  // "m", "rad" or "1"
  std::string help;
  double default_value = 0;
  double min = 0;
  double max = 0;
};

struct PluginShapeInfo {
  std::string name;
  std::string plugin_id;
  std::string help;
  std::filesystem::path library;
  std::vector<PluginParameter> parameters;
  bool thread_safe = false;
  bool has_section_area = false;
  bool has_section_properties = false;
};

/// The tip shapes of every plugin found. Libraries stay loaded for the registry's lifetime
/// (and as long as any moved-to registry holds them). Calls to a shape that is not thread
/// safe are serialised; the registry itself may be shared between threads once built.
class PluginRegistry {
 public:
  struct SectionProperties {
    double area_m2;
    double i_min_m4;
  };

  PluginRegistry();
  ~PluginRegistry();
  PluginRegistry(PluginRegistry&&) noexcept;
  PluginRegistry& operator=(PluginRegistry&&) noexcept;
  PluginRegistry(const PluginRegistry&) = delete;
  PluginRegistry& operator=(const PluginRegistry&) = delete;

  /// Searches the built-in folder (the build tree's plugin folder, or
  /// <exe dir>/../lib/mneedle/plugins when installed), then each folder of
  /// MNEEDLE_PLUGIN_PATH (':'-separated), then extra_dirs; never the current directory.
  /// Broken plugin files become warnings(); a later shape with a known name is skipped
  /// with a warning.
  static PluginRegistry discover(const std::vector<std::filesystem::path>& extra_dirs = {});

  /// The same with the built-in folder given by the caller: a library loaded into another
  /// program (the Python package, whose executable is python3) knows where its plugins are;
  /// the executable's folder says nothing about that.
  static PluginRegistry discover_from(const std::filesystem::path& builtin_dir,
                                      const std::vector<std::filesystem::path>& extra_dirs = {});

  /// The built-in plugin folder this executable would search (may not exist).
  static std::filesystem::path builtin_plugin_dir();

  /// Loads one plugin library and adds its shapes. Throws InputError naming the file if it
  /// cannot be loaded, has no entry symbol, a different ABI major version, malformed
  /// descriptors or a shape name that is already registered.
  void load_library(const std::filesystem::path& library);

  const std::vector<PluginShapeInfo>& shapes() const;
  /// Throws InputError listing the known shape names (and plugin files that failed to load).
  const PluginShapeInfo& shape(std::string_view name) const;
  /// One line per plugin file that failed to load during discover().
  const std::vector<std::string>& warnings() const;

  /// Parameter vector in the shape's order: given values (SI) checked against the bounds,
  /// defaults for the rest. Unknown names and out-of-bounds values throw InputError naming
  /// the parameter and the bound.
  std::vector<double> resolve_parameters(std::string_view shape,
                                         const std::map<std::string, double>& si) const;

  /// The shape's mesh (metres, needle frame), checked to be a valid closed solid. Throws
  /// InvalidShapeError when the plugin says the parameters make no valid shape.
  TriangleMesh generate(std::string_view shape, const std::map<std::string, double>& si) const;

  /// Analytic section at height h (m) above the tip; nullopt when the shape has no hook.
  std::optional<double> section_area(std::string_view shape,
                                     const std::map<std::string, double>& si, double h_m) const;
  std::optional<SectionProperties> section_properties(std::string_view shape,
                                                      const std::map<std::string, double>& si,
                                                      double h_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mneedle
