// mneedle plane-strain: paper C §6's plane-strain insertion of a rigid needle along a cut, with
// its force curve and energy ledger (docs/model.md, "Plane-strain insertion along a cut").
#include <CLI/CLI.hpp>

#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/base/units.h"
#include "mneedle/fe/plane_strain_insertion.h"
#include "mneedle/plot/figure.h"
#include "option_values.h"

namespace mneedle::cli {
namespace {

struct PlaneStrainArgs {
  std::string tissue, block, thickness, needle_width, tip_angle, shoulder_radius, travel,
      element_size, step;
  std::string toughness, openings, initial_cut, viscosity;  // the cohesive interface
  double friction = 0.0;
  std::string csv, plot, energy_plot;
  bool json = false;
};

// "A,B" -> two quantities of one dimension.
std::pair<double, double> pair_of(const std::string& option, const std::string& text,
                                  Dimension first, Dimension second, const char* example) {
  const auto comma = text.find(',');
  if (comma == std::string::npos)
    throw InputError(option + " '" + text + "': expected two values, e.g. " + example);
  return {option_quantity(option, trim(text.substr(0, comma)), first),
          option_quantity(option, trim(text.substr(comma + 1)), second)};
}

std::string sig(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

void write_csv(const std::string& file, const fe::PlaneStrainInsertionResult& r) {
  std::ofstream out(file);
  if (!out) throw InputError(file + ": cannot be written");
  out << std::setprecision(10)
      << "travel [m],force [N],shaft friction [N],shaft normal force [N],external work [J],"
         "strain energy [J],friction work [J],cohesive work [J],fracture energy [J],"
         "crack depth [m],balance error [1],tip contacts,shaft contacts,sticking\n";
  for (const auto& s : r.steps)
    out << s.travel_m << ',' << s.force_N << ',' << s.friction_force_N << ',' << s.normal_force_N
        << ',' << s.external_work_J << ',' << s.strain_energy_J << ',' << s.friction_work_J << ','
        << s.cohesive_work_J << ',' << s.fracture_energy_J << ',' << s.crack_depth_m << ','
        << s.balance_error << ',' << s.tip_contacts << ',' << s.shaft_contacts << ',' << s.sticking
        << '\n';
  if (!out) throw InputError(file + ": write failed");
}

// Paper C's Fig. 14: the ledger's terms against travel, W_ext = U + W_f + W_coh at every step.
plot::Figure energy_figure(const fe::PlaneStrainInsertionProblem& p,
                           const fe::PlaneStrainInsertionResult& r) {
  plot::Figure f;
  f.title = "energy ledger of the insertion (paper C, Fig. 14)";
  f.x.name = "needle travel";
  f.y = {"energy", Dimension::Energy, "", false};
  std::vector<double> x, external, strain, friction, cohesive, fracture;
  for (const auto& s : r.steps) {
    x.push_back(s.travel_m);
    external.push_back(s.external_work_J);
    strain.push_back(s.strain_energy_J);
    friction.push_back(s.friction_work_J);
    cohesive.push_back(s.cohesive_work_J);
    fracture.push_back(s.fracture_energy_J);
  }
  f.series.push_back({"external work", x, external, plot::Mark::Line});
  f.series.push_back({"strain energy", x, strain, plot::Mark::Line});
  f.series.push_back({"friction work", x, friction, plot::Mark::Line});
  if (p.cohesion.toughness_J_per_m2 > 0.0) {
    f.series.push_back({"cohesive work", x, cohesive, plot::Mark::Line});
    f.series.push_back({"fracture energy (dissipated)", x, fracture, plot::Mark::Line});
  }
  f.lines.push_back({"tip at the bottom", p.block_depth_m});
  if (r.puncture_travel_m > 0.0) f.lines.push_back({"crack runs", r.puncture_travel_m});
  return f;
}

void run_plane_strain(const PlaneStrainArgs& a) {
  fe::PlaneStrainInsertionProblem p;
  const auto [E, nu] =
      pair_of("--tissue", a.tissue, Dimension::Pressure, Dimension::Dimensionless, "7kPa,0.475");
  p.youngs_modulus_Pa = E;
  p.poisson_ratio = nu;
  const auto [width, depth] =
      pair_of("--block", a.block, Dimension::Length, Dimension::Length, "160mm,86mm");
  p.block_width_m = width;
  p.block_depth_m = depth;
  p.thickness_m = option_quantity("--thickness", a.thickness, Dimension::Length);
  p.needle_width_m = option_quantity("--needle-width", a.needle_width, Dimension::Length);
  p.tip_angle_rad = option_quantity("--tip-angle", a.tip_angle, Dimension::Angle);
  p.friction_coefficient = a.friction;
  p.travel_m = a.travel.empty() ? depth : option_quantity("--travel", a.travel, Dimension::Length);
  // 0 is the library's "default" (w / 4); given on the command line it would be a sharp
  // shoulder, which is not offered (docs/model.md, "Plane-strain insertion along a cut").
  if (!a.shoulder_radius.empty())
    p.shoulder_radius_m =
        positive_option_quantity("--shoulder-radius", a.shoulder_radius, Dimension::Length);
  if (!a.element_size.empty())
    p.element_size_m =
        positive_option_quantity("--element-size", a.element_size, Dimension::Length);
  if (!a.step.empty()) p.step_m = positive_option_quantity("--step", a.step, Dimension::Length);
  const bool cohesive = !a.toughness.empty();
  if (!cohesive && (!a.openings.empty() || !a.initial_cut.empty() || !a.viscosity.empty()))
    throw InputError(
        "plane-strain: --cohesive-openings, --initial-cut and --viscosity need "
        "--toughness (the cohesive interface)");
  if (cohesive) {
    if (a.openings.empty())
      throw InputError("plane-strain: --toughness needs --cohesive-openings (e.g. 7mm,7.5mm)");
    p.cohesion.toughness_J_per_m2 =
        option_quantity("--toughness", a.toughness, Dimension::Toughness);
    if (!(p.cohesion.toughness_J_per_m2 > 0.0))
      throw InputError("--toughness '" + a.toughness +
                       "': must be positive (leave it out for a cut block)");
    const auto [peak, failure] = pair_of("--cohesive-openings", a.openings, Dimension::Length,
                                         Dimension::Length, "7mm,7.5mm");
    p.cohesion.peak_opening_m = peak;
    p.cohesion.failure_opening_m = failure;
    if (!a.initial_cut.empty())
      p.cohesion.initial_cut_m = option_quantity("--initial-cut", a.initial_cut, Dimension::Length);
    if (!a.viscosity.empty())
      p.cohesion.viscosity_m = option_quantity("--viscosity", a.viscosity, Dimension::Length);
  }
  const fe::PlaneStrainInsertionResult r = fe::simulate_plane_strain_insertion(p);
  const fe::PlaneStrainInsertionStep& end = r.steps.back();

  if (!a.csv.empty()) write_csv(a.csv, r);
  if (!a.plot.empty()) {
    plot::Figure f;
    f.title = "plane-strain insertion along a cut (paper C)";
    f.x.name = "needle travel";
    std::vector<double> x, force, friction;
    for (const auto& s : r.steps) {
      x.push_back(s.travel_m);
      force.push_back(s.force_N);
      friction.push_back(s.friction_force_N);
    }
    f.series.push_back({"insertion force", x, force, plot::Mark::Line});
    f.series.push_back({"shaft friction", x, friction, plot::Mark::Line});
    f.lines.push_back({"tip at the bottom", p.block_depth_m});
    if (r.puncture_travel_m > 0.0) f.lines.push_back({"crack runs", r.puncture_travel_m});
    plot::write_svg(a.plot, f);
  }
  if (!a.energy_plot.empty()) plot::write_svg(a.energy_plot, energy_figure(p, r));

  const double balance_bound = 0.02;  // paper C's requirement for the ledger (issue text)
  nlohmann::json warnings = nlohmann::json::array();
  if (r.max_abs_balance_error > balance_bound)
    warnings.push_back("the energy ledger closes only to " + sig(100 * r.max_abs_balance_error, 3) +
                       " % at its worst step (above 2 %): refine --element-size or --step");
  if (a.json) {
    nlohmann::ordered_json out;
    out["problem"] = {{"youngs_modulus_Pa", p.youngs_modulus_Pa},
                      {"poisson_ratio", p.poisson_ratio},
                      {"block_width_m", p.block_width_m},
                      {"block_depth_m", p.block_depth_m},
                      {"thickness_m", p.thickness_m},
                      {"needle_width_m", p.needle_width_m},
                      {"tip_angle_rad", p.tip_angle_rad},
                      {"shoulder_radius_m", r.shoulder_radius_m},
                      {"friction_coefficient", p.friction_coefficient},
                      {"travel_m", p.travel_m}};
    if (cohesive)
      out["problem"]["cohesion"] = {{"toughness_J_per_m2", p.cohesion.toughness_J_per_m2},
                                    {"peak_opening_m", p.cohesion.peak_opening_m},
                                    {"failure_opening_m", p.cohesion.failure_opening_m},
                                    {"initial_cut_m", p.cohesion.initial_cut_m},
                                    {"viscosity_m", p.cohesion.viscosity_m}};
    out["mesh"] = {{"nodes", r.nodes},
                   {"elements", r.elements},
                   {"cut_nodes", r.cut_nodes},
                   {"element_size_m", r.element_size_m},
                   {"step_m", r.step_m}};
    out["end"] = {{"travel_m", end.travel_m},
                  {"force_N", end.force_N},
                  {"friction_force_N", end.friction_force_N},
                  {"normal_force_N", end.normal_force_N},
                  {"external_work_J", end.external_work_J},
                  {"strain_energy_J", end.strain_energy_J},
                  {"friction_work_J", end.friction_work_J},
                  {"cohesive_work_J", end.cohesive_work_J},
                  {"fracture_energy_J", end.fracture_energy_J},
                  {"crack_depth_m", end.crack_depth_m},
                  {"balance_error", end.balance_error}};
    if (cohesive)
      out["puncture"] = r.puncture_travel_m > 0.0
                            ? nlohmann::ordered_json{{"travel_m", r.puncture_travel_m},
                                                     {"force_N", r.puncture_force_N}}
                            : nlohmann::ordered_json(nullptr);
    out["max_abs_balance_error"] = r.max_abs_balance_error;
    out["max_penetration_m"] = r.max_penetration_m;
    nlohmann::ordered_json steps;
    for (const char* k : {"travel_m", "force_N", "friction_force_N", "external_work_J",
                          "strain_energy_J", "friction_work_J", "cohesive_work_J",
                          "fracture_energy_J", "crack_depth_m", "balance_error"})
      steps[k] = nlohmann::json::array();
    for (const auto& s : r.steps) {
      steps["travel_m"].push_back(s.travel_m);
      steps["force_N"].push_back(s.force_N);
      steps["friction_force_N"].push_back(s.friction_force_N);
      steps["external_work_J"].push_back(s.external_work_J);
      steps["strain_energy_J"].push_back(s.strain_energy_J);
      steps["friction_work_J"].push_back(s.friction_work_J);
      steps["cohesive_work_J"].push_back(s.cohesive_work_J);
      steps["fracture_energy_J"].push_back(s.fracture_energy_J);
      steps["crack_depth_m"].push_back(s.crack_depth_m);
      steps["balance_error"].push_back(s.balance_error);
    }
    out["steps"] = steps;
    out["warnings"] = warnings;
    print_checked_json(std::cout, out, "plane-strain");
    return;
  }
  const auto mj = [](double j) { return sig(j * 1e3) + " mJ"; };
  std::cout << "plane-strain insertion along a cut: " << r.nodes << " nodes, " << r.cut_nodes
            << " on the cut, cells " << format_quantity(r.element_size_m, Dimension::Length) << ", "
            << r.steps.size() - 1 << " steps of " << format_quantity(r.step_m, Dimension::Length)
            << "\n"
            << "at travel " << format_quantity(end.travel_m, Dimension::Length) << ": force "
            << format_quantity(end.force_N, Dimension::Force) << " (shaft friction "
            << format_quantity(end.friction_force_N, Dimension::Force) << ")\n"
            << "energy: W_ext " << mj(end.external_work_J) << " = U " << mj(end.strain_energy_J)
            << " + W_f " << mj(end.friction_work_J);
  if (cohesive)
    std::cout << " + W_coh " << mj(end.cohesive_work_J) << " (fracture "
              << mj(end.fracture_energy_J) << ")";
  std::cout << " (closure " << sig(100 * end.balance_error, 3) << " %, worst step "
            << sig(100 * r.max_abs_balance_error, 3) << " %)\n";
  if (cohesive) {
    std::cout << "crack from the initial cut to "
              << format_quantity(end.crack_depth_m, Dimension::Length) << "; ";
    if (r.puncture_travel_m > 0.0)
      std::cout << "puncture (the first cell fails) at travel "
                << format_quantity(r.puncture_travel_m, Dimension::Length) << ", force "
                << format_quantity(r.puncture_force_N, Dimension::Force) << "\n";
    else
      std::cout << "no cell failed: no puncture within the travel\n";
  }
  for (const auto& w : warnings) std::cout << "warning: " << w.get<std::string>() << "\n";
}

}  // namespace

void add_plane_strain_command(CLI::App& app) {
  auto a = std::make_shared<PlaneStrainArgs>();
  auto* cmd = app.add_subcommand(
      "plane-strain", "Paper C's plane-strain insertion along a cut: force and energy ledger");
  cmd->footer(
      "A rigid needle (a strip with a wedge tip) pushed down a block already cut along its path:\n"
      "frictionless tip, Coulomb shaft. Every value needs its unit.\n"
      "Example (paper C, no cohesion):\n"
      "  mneedle plane-strain --tissue 7kPa,0.475 --block 160mm,86mm --thickness 15mm \\\n"
      "      --needle-width 8mm --tip-angle 50deg --friction 0.5 --json");
  cmd->add_option("--tissue", a->tissue, "E,nu of the block, e.g. 7kPa,0.475")->required();
  cmd->add_option("--block", a->block, "Width,depth of the block, e.g. 160mm,86mm")->required();
  cmd->add_option("--thickness", a->thickness, "Out-of-plane thickness, e.g. 15mm")->required();
  cmd->add_option("--needle-width", a->needle_width, "Needle width, e.g. 8mm")->required();
  cmd->add_option("--tip-angle", a->tip_angle, "Included angle of the tip, e.g. 50deg")->required();
  cmd->add_option("--friction", a->friction, "Coulomb coefficient on the shaft")
      ->capture_default_str();
  cmd->add_option("--shoulder-radius", a->shoulder_radius,
                  "Radius rounding the shoulder (default and largest: width/4)");
  cmd->add_option("--travel", a->travel, "Tip travel (default: the block's depth)");
  cmd->add_option("--element-size", a->element_size, "Cell size along the cut (default w/8)");
  cmd->add_option("--step", a->step, "Travel per step (default: cell/8)");
  cmd->add_option("--toughness", a->toughness,
                  "G_c of a cohesive interface along the path, e.g. 17.43J/m2 (default: cut)");
  cmd->add_option("--cohesive-openings", a->openings,
                  "Openings at the peak traction and at failure, e.g. 7mm,7.5mm");
  cmd->add_option("--initial-cut", a->initial_cut, "Depth cut before the insertion (default 0)");
  cmd->add_option("--viscosity", a->viscosity,
                  "Travel over which damage relaxes to the law (default 0.5mm; 0mm: none)");
  cmd->add_option("--csv", a->csv, "Write every step (unit-bracketed columns) to this file");
  cmd->add_option("--plot", a->plot, "Write the force curve as SVG");
  cmd->add_option("--energy-plot", a->energy_plot,
                  "Write the energy ledger against travel as SVG (paper C, Fig. 14)");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_plane_strain(*a); });
}

}  // namespace mneedle::cli
