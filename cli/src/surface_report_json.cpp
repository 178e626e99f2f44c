#include "surface_report_json.h"

#include <string>

#include "json_output.h"
#include "mneedle/geometry/surface_report.h"

namespace mneedle::cli {

nlohmann::json surface_report_json(const TriangleMesh& mesh, const std::vector<double>& heights_m) {
  const SurfaceReport report = surface_report(mesh, heights_m);
  nlohmann::json groups = nlohmann::json::object();
  for (SurfaceGroup g :
       {SurfaceGroup::alpha, SurfaceGroup::beta, SurfaceGroup::side, SurfaceGroup::back}) {
    const GroupSummary& s = report.groups.of(g);
    groups[std::string(group_name(g))] = {{"count", s.count}, {"area_m2", s.area_m2}};
  }
  nlohmann::json tip_area = nlohmann::json::array();
  for (const TipAreaPoint& p : report.tip_area) {
    tip_area.push_back({{"height_m", p.height_m}, {"area_m2", p.area_m2}});
  }
  nlohmann::json out = {{"groups", groups}, {"tip_area", tip_area}};
  require_finite_json(out, "surface report");
  return out;
}

}  // namespace mneedle::cli
