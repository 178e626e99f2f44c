#pragma once
// Everything mneedle can say about one needle design in one scene: its geometry, the force on it
// up to the insertion depth, its strength and margin. Screening ranks these; the optimiser
// minimises over them.

#include <optional>
#include <string>
#include <vector>

#include "mneedle/mesh.h"
#include "mneedle/needle_material.h"
#include "mneedle/needle_strength.h"
#include "mneedle/scene.h"
#include "mneedle/surface_loads.h"

namespace mneedle {

struct DesignGeometry {
  std::size_t triangles = 0;
  double volume_m3 = 0.0;
  double area_m2 = 0.0;
  double length_m = 0.0;
  double tip_length_m = 0.0;  // height where the section reaches its shaft value
  double alpha_area_m2 = 0.0;
  double beta_area_m2 = 0.0;
};

struct DesignEvaluation {
  DesignGeometry geometry;
  double depth_m = 0.0;           // the depth it is evaluated to (target or insertion depth)
  double force_at_depth_n = 0.0;  // post-puncture model at depth_m
  double peak_force_n = 0.0;      // largest force up to depth_m
  StrengthReport strength;
  std::string material;
  double margin = 0.0;  // capacity / peak force
  double safety_factor = 1.5;
  bool passes = false;             // margin >= safety factor and the needle reaches depth_m
  std::vector<std::string> notes;  // why a design fails, what was not modelled
};

struct EvaluationOptions {
  int depth_steps = 100;                       // points of the force curve up to the depth
  std::optional<std::string> material;         // overrides the scene needle's material
  std::optional<SectionProfile> section_hook;  // analytic sections (plugin); else sliced mesh
};

/// Evaluates a validated mesh in the needle frame. `needle_material` names a built-in material or
/// one of the scene's [[materials]]. Throws InputError for inconsistent input (a needle shorter
/// than the depth, an unknown material).
DesignEvaluation evaluate_design(const TriangleMesh& mesh, const Scene& scene,
                                 const std::string& needle_material,
                                 const EvaluationOptions& options = {});

/// The scene's needle materials as NeedleMaterial values (fracture mode assumed for user ones).
std::vector<NeedleMaterial> scene_needle_materials(const Scene& scene);

}  // namespace mneedle
