// The Python module mneedle._core: each operation of mneedle::api with the GIL released while it
// runs, its result handed to Python as plain dicts (pybind11_json), its errors as
// mneedle.InputError / mneedle.SolverError with the CLI's messages (docs/python.md). Only
// strings, numbers, lists and dicts cross: the C++ types stay on this side.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <pybind11_json/pybind11_json.hpp>
#include <string>
#include <vector>

#include "mneedle/api/fit_report.h"
#include "mneedle/api/scene_values.h"
#include "mneedle/api/screening_report.h"
#include "mneedle/api/simulation.h"
#include "mneedle/api/strength_report.h"
#include "mneedle/base/error.h"
#include "mneedle/base/provenance.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/fe/blas_kernels.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/needle/needle_frame.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "mneedle/screening.h"

namespace py = pybind11;

namespace mneedle::python {
namespace {

std::vector<std::filesystem::path> paths(const std::vector<std::string>& dirs) {
  return {dirs.begin(), dirs.end()};
}

// One registry per list of extra plugin folders, for the life of the process: a plugin that is
// not thread-safe is serialised by its registry, so Python threads must share it (a registry
// per call would let two threads into the same plugin at once). Plugins are found at the first
// call that names those folders.
std::mutex registries_mutex;
std::filesystem::path builtin_dir;  // the package's own plugin folder (_paths.py)
std::map<std::vector<std::string>, std::unique_ptr<PluginRegistry>> registries;

const PluginRegistry& registry_for(const std::vector<std::string>& plugin_dirs) {
  std::lock_guard<std::mutex> lock(registries_mutex);
  auto& registry = registries[plugin_dirs];
  if (!registry)
    registry = std::make_unique<PluginRegistry>(
        PluginRegistry::discover_from(builtin_dir, paths(plugin_dirs)));
  return *registry;
}

void set_plugin_folder(const std::string& folder) {
  std::lock_guard<std::mutex> lock(registries_mutex);
  builtin_dir = folder;  // once, at import: before any registry exists
}

// A scene is a file or values; the values arrive converted to JSON (while the GIL is held) and
// are parsed after it is released.
Scene scene_of(const std::string& file, const nlohmann::json& values, const std::string& source) {
  if (!file.empty()) return load_scene(file);
  return scene_from_values(values, source);
}

nlohmann::json simulate(const std::string& file, const nlohmann::json& values,
                        const std::string& source, const SimulateSettings& settings,
                        const std::vector<std::string>& plugin_dirs) {
  Scene scene = scene_of(file, values, source);
  apply_simulate_settings(scene, settings);
  const PluginRegistry& registry = registry_for(plugin_dirs);
  const std::vector<PreparedNeedle> needles =
      prepare_needles(registry, scene, settings.max_needles);
  const InsertionRun run = run_insertion(scene, needles, simulate_run_options(scene, settings));
  return simulation_json(run, scene, needles, settings);
}

nlohmann::json strength(const std::string& file, const std::string& plugin,
                        const std::vector<std::string>& set, const std::string& unit,
                        const std::string& axis, const StrengthSettings& settings,
                        const std::vector<std::string>& plugin_dirs) {
  if (file.empty() == plugin.empty())
    throw InputError("strength: give either a mesh file or plugin=NAME");
  const PluginRegistry& registry = registry_for(plugin_dirs);
  const NeedleSource needle =
      file.empty() ? needle_from_plugin(registry, plugin,
                                        parse_parameter_settings(registry.shape(plugin), set))
                   : needle_from_file(file, length_unit_scale(unit), parse_axis_choice(axis));
  return strength_report(registry, needle, settings);
}

nlohmann::json screen(const std::vector<std::string>& designs, const std::string& file,
                      const ScreeningOptions& options, const std::string& unit,
                      const std::vector<std::string>& plugin_dirs) {
  const Scene scene = load_scene(file);
  const PluginRegistry& registry = registry_for(plugin_dirs);
  const auto inputs = collect_designs(paths(designs), length_unit_scale(unit));
  parse_axis_choice(options.axis);
  check_screening_scene(scene, registry, options);  // as the CLI's screen, before any design
  const auto rows = rank_rows(screen_designs(inputs, scene, file, registry, options));
  return screening_json(rows, file, options, screening_warnings(rows, scene));
}

nlohmann::json fit(const std::vector<std::string>& files, const FitSettings& settings) {
  return fit_recordings(files, settings).report;
}

}  // namespace
}  // namespace mneedle::python

