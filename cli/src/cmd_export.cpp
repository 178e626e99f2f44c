// `mneedle export SCENE --format inp -o model.inp [--depth D]`: the scene's 3-D pre-puncture
// model at one depth as a CalculiX/Abaqus deck — our mesh, layers, constraints and the needle's
// sticking contact as prescribed displacements — so that an independent solver can solve the same
// problem (docs/cli.md, "mneedle export"). Linear layers only: the deck holds linear elasticity.
#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/material_model.h"
#include "mneedle/base/units.h"
#include "mneedle/design_source.h"
#include "mneedle/insertion/insertion_run.h"
#include "mneedle/plugin_host.h"
#include "mneedle/scene/scene.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct ExportArgs {
  std::filesystem::path scene;
  std::string format;
  std::string out;
  std::string depth;
  std::string fidelity;
  bool no_reductions = false;
  bool json = false;
  std::vector<std::string> plugin_dirs;
};

void run_export(const ExportArgs& a) {
  Scene scene = load_scene(a.scene);
  if (!a.depth.empty()) {
    scene.insertion.depth = option_quantity("--depth", a.depth, Dimension::Length);
    if (!(scene.insertion.depth > 0.0))
      throw InputError("export: --depth " + a.depth + ": must be positive");
  }
  // Refused before any work: the deck holds linear elasticity only (fe/inp_writer.h).
  for (const TissueLayer& layer : scene.tissue.layers)
    if (layer.material.model != MaterialModel::Linear)
      throw InputError("export: layer '" + layer.name +
                       "' is not linear: the .inp deck holds linear elastic layers only");
  const PluginRegistry registry =
      PluginRegistry::discover({a.plugin_dirs.begin(), a.plugin_dirs.end()});
  const std::vector<PreparedNeedle> needles = prepare_needles(registry, scene);
  record_scene(scene, a.scene);
  record_plugin_meshes(scene, needles);

  InsertionRunOptions options = scene_run_options(scene);
  if (a.fidelity == "fast") options.fidelity = fe::Fidelity::Fast;
  if (a.fidelity == "standard") options.fidelity = fe::Fidelity::Standard;
  if (a.fidelity == "fine") options.fidelity = fe::Fidelity::Fine;
  if (options.contact != Contact::Sticking)
    throw InputError(a.scene.string() +
                     ": model.contact: the deck prescribes sticking contact; the scene asks for " +
                     "frictionless");
  options.model = PreModel::Full3d;
  options.allow_reductions = !a.no_reductions;
  options.inp_path = a.out;
  options.inp_depth_m = scene.insertion.depth;
  options.inp_comment = {provenance_comment().substr(2)};
  const InsertionRun run = run_insertion(scene, needles, options);
  if (!run.exported)
    throw InputError("export: " + a.scene.string() + ": no finite element step reached " +
                     format_quantity(scene.insertion.depth, Dimension::Length) +
                     " or less (the first step is " +
                     format_quantity(run.first_step_m, Dimension::Length) + "): nothing written");
  const fe::InpExport& e = *run.exported;
  nlohmann::ordered_json out;
  out["file"] = e.path;
  out["format"] = "inp";
  out["depth_m"] = e.depth_m;
  out["nodes"] = e.nodes;
  out["elements"] = e.elements;
  out["prescribed_nodes"] = e.prescribed_nodes;
  out["reaction_N"] = {e.reaction_N.x(), e.reaction_N.y(), e.reaction_N.z()};
  out["reductions"] = nlohmann::ordered_json::array();
  for (const Reduction& r : run.reductions) out["reductions"].push_back(r.name);
  // Shallower than asked: the puncture ended the pre-puncture model first (the deck is its last
  // step; it was written without a word).
  const bool shallower = e.depth_m < scene.insertion.depth * (1.0 - 1e-9);
  if (shallower) {
    std::string why = "the pre-puncture model's last step before that depth";
    for (const NeedleRun& n : run.needles)
      if (n.puncture && n.puncture->depth_m <= scene.insertion.depth)
        why = "needle '" + n.name + "' punctures at " +
              format_quantity(n.puncture->depth_m, Dimension::Length) +
              ": the pre-puncture model stops at its step past that";
    std::cerr << "mneedle: note: the deck is at " + format_quantity(e.depth_m, Dimension::Length) +
                     ", not " + format_quantity(scene.insertion.depth, Dimension::Length) + ": " +
                     why + "\n";
  }
  out["requested_depth_m"] = scene.insertion.depth;
  require_finite_json(out, "export");
  if (a.json) {
    print_checked_json(std::cout, out, "export");
    return;
  }
  std::cout << e.path << ": " << e.nodes << " nodes, " << e.elements << " elements, "
            << e.prescribed_nodes << " nodes held by the needles at "
            << format_quantity(e.depth_m, Dimension::Length) << "; the tissue's reaction there: "
            << format_quantity(e.reaction_N.z(), Dimension::Force) << " (z, meshed part)\n";
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  auto* cmd = app.add_subcommand(
      "export", "Write the scene's 3-D model at one depth as a CalculiX/Abaqus .inp deck");
  cmd->add_option("scene", args->scene, "scene file (TOML)")->required();
  cmd->add_option("--format", args->format, "deck format")
      ->required()
      ->check(CLI::IsMember({"inp"}));
  cmd->add_option("-o,--out", args->out, "the .inp file to write")->required();
  cmd->add_option("--depth", args->depth,
                  "needle depth of the deck, with a unit (default: the scene's insertion depth); "
                  "the last finite element step not deeper is written");
  cmd->add_option("--fidelity", args->fidelity, "mesh fidelity (default: the scene's)")
      ->check(CLI::IsMember({"fast", "standard", "fine"}));
  cmd->add_flag("--no-reductions", args->no_reductions,
                "mesh the whole block (no half or quarter model)");
  cmd->add_flag("--json", args->json, "print what was written as JSON");
  cmd->add_option("--plugin-dir", args->plugin_dirs, "Extra plugin folder (repeatable)");
  cmd->footer(
      "Example:\n  mneedle export tests/assets/scenes/bevel_3d_linear.toml --format inp -o "
      "bevel.inp\n"
      "  ccx bevel      # CalculiX solves the same problem: compare its RF total with reaction_N");
  cmd->callback([args] { run_export(*args); });
}

}  // namespace mneedle::cli
