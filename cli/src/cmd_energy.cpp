// mneedle energy: paper C's stages of deep insertions and the toughness from their energy balance
// (docs/model.md, "Energy balance of a deep insertion").
#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "commands.h"
#include "json_output.h"
#include "mneedle/base/error.h"
#include "mneedle/base/text.h"
#include "mneedle/base/units.h"
#include "mneedle/fe/plane_strain_crack.h"
#include "mneedle/measurement/energy_balance.h"
#include "mneedle/measurement/force_curve.h"
#include "mneedle/measurement/toughness.h"
#include "mneedle/plot/figure.h"
#include "option_values.h"
#include "run_provenance.h"

namespace mneedle::cli {
namespace {

struct EnergyArgs {
  std::vector<std::string> curves;
  std::string depth, crack_width, crack_widths, needle_diameter, strain_energy, tissue,
      friction_force, block_size = "640mm";
  std::string depth_col, force_col, depth_unit, force_unit;
  std::string plot;  // SVG of every record with its stages
  double min_drop = 0.1, exit_drop = 0.2;
  bool json = false;
};

constexpr const char* kStageNames[5] = {"A", "B", "C", "D", "E"};

std::string sig(double v, int digits = 4) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}
std::string mj(double joules) {
  return sig(joules * 1e3) + " mJ";
}
std::string len(double m) {
  return format_quantity(m, Dimension::Length);
}

// "0mm:18mm,30mm:14mm,50mm:13mm" -> (depth, width) pairs, SI.
std::vector<std::pair<double, double>> parse_widths(const std::string& text) {
  std::vector<std::pair<double, double>> pairs;
  std::stringstream s(text);
  for (std::string item; std::getline(s, item, ',');) {
    const auto colon = item.find(':');
    if (colon == std::string::npos)
      throw InputError("--crack-widths '" + item + "': expected depth:width, e.g. 30mm:14mm");
    pairs.emplace_back(
        option_quantity("--crack-widths", trim(item.substr(0, colon)), Dimension::Length),
        option_quantity("--crack-widths", trim(item.substr(colon + 1)), Dimension::Length));
  }
  return pairs;
}

struct WidthChoice {
  double mean_m = 0.0;
  std::optional<CrackWidthFit> fit;
};

WidthChoice crack_width(const EnergyArgs& a, double depth_m) {
  if (a.crack_width.empty() == a.crack_widths.empty())
    throw InputError("energy: give exactly one of --crack-width or --crack-widths");
  WidthChoice w;
  if (!a.crack_width.empty()) {
    w.mean_m = positive_option_quantity("--crack-width", a.crack_width, Dimension::Length);
    return w;
  }
  w.fit = fit_crack_width(parse_widths(a.crack_widths), depth_m);
  w.mean_m = w.fit->mean_width_m;
  return w;
}

struct StrainChoice {
  double J_per_m = 0.0;
  std::optional<fe::CrackOpeningResult> fe;
  fe::CrackOpeningProblem problem;
};

StrainChoice strain_energy(const EnergyArgs& a, double mean_width_m) {
  if (a.strain_energy.empty() == a.tissue.empty())
    throw InputError("energy: give exactly one of --strain-energy or --tissue");
  StrainChoice s;
  if (!a.strain_energy.empty()) {
    s.J_per_m = option_quantity("--strain-energy", a.strain_energy, Dimension::Force);
    if (!(s.J_per_m >= 0.0))
      throw InputError("--strain-energy '" + a.strain_energy + "': must not be negative");
    return s;
  }
  const auto comma = a.tissue.find(',');
  if (comma == std::string::npos)
    throw InputError("--tissue '" + a.tissue + "': expected E,nu, e.g. 7kPa,0.475");
  if (a.needle_diameter.empty())
    throw InputError("--tissue needs --needle-diameter (the needle that opens the crack)");
  s.problem.youngs_modulus_Pa =
      option_quantity("--tissue", trim(a.tissue.substr(0, comma)), Dimension::Pressure);
  s.problem.poisson_ratio =
      option_quantity("--tissue", trim(a.tissue.substr(comma + 1)), Dimension::Dimensionless);
  s.problem.crack_width_m = mean_width_m;
  s.problem.needle_radius_m =
      0.5 * positive_option_quantity("--needle-diameter", a.needle_diameter, Dimension::Length);
  s.problem.block_size_m =
      positive_option_quantity("--block-size", a.block_size, Dimension::Length);
  s.fe = fe::crack_opening_strain_energy(s.problem);
  s.J_per_m = s.fe->strain_energy_J_per_m;
  return s;
}

struct Record {
  std::string file;
  std::string error;
  InsertionPass pass;
  InsertionStages stages;
  std::optional<EnergyBalance> balance;
};

nlohmann::json stages_json(const Record& r) {
  const auto& c = r.pass.curve;
  const auto& s = r.stages;
  const auto point = [&](std::size_t i) {
    return nlohmann::json{{"depth_m", c.depth_m[i]}, {"force_N", c.force_N[i]}};
  };
  nlohmann::json j = {{"puncture", point(s.puncture_index)},
                      {"relaxed", point(s.relaxed_index)},
                      {"peak", point(s.peak_index)},
                      {"through", s.through}};
  if (s.through) {
    j["sliding_start"] = point(s.sliding_index);
    j["sliding_force_N"] = s.sliding_force_N;
    j["sliding_samples"] = s.sliding_samples;
  }
  nlohmann::json work;
  for (int k = 0; k < 5; ++k) work[kStageNames[k]] = s.stage_work_J[k];
  j["work_J"] = work;
  return j;
}

nlohmann::json balance_json(const EnergyBalance& e) {
  return {{"cut_start_m", e.cut_start_m},
          {"cut_end_m", e.cut_end_m},
          {"external_work_J", e.external_work_J},
          {"friction_force_N", e.friction_force_N},
          {"friction_force_source", e.friction_from_record ? "sliding stage E" : "given"},
          {"friction_work_J", e.friction_work_J},
          {"strain_work_J", e.strain_work_J},
          {"crack_work_J", e.crack_work_J},
          {"toughness_J_per_m2", e.toughness_J_per_m2}};
}

void print_record(const Record& r, bool balance) {
  std::cout << r.file << ": ";
  if (!r.error.empty()) {
    std::cout << "error: " << r.error << "\n";
    return;
  }
  const auto& c = r.pass.curve;
  const auto& s = r.stages;
  const auto at = [&](std::size_t i) {
    return len(c.depth_m[i]) + " (" + format_quantity(c.force_N[i], Dimension::Force) + ")";
  };
  std::cout << c.depth_m.size() << " points from contact at travel "
            << len(r.pass.cut.contact_travel_m) << "\n"
            << "  A deformation to the puncture at " << at(s.puncture_index) << "\n"
            << "  B relaxation to " << at(s.relaxed_index) << "\n"
            << "  C cutting to the peak at " << at(s.peak_index) << "\n";
  if (s.through) {
    std::cout << "  D exit relaxation to " << at(s.sliding_index) << "\n"
              << "  E sliding to " << len(c.depth_m.back()) << " at "
              << format_quantity(s.sliding_force_N, Dimension::Force) << " (mean of "
              << s.sliding_samples << " samples)\n";
  } else {
    std::cout << (balance ? "  no D or E: the force does not fall and settle after its peak\n"
                          : "  D and E sought only with --depth (a through insertion)\n");
  }
  std::cout << "  work by stage:";
  for (int k = 0; k < 5; ++k) std::cout << " " << kStageNames[k] << " " << mj(s.stage_work_J[k]);
  std::cout << "\n";
  if (r.balance) {
    const auto& e = *r.balance;
    std::cout << "  balance over " << len(e.cut_start_m) << " to " << len(e.cut_end_m) << ": W_ext "
              << mj(e.external_work_J) << " = W_f " << mj(e.friction_work_J) << " (F_max "
              << format_quantity(e.friction_force_N, Dimension::Force)
              << (e.friction_from_record ? ", stage E" : ", given") << ") + W_eps "
              << mj(e.strain_work_J) << " + W_Gc " << mj(e.crack_work_J) << "\n"
              << "  G_c = " << sig(e.toughness_J_per_m2) << " J/m^2\n";
  }
}

// Every record's force against depth; one record gets its stage boundaries drawn, several their
// punctures and peaks marked.
plot::Figure energy_figure(const std::vector<Record>& records) {
  plot::Figure f;
  f.title = "energy: stages of the insertion (paper C)";
  f.x.name = "depth from contact";
  std::size_t drawn = 0;
  for (const Record& r : records) {
    if (!r.error.empty()) continue;
    ++drawn;
    const auto& c = r.pass.curve;
    f.series.push_back({std::filesystem::path(r.file).filename().string(), c.depth_m, c.force_N,
                        plot::Mark::Line});
    f.points.push_back(
        {"puncture", c.depth_m[r.stages.puncture_index], c.force_N[r.stages.puncture_index]});
    f.points.push_back({"peak", c.depth_m[r.stages.peak_index], c.force_N[r.stages.peak_index]});
  }
  // Past three records the words would pile up on each other: the circles stay, the title says
  // what they are.
  if (drawn > 3) {
    for (plot::Point& p : f.points) p.label.clear();
    f.title = "energy: " + std::to_string(drawn) + " records (circles: puncture and peak)";
  }
  if (drawn == 1) {
    for (const Record& r : records) {
      if (!r.error.empty()) continue;
      f.title = "energy: " + std::filesystem::path(r.file).filename().string();
      const auto& c = r.pass.curve;
      const auto& s = r.stages;
      f.lines.push_back({"A|B", c.depth_m[s.puncture_index]});
      f.lines.push_back({"B|C", c.depth_m[s.relaxed_index]});
      if (s.through) {
        f.lines.push_back({"C|D", c.depth_m[s.peak_index]});
        f.lines.push_back({"D|E", c.depth_m[s.sliding_index]});
      }
      if (r.balance) f.lines.push_back({"cut from", r.balance->cut_start_m});
    }
  }
  return f;
}

void run_energy(const EnergyArgs& a) {
  if (!(a.min_drop > 0.0 && a.min_drop < 1.0) || !(a.exit_drop > 0.0 && a.exit_drop < 1.0))
    throw InputError("--min-drop and --exit-drop are fractions between 0 and 1");
  const bool balance = !a.depth.empty();
  if (!balance && (!a.crack_width.empty() || !a.crack_widths.empty() || !a.strain_energy.empty() ||
                   !a.tissue.empty() || !a.friction_force.empty()))
    throw InputError("energy: the balance options need --depth (the block's thickness)");
  EnergyBalanceInputs in;
  std::optional<WidthChoice> width;
  std::optional<StrainChoice> strain;
  if (balance) {
    in.block_depth_m = positive_option_quantity("--depth", a.depth, Dimension::Length);
    width = crack_width(a, in.block_depth_m);
    in.mean_crack_width_m = width->mean_m;
    strain = strain_energy(a, width->mean_m);
    in.strain_energy_J_per_m = strain->J_per_m;
    if (!a.friction_force.empty())
      in.friction_force_N =
          positive_option_quantity("--friction-force", a.friction_force, Dimension::Force);
  }
  const CurveColumns columns{a.depth_col, a.force_col, "", a.depth_unit, a.force_unit};
  std::vector<Record> records;
  for (const auto& file : a.curves) {
    Record r;
    r.file = file;
    try {
      r.pass = prepare_pass(read_force_curve_csv(file, columns));
      record_input("curve", file);
      StageOptions o;
      o.min_drop_fraction = a.min_drop;
      o.min_exit_drop_fraction = a.exit_drop;
      o.noise_N = r.pass.cut.noise_N;
      o.seek_exit = balance;  // a record goes through only when the user gives the block
      r.stages = split_stages(r.pass.curve, o);
      if (balance) r.balance = energy_balance(r.pass.curve, r.stages, in);
    } catch (const InputError& e) {
      r.error = e.what();  // the other records still run; the exit status reports it
    }
    records.push_back(std::move(r));
  }

  // Paper C §5 averages each record's values, not the records' mean curve.
  std::size_t done = 0, failed = 0;
  EnergyBalance mean;
  for (const auto& r : records) {
    if (!r.error.empty()) ++failed;
    if (!r.balance) continue;
    ++done;
    mean.external_work_J += r.balance->external_work_J;
    mean.friction_force_N += r.balance->friction_force_N;
    mean.friction_work_J += r.balance->friction_work_J;
    mean.strain_work_J += r.balance->strain_work_J;
    mean.crack_work_J += r.balance->crack_work_J;
    mean.toughness_J_per_m2 += r.balance->toughness_J_per_m2;
  }
  if (done > 0) {
    const double k = static_cast<double>(done);
    for (double* v : {&mean.external_work_J, &mean.friction_force_N, &mean.friction_work_J,
                      &mean.strain_work_J, &mean.crack_work_J, &mean.toughness_J_per_m2})
      *v /= k;
  }

  if (!a.plot.empty() && records.size() > failed) plot::write_svg(a.plot, energy_figure(records));

  nlohmann::json warnings = nlohmann::json::array();
  if (balance && !a.needle_diameter.empty() &&
      in.mean_crack_width_m <
          option_quantity("--needle-diameter", a.needle_diameter, Dimension::Length))
    warnings.push_back("the mean crack width is below the needle's diameter, its lower bound");
  for (const auto& r : records)
    if (r.balance && r.balance->crack_work_J < 0.0)
      warnings.push_back(r.file + ": W_Gc < 0: friction and strain energy exceed the work done");

  if (a.json) {
    nlohmann::json out;
    nlohmann::json recs = nlohmann::json::array();
    for (const auto& r : records) {
      nlohmann::json j = {{"file", r.file}};
      if (!r.error.empty()) {
        j["error"] = r.error;
      } else {
        j["points"] = r.pass.curve.depth_m.size();
        j["contact_travel_m"] = r.pass.cut.contact_travel_m;
        j["stages"] = stages_json(r);
        if (r.balance) j["balance"] = balance_json(*r.balance);
      }
      recs.push_back(j);
    }
    out["records"] = recs;
    if (balance) {
      out["block_depth_m"] = in.block_depth_m;
      out["mean_crack_width_m"] = in.mean_crack_width_m;
      if (width->fit)
        // w(z) = c0 + c1 z + c2 z^2 in SI: c0 in m, c1 in 1, c2 in 1/m (not all metres).
        out["crack_width_fit"] = {{"coefficients_SI", width->fit->coefficients},
                                  {"min_width_m", width->fit->min_width_m},
                                  {"max_residual_m", width->fit->max_residual_m}};
      out["strain_energy_J_per_m"] = in.strain_energy_J_per_m;
      out["strain_energy_source"] = strain->fe ? "plane-strain FE" : "given";
      if (strain->fe)
        out["strain_energy_fe"] = {{"youngs_modulus_Pa", strain->problem.youngs_modulus_Pa},
                                   {"poisson_ratio", strain->problem.poisson_ratio},
                                   {"needle_radius_m", strain->problem.needle_radius_m},
                                   {"block_size_m", strain->problem.block_size_m},
                                   {"nodes", strain->fe->nodes},
                                   {"elements", strain->fe->elements},
                                   {"contact_nodes", strain->fe->contact_nodes},
                                   {"element_size_m", strain->fe->element_size_m}};
      if (done > 0) {
        out["mean"] = balance_json(mean);
        out["mean"].erase("cut_start_m");
        out["mean"].erase("cut_end_m");
        out["mean"].erase("friction_force_source");
        out["mean"]["records"] = done;
      }
    }
    out["warnings"] = warnings;
    print_checked_json(std::cout, out, "energy");
  } else {
    for (const auto& r : records) print_record(r, balance);
    if (balance) {
      std::cout << "mean crack width " << len(in.mean_crack_width_m);
      if (width->fit)
        std::cout << " (polynomial of degree " << width->fit->coefficients.size() - 1
                  << " through the widths, smallest " << len(width->fit->min_width_m) << ")";
      std::cout << "; strain energy per length " << sig(in.strain_energy_J_per_m * 1e3) << " mJ/m";
      if (strain->fe) std::cout << " (plane-strain FE, " << strain->fe->nodes << " nodes)";
      std::cout << "\n";
      if (done > 1) {
        std::cout << "mean of " << done << " records: W_ext " << mj(mean.external_work_J)
                  << ", F_max " << format_quantity(mean.friction_force_N, Dimension::Force)
                  << ", W_f " << mj(mean.friction_work_J) << ", W_eps " << mj(mean.strain_work_J)
                  << ", W_Gc " << mj(mean.crack_work_J) << ", G_c " << sig(mean.toughness_J_per_m2)
                  << " J/m^2\n";
      }
    }
    for (const auto& w : warnings) std::cout << "warning: " << w.get<std::string>() << "\n";
  }
  if (failed > 0) {
    for (const auto& r : records)
      if (!r.error.empty())
        throw InputError(
            r.error +
            (failed > 1 ? " (and " + std::to_string(failed - 1) + " more records failed)" : ""));
  }
}

}  // namespace

