#include "mneedle/measurement/toughness.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>

#include "mneedle/base/error.h"
#include "mneedle/base/units.h"
#include "mneedle/geometry/cross_section.h"
#include "mneedle/strength/section_table.h"

namespace mneedle {
namespace {

// Starts a pass at depth 0: clipped (interpolated) when it reaches below, else given zero force
// at 0, since before its contact nothing touched the needle.
ForceCurve start_at_zero(const ForceCurve& c) {
  ForceCurve out;
  out.source = c.source;
  if (c.depth_m.front() > 0.0) {
    out.depth_m.push_back(0.0);
    out.force_N.push_back(0.0);
  } else {
    out.depth_m.push_back(0.0);
    out.force_N.push_back(force_at(c, 0.0));
  }
  for (std::size_t i = 0; i < c.depth_m.size(); ++i) {
    if (c.depth_m[i] <= 0.0) continue;
    out.depth_m.push_back(c.depth_m[i]);
    out.force_N.push_back(c.force_N[i]);
  }
  return out;
}

std::size_t count_beyond(const ForceCurve& c, double end) {
  return static_cast<std::size_t>(
      std::count_if(c.depth_m.begin(), c.depth_m.end(), [end](double z) { return z > end; }));
}

// Samples of a pass (its own, not the zero added at depth 0) from depth 0 to `end`.
std::size_t samples_within(const ForceCurve& c, double end) {
  const double tolerance = 1e-9 * end;  // as for the grid: equal but for rounding
  return static_cast<std::size_t>(std::count_if(c.depth_m.begin(), c.depth_m.end(), [&](double z) {
    return z >= -tolerance && z <= end + tolerance;
  }));
}

std::size_t count_within(const ForceCurve& c, double end) {
  return c.depth_m.size() - count_beyond(c, end);
}

double trapezoid(const std::vector<double>& z, const std::vector<double>& f) {
  double sum = 0.0;
  for (std::size_t i = 1; i < z.size(); ++i) sum += 0.5 * (f[i] + f[i - 1]) * (z[i] - z[i - 1]);
  return sum;
}

InsertionPass constructed_pass(const InsertionPass& first, const std::string& how) {
  InsertionPass pass;
  pass.curve.source = first.cut.source + " (" + how + ")";
  pass.cut.source = pass.curve.source;
  return pass;
}

}  // namespace

InsertionPass prepare_pass(const ForceCurve& raw, const LoadingBranchOptions& options) {
  InsertionPass pass;
  pass.branch = extract_loading_branch(raw, options);
  const MonotoneCurve merged = merge_repeated_depths(pass.branch.curve);
  pass.curve = merged.curve;
  auto& cut = pass.cut;
  cut.source = raw.source;
  cut.rows = raw.depth_m.size();
  cut.points = pass.curve.depth_m.size();
  cut.before_contact = pass.branch.contact_index;
  cut.hold = pass.branch.hold_samples;
  cut.retraction = pass.branch.retraction_samples;
  cut.repeated_depth = merged.repeated_samples;
  cut.receding_depth = merged.receding_samples;
  cut.contact_travel_m = pass.branch.contact_travel_m;
  cut.baseline_N = pass.branch.baseline_N;
  cut.noise_N = pass.branch.noise_N;
  if (pass.curve.depth_m.size() < 2) {
    throw InputError(raw.source + ":" + std::to_string(raw.line[pass.branch.contact_index]) +
                     ": no loading branch: the depth never increases after contact");
  }
  return pass;
}

DepthAlignment parse_depth_alignment(std::string_view text) {
  if (text == "contact") return DepthAlignment::Contact;
  if (text == "travel") return DepthAlignment::Travel;
  throw InputError("--align '" + std::string(text) + "': expected contact or travel");
}

ForceDifference force_difference(const InsertionPass& first, const InsertionPass& second,
                                 const ToughnessOptions& options) {
  ForceCurve shifted = second.curve;
  if (options.alignment == DepthAlignment::Travel) {
    const double shift = second.cut.contact_travel_m - first.cut.contact_travel_m;
    for (auto& z : shifted.depth_m) z += shift;
  }
  const ForceCurve f = start_at_zero(first.curve);
  const ForceCurve b = start_at_zero(shifted);
  double end = std::min(f.depth_m.back(), b.depth_m.back());
  const std::string both = first.cut.source + " and " + second.cut.source;
  if (options.max_depth_m) {
    const double max_depth = *options.max_depth_m;
    if (!(max_depth > 0.0) || !std::isfinite(max_depth)) {
      throw InputError(both + ": --max-depth " + format_quantity(max_depth, Dimension::Length) +
                       ": must be a positive length");
    }
    end = std::min(end, max_depth);
  }
  if (!(end > 0.0)) throw InputError(both + ": no common depth range to integrate over");
  // A range shorter than a few samples gives a number, but not an integral of the curves
  // (docs/model.md, "Fracture toughness from two insertions", step 4).
  const std::size_t first_kept = samples_within(first.curve, end);
  const std::size_t second_kept = samples_within(shifted, end);
  if (std::min(first_kept, second_kept) < kMinIntegrationSamples) {
    const bool by_option = options.max_depth_m && *options.max_depth_m <= end;
    throw InputError(
        both + ": " + (by_option ? "--max-depth " : "the common depth range up to ") +
        format_quantity(end, Dimension::Length) + " keeps " + std::to_string(first_kept) +
        (first_kept == 1 ? " sample of " : " samples of ") + first.cut.source + " and " +
        std::to_string(second_kept) + " of " + second.cut.source + "; at least " +
        std::to_string(kMinIntegrationSamples) + " of each are needed");
  }
  ForceDifference out;
  out.end_depth_m = end;
  std::vector<double> grid;
  for (const auto* c : {&f, &b}) {
    for (double z : c->depth_m)
      if (z < end) grid.push_back(z);
  }
  grid.push_back(end);
  std::sort(grid.begin(), grid.end());
  // Depths equal but for rounding (0.101 mm - 0.100 mm vs 1 um) are one grid point.
  const double tolerance = 1e-9 * end;
  grid.erase(std::unique(grid.begin(), grid.end(),
                         [tolerance](double a, double b) { return b - a <= tolerance; }),
             grid.end());
  for (double z : grid) {
    out.depth_m.push_back(z);
    out.first_force_N.push_back(force_at(f, z));
    out.second_force_N.push_back(force_at(b, z));
  }
  std::vector<double> diff(grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i)
    diff[i] = out.first_force_N[i] - out.second_force_N[i];
  out.first_work_J = trapezoid(out.depth_m, out.first_force_N);
  out.second_work_J = trapezoid(out.depth_m, out.second_force_N);
  out.difference_work_J = trapezoid(out.depth_m, diff);
  out.first = first.cut;
  out.second = second.cut;
  out.first.points = count_within(f, end);
  out.first.beyond_end = count_beyond(f, end);
  out.second.points = count_within(b, end);
  out.second.beyond_end = count_beyond(b, end);
  return out;
}

double toughness_J_per_m2(const ForceDifference& difference, double crack_area_m2) {
  if (!(crack_area_m2 > 0.0) || !std::isfinite(crack_area_m2)) {
    throw InputError("crack area: expected a positive area, got " + std::to_string(crack_area_m2) +
                     " m^2");
  }
  return difference.difference_work_J / crack_area_m2;
}

CrackArea needle_crack_area(const TriangleMesh& needle_frame_mesh, double depth_m) {
  const SectionTable table = SectionTable::from_mesh(needle_frame_mesh, 200);
  CrackArea out;
  out.needle_length_m = table.length_m();
  out.tip_length_m = table.tip_length_m();
  // Stay just inside the mesh: a plane through the base's vertices gives degenerate loops.
  out.height_m = std::min(std::max(depth_m, 0.0), out.needle_length_m * (1.0 - 1e-7));
  out.area_m2 = CrossSectionSlicer(needle_frame_mesh).slice(out.height_m).area_m2;
  for (int i = 0; i <= 200; ++i) {
    const double h = out.needle_length_m * i / 200.0;
    if (h <= out.height_m) out.area_m2 = std::max(out.area_m2, table.at(h).area_m2);
  }
  return out;
}

double parse_area_m2(std::string_view text) {
  const auto fail = [&](const std::string& why) {
    return InputError("area '" + std::string(text) + "': " + why +
                      " (expected a length unit squared, e.g. 1.27mm^2, 0.04 mm2, 4e-7 m^2)");
  };
  std::string t(text);
  bool squared = false;
  for (const std::string suffix : {"^2", "\xC2\xB2", "2"}) {
    const std::size_t n = suffix.size();
    if (t.size() > n && t.compare(t.size() - n, n, suffix) == 0 &&
        std::isalpha(static_cast<unsigned char>(t[t.size() - n - 1]))) {
      t.erase(t.size() - n);
      squared = true;
      break;
    }
  }
  double value = 0.0;
  try {
    if (squared) {
      char* unit_start = nullptr;
      const double number = std::strtod(t.c_str(), &unit_start);
      if (unit_start == t.c_str()) throw fail("no number");
      if (!std::isfinite(number)) throw fail("not a finite number");  // 1e400: beyond a double
      const double metres = parse_quantity("1 " + std::string(unit_start), Dimension::Length);
      value = number * metres * metres;
    } else {
      // A bare number would be read in m^2, a million times the mm^2 a user usually means: the
      // unit is required, as for every dimensional value (docs/cli.md).
      char* end = nullptr;
      std::strtod(t.c_str(), &end);
      const char* rest = end;
      const bool plain = end != t.c_str() && std::all_of(rest, t.c_str() + t.size(), [](char c) {
                           return std::isspace(static_cast<unsigned char>(c));
                         });
      throw fail(plain ? "needs its unit" : "not an area");
    }
  } catch (const InputError& e) {
    if (std::string(e.what()).rfind("area '", 0) == 0) throw;
    throw fail(e.what());
  }
  if (!(value > 0.0) || !std::isfinite(value)) throw fail("must be positive");
  return value;
}

ForceDrop largest_force_drop(const ForceCurve& curve, double min_fraction) {
  ForceDrop drop;
  double best = -1.0;
  std::size_t peak = 0;
  for (std::size_t i = 0; i < curve.force_N.size(); ++i) {
    if (curve.force_N[i] > curve.force_N[peak]) peak = i;
    const double fall = curve.force_N[peak] - curve.force_N[i];
    if (fall > best) {
      best = fall;
      drop.peak_index = peak;
      drop.bottom_index = i;
    }
  }
  drop.peak_depth_m = curve.depth_m[drop.peak_index];
  drop.peak_force_N = curve.force_N[drop.peak_index];
  drop.bottom_depth_m = curve.depth_m[drop.bottom_index];
  drop.bottom_force_N = curve.force_N[drop.bottom_index];
  if (!(best > min_fraction * drop.peak_force_N) || drop.bottom_depth_m <= 0.0) {
    throw InputError(curve.source + ": no puncture: the force never drops by " +
                     std::to_string(static_cast<int>(100 * min_fraction)) +
                     " % of its peak, so there is no post-puncture part");
  }
  return drop;
}

InsertionPass second_pass_from_retraction(const ForceCurve& raw, const InsertionPass& first) {
  InsertionPass pass = constructed_pass(first, "retraction");
  const auto& b = first.branch;
  const std::size_t start = b.end_index + b.hold_samples + 1;
  ForceCurve way_in;  // retraction samples, deepest first reversed to shallowest first
  way_in.source = pass.curve.source;
  for (std::size_t i = raw.depth_m.size(); i-- > start;) {
    way_in.depth_m.push_back(raw.depth_m[i] - b.contact_travel_m);
    way_in.force_N.push_back(-(raw.force_N[i] - b.baseline_N));
    way_in.line.push_back(raw.line[i]);
  }
  // Samples outside the tissue (below contact) are clipped except the last one, which anchors
  // the interpolation at depth 0.
  std::size_t first_inside = 0;
  while (first_inside + 1 < way_in.depth_m.size() && way_in.depth_m[first_inside + 1] <= 0.0)
    ++first_inside;
  ForceCurve inside;
  inside.source = way_in.source;
  for (std::size_t i = first_inside; i < way_in.depth_m.size(); ++i) {
    inside.depth_m.push_back(way_in.depth_m[i]);
    inside.force_N.push_back(way_in.force_N[i]);
    inside.line.push_back(way_in.line[i]);
  }
  const MonotoneCurve merged = merge_repeated_depths(inside);
  if (merged.curve.depth_m.size() < 2 ||
      merged.curve.depth_m.back() < 0.5 * first.curve.depth_m.back()) {
    throw InputError(raw.source + ": no retraction to build a second pass from (" +
                     std::to_string(b.retraction_samples) + " samples after the hold)");
  }
  pass.curve.depth_m = merged.curve.depth_m;
  pass.curve.force_N = merged.curve.force_N;
  pass.cut.rows = way_in.depth_m.size();
  pass.cut.before_contact = first_inside;
  pass.cut.repeated_depth = merged.repeated_samples;
  pass.cut.receding_depth = merged.receding_samples;
  pass.cut.contact_travel_m = b.contact_travel_m;
  pass.cut.baseline_N = b.baseline_N;
  pass.cut.noise_N = b.noise_N;
  pass.cut.points = pass.curve.depth_m.size();
  return pass;
}

InsertionPass second_pass_from_tail(const InsertionPass& first, ForceDrop* drop_out) {
  const ForceDrop drop = largest_force_drop(first.curve);
  if (drop_out) *drop_out = drop;
  InsertionPass pass = constructed_pass(first, "post-puncture tail");
  const auto& c = first.curve;
  for (std::size_t i = 0; i < c.depth_m.size(); ++i) {
    const double z = c.depth_m[i];
    pass.curve.depth_m.push_back(z);
    pass.curve.force_N.push_back(i >= drop.bottom_index ? c.force_N[i]
                                                        : std::max(z, 0.0) / drop.bottom_depth_m *
                                                              drop.bottom_force_N);
  }
  pass.cut.contact_travel_m = first.cut.contact_travel_m;
  pass.cut.baseline_N = first.cut.baseline_N;
  pass.cut.points = pass.curve.depth_m.size();
  return pass;
}

}  // namespace mneedle