PYBIND11_MODULE(_core, m) {
  using namespace mneedle;
  using namespace mneedle::python;
  m.doc() = "mneedle's C++ core; use the mneedle package (docs/python.md)";
  // Exceptions map by type; what() is the CLI's message, word for word.
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<SolverError>(m, "SolverError", PyExc_RuntimeError);
  m.attr("__version__") = tool_version();
  // The factorisations' BLAS kernels, as the CLI chooses them (docs/python.md): at import, before
  // any thread of this module shares OpenBLAS.
  fe::select_blas_kernels(fe::blas_kernel_choice_from_environment());

  m.def("_set_plugin_folder", &set_plugin_folder, py::arg("folder"));
  m.def("read_scene", &read_scene_values, py::arg("file"),
        py::call_guard<py::gil_scoped_release>());
  m.def("scene_toml", &scene_values_toml, py::arg("values"), py::arg("source"),
        py::call_guard<py::gil_scoped_release>());
  m.def(
      "simulate",
      [](const std::string& file, const nlohmann::json& values, const std::string& source,
         const std::string& fidelity, const std::string& contact, const std::string& criterion,
         const std::string& model, const std::string& axis, std::size_t max_needles,
         bool no_reductions, const std::vector<std::string>& plugin_dirs, bool keep_reached) {
        SimulateSettings s{fidelity, contact,     criterion,     model,
                           axis,     max_needles, no_reductions, keep_reached};
        return simulate(file, values, source, s, plugin_dirs);
      },
      py::call_guard<py::gil_scoped_release>());
  m.def(
      "strength",
      [](const std::string& file, const std::string& plugin, const std::vector<std::string>& set,
         const std::string& unit, const std::string& axis, const std::string& material,
         const std::string& end, const std::string& depth, double lateral_ratio,
         const std::vector<std::string>& plugin_dirs) {
        return strength(file, plugin, set, unit, axis,
                        StrengthSettings{material, end, depth, lateral_ratio}, plugin_dirs);
      },
      py::call_guard<py::gil_scoped_release>());
  m.def(
      "screen",
      [](const std::vector<std::string>& designs, const std::string& scene,
         const std::string& fidelity, const std::string& model, const std::string& material,
         int jobs, const std::string& unit, const std::string& axis, bool repair,
         const std::vector<std::string>& plugin_dirs) {
        ScreeningOptions o;
        o.fidelity = fidelity;
        o.model = model;
        if (!material.empty()) o.material = material;
        o.jobs = jobs;
        o.axis = axis;
        o.repair = repair;
        return screen(designs, scene, o, unit, plugin_dirs);
      },
      py::call_guard<py::gil_scoped_release>());
  m.def(
      "fit",
      [](const std::vector<std::string>& files, const std::string& depth_col,
         const std::string& force_col, const std::string& depth_unit, const std::string& force_unit,
         const std::string& speed, const std::string& angle, const std::vector<std::string>& fix,
         const std::vector<std::string>& free, const std::vector<std::string>& layer_starts,
         std::size_t detect_layers, int starts) {
        FitSettings s;
        s.curve = {depth_col, force_col, depth_unit, force_unit, speed, angle};
        s.fix = fix;
        s.free = free;
        s.layer_starts = layer_starts;
        s.detect_layers = detect_layers;
        s.starts = starts;
        return fit(files, s);
      },
      py::call_guard<py::gil_scoped_release>());
}