void add_energy_command(CLI::App& app) {
  auto a = std::make_shared<EnergyArgs>();
  auto* cmd = app.add_subcommand(
      "energy", "Stages of deep insertions and G_c from their energy balance (paper C)");
  cmd->footer(
      "Without --depth: the stages A-E of each record and the work in each. With --depth: the\n"
      "balance W_ext = W_f + W_eps + W_Gc over one block depth before the peak force, and\n"
      "G_c = W_Gc / (w d). Records that fail are reported; the others still run (exit 1).\n"
      "Examples:\n"
      "  mneedle energy rec1.csv rec2.csv\n"
      "  mneedle energy rec*.csv --depth 86mm --crack-width 15mm --strain-energy 73.2mJ/m\n"
      "  mneedle energy rec.csv --depth 86mm --crack-widths 0mm:18mm,30mm:14mm,50mm:13mm \\\n"
      "      --tissue 7kPa,0.475 --needle-diameter 8mm --json");
  cmd->add_option("curves", a->curves, "Force-displacement records (CSV)")->required();
  cmd->add_option("--depth", a->depth, "Thickness d of the block the needle goes through");
  cmd->add_option("--crack-width", a->crack_width, "Mean crack width w, e.g. 15mm");
  cmd->add_option("--crack-widths", a->crack_widths,
                  "Measured widths depth:width,... (a polynomial of degree <= 2, averaged)");
  cmd->add_option("--strain-energy", a->strain_energy,
                  "Strain energy per unit crack length U_eps, e.g. 73.2mJ/m");
  cmd->add_option("--tissue", a->tissue,
                  "E,nu: compute U_eps by the plane-strain FE of the crack opened by the needle");
  cmd->add_option("--needle-diameter", a->needle_diameter, "Needle diameter (with --tissue)");
  cmd->add_option("--block-size", a->block_size, "Side of the plane-strain FE's square block")
      ->capture_default_str();
  cmd->add_option("--friction-force", a->friction_force,
                  "F_max: friction once through (default: the mean force of stage E)");
  cmd->add_option("--min-drop", a->min_drop, "Puncture: fall below a peak by this fraction")
      ->capture_default_str();
  cmd->add_option("--exit-drop", a->exit_drop, "Exit: fall after the peak by this fraction")
      ->capture_default_str();
  cmd->add_option("--depth-col", a->depth_col, "Depth column (default: depth*, travel*, ...)");
  cmd->add_option("--force-col", a->force_col, "Force column (default: force*, fz*, ...)");
  cmd->add_option("--depth-unit", a->depth_unit, "Unit of the depth column (default: its name)");
  cmd->add_option("--force-unit", a->force_unit, "Unit of the force column (default: its name)");
  cmd->add_option("--plot", a->plot, "Write every record with its stages as SVG");
  cmd->add_flag("--json", a->json, "Print one JSON object");
  cmd->callback([a] { run_energy(*a); });
}

}  // namespace mneedle::cli
