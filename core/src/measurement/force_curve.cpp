#include "mneedle/measurement/force_curve.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "mneedle/base/csv.h"
#include "mneedle/base/error.h"
#include "mneedle/base/units.h"

namespace mneedle {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

std::string joined(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string where(const std::string& source, std::size_t line) {
  return source + ":" + std::to_string(line);
}

// The unit written in brackets at the end of a column name ("z [mm]" -> "mm"), or "".
std::string bracketed_unit(const std::string& column) {
  if (column.size() < 3) return {};
  const char close = column.back();
  const char open = close == ']' ? '[' : close == ')' ? '(' : '\0';
  const auto at = open ? column.rfind(open) : std::string::npos;
  if (at == std::string::npos) return {};
  return std::string(trim(std::string_view(column).substr(at + 1, column.size() - at - 2)));
}

// The column name without a bracketed unit ("z [mm]" -> "z").
std::string name_without_unit(const std::string& column) {
  if (bracketed_unit(column).empty()) return column;
  return std::string(trim(
      std::string_view(column).substr(0, column.find_last_of(column.back() == ']' ? '[' : '('))));
}

// Index of the column called `wanted`, or (when empty) of the first column starting with one of
// `prefixes` followed by '_' or the end of the name (a bracketed unit not counted).
std::optional<std::size_t> find_column(const std::vector<std::string>& header,
                                       const std::string& wanted,
                                       const std::vector<std::string>& prefixes) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (!wanted.empty()) {
      if (header[i] == wanted) return i;
      continue;
    }
    const auto name = lower(name_without_unit(header[i]));
    for (const auto& p : prefixes) {
      if (name == p || name.rfind(p + "_", 0) == 0) return i;
    }
  }
  return std::nullopt;
}

std::size_t require_column(const std::vector<std::string>& header, const std::string& wanted,
                           const std::vector<std::string>& prefixes, const std::string& role,
                           const std::string& source) {
  if (auto i = find_column(header, wanted, prefixes)) return *i;
  const std::string asked =
      wanted.empty() ? "no " + role + " column" : "no column '" + wanted + "'";
  throw InputError(where(source, 1) + ": " + asked + " (columns: " + joined(header) + ")");
}

// SI factor of a column from an explicit unit, a bracketed unit or the suffix after the last '_'.
double column_scale(const std::string& column, const std::string& unit, Dimension dimension,
                    const std::string& source) {
  std::string text = unit.empty() ? bracketed_unit(column) : unit;
  if (text.empty()) {
    const auto underscore = column.rfind('_');
    if (underscore == std::string::npos) {
      throw InputError(where(source, 1) + ": column '" + column + "' has no unit suffix (like _" +
                       std::string(si_unit(dimension)) + "); give the unit as an option");
    }
    text = column.substr(underscore + 1);
  }
  try {
    return parse_quantity("1 " + text, dimension);
  } catch (const InputError& e) {
    throw InputError(where(source, 1) + ": column '" + column + "': " + e.what());
  }
}

double parse_number(const std::string& field, const std::string& column, const std::string& source,
                    std::size_t line) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (field.empty() || ec != std::errc() || ptr != end || !std::isfinite(value)) {
    throw InputError(where(source, line) + ": column '" + column + "': '" + field +
                     "' is not a number");
  }
  return value;
}

double median(std::vector<double> v) {
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

std::size_t deepest_index(const std::vector<double>& depth, std::size_t from) {
  const double max_depth =
      *std::max_element(depth.begin() + static_cast<std::ptrdiff_t>(from), depth.end());
  const double range = max_depth - *std::min_element(depth.begin(), depth.end());
  const double tolerance = 2e-3 * range;  // stage encoders settle within ~0.2 % of the stroke
  for (std::size_t i = from; i < depth.size(); ++i) {
    if (depth[i] >= max_depth - tolerance) return i;
  }
  return depth.size() - 1;
}

ForceCurve slice(const ForceCurve& raw, std::size_t first, std::size_t last) {
  ForceCurve out;
  out.source = raw.source;
  for (std::size_t i = first; i <= last; ++i) {
    if (!raw.time_s.empty()) out.time_s.push_back(raw.time_s[i]);
    out.depth_m.push_back(raw.depth_m[i]);
    out.force_N.push_back(raw.force_N[i]);
    out.line.push_back(raw.line[i]);
  }
  return out;
}

std::string describe_cut(const ForceCurve& raw, const LoadingBranch& b) {
  std::ostringstream s;
  s << raw.source << ": kept lines " << raw.line[b.contact_index] << "-" << raw.line[b.end_index]
    << " (" << (b.end_index - b.contact_index + 1) << " samples, contact at travel "
    << b.contact_travel_m * 1e3 << " mm, baseline " << b.baseline_N << " N removed); cut "
    << b.contact_index << " before contact, " << b.hold_samples << " in the hold, "
    << b.retraction_samples << " in the retraction";
  return s.str();
}

}  // namespace

ForceCurve read_force_curve_csv(const std::filesystem::path& file, const CurveColumns& columns) {
  const CsvTable table = read_csv(file);
  ForceCurve curve;
  curve.source = table.source;
  const auto& header = table.header;
  const auto depth_col =
      require_column(header, columns.depth, {"depth", "travel", "position", "displacement", "z"},
                     "depth", curve.source);
  const auto force_col =
      require_column(header, columns.force, {"force", "fz", "f"}, "force", curve.source);
  const auto time_col = find_column(header, columns.time, {"time", "t"});
  if (!columns.time.empty() && !time_col) {
    require_column(header, columns.time, {}, "time", curve.source);
  }
  const double depth_scale =
      column_scale(header[depth_col], columns.depth_unit, Dimension::Length, curve.source);
  const double force_scale =
      column_scale(header[force_col], columns.force_unit, Dimension::Force, curve.source);
  const double time_scale =
      time_col ? column_scale(header[*time_col], "", Dimension::Time, curve.source) : 1.0;
  for (const auto& row : table.rows) {
    const auto& fields = row.fields;
    const std::size_t line_number = row.line;
    curve.depth_m.push_back(depth_scale * parse_number(fields[depth_col], header[depth_col],
                                                       curve.source, line_number));
    curve.force_N.push_back(force_scale * parse_number(fields[force_col], header[force_col],
                                                       curve.source, line_number));
    if (time_col) {
      curve.time_s.push_back(time_scale * parse_number(fields[*time_col], header[*time_col],
                                                       curve.source, line_number));
    }
    curve.line.push_back(line_number);
  }
  if (curve.depth_m.empty()) {
    throw InputError(table.where(table.header_line) + ": no data rows after the header");
  }
  return curve;
}

LoadingBranch extract_loading_branch(const ForceCurve& raw, const LoadingBranchOptions& options) {
  const std::size_t n = raw.force_N.size();
  if (n < 3) throw InputError(raw.source + ": no loading branch: fewer than 3 samples");
  // The approach (before any force) gives the sensor offset and its noise.
  const std::size_t window = std::clamp<std::size_t>(n / 20, 3, 200);
  std::vector<double> head(raw.force_N.begin(),
                           raw.force_N.begin() + static_cast<std::ptrdiff_t>(window));
  LoadingBranch b;
  b.baseline_N = median(head);
  for (auto& f : head) f = std::abs(f - b.baseline_N);
  b.noise_N = 1.4826 * median(head);
  const double peak = *std::max_element(raw.force_N.begin(), raw.force_N.end()) - b.baseline_N;
  const double threshold =
      std::max(options.noise_factor * b.noise_N, options.min_rise_fraction * peak);
  std::size_t rise = n;
  for (std::size_t i = 0; i < n && rise == n; ++i) {
    if (raw.force_N[i] - b.baseline_N > threshold && peak > 0.0) rise = i;
  }
  if (rise == n) {
    throw InputError(where(raw.source, raw.line.back()) +
                     ": no loading branch: the force never rises above the noise (baseline " +
                     std::to_string(b.baseline_N) + " N, noise " + std::to_string(b.noise_N) +
                     " N)");
  }
  // Walk back to where the force was last within the noise: that is where the needle touched.
  std::size_t contact = rise;
  while (contact > 0 && raw.force_N[contact - 1] - b.baseline_N > b.noise_N) --contact;
  if (contact > 0) --contact;
  b.contact_index = contact;
  b.end_index = deepest_index(raw.depth_m, contact);
  if (b.end_index < contact + 2 || raw.depth_m[b.end_index] <= raw.depth_m[contact]) {
    throw InputError(where(raw.source, raw.line[contact]) +
                     ": no loading branch: the needle does not advance after contact");
  }
  const double max_depth = raw.depth_m[b.end_index];
  const double range = max_depth - *std::min_element(raw.depth_m.begin(), raw.depth_m.end());
  std::size_t i = b.end_index + 1;
  while (i < n && raw.depth_m[i] >= max_depth - 2e-3 * range) ++i, ++b.hold_samples;
  b.retraction_samples = n - i;
  b.contact_travel_m = raw.depth_m[contact];
  b.curve = slice(raw, contact, b.end_index);
  for (auto& d : b.curve.depth_m) d -= b.contact_travel_m;
  for (auto& f : b.curve.force_N) f -= b.baseline_N;
  b.summary = describe_cut(raw, b);
  return b;
}

MonotoneCurve merge_repeated_depths(const ForceCurve& curve) {
  MonotoneCurve out;
  out.curve.source = curve.source;
  const bool timed = curve.time_s.size() == curve.depth_m.size();
  std::size_t members = 0;  // samples in the current group
  for (std::size_t i = 0; i < curve.depth_m.size(); ++i) {
    const double z = curve.depth_m[i];
    if (members > 0 && z <= out.curve.depth_m.back()) {
      ++(z == out.curve.depth_m.back() ? out.repeated_samples : out.receding_samples);
      auto& mean = out.curve.force_N.back();
      mean += (curve.force_N[i] - mean) / static_cast<double>(++members);
      continue;
    }
    out.curve.depth_m.push_back(z);
    out.curve.force_N.push_back(curve.force_N[i]);
    if (timed) out.curve.time_s.push_back(curve.time_s[i]);
    if (i < curve.line.size()) out.curve.line.push_back(curve.line[i]);
    members = 1;
  }
  return out;
}

ForceCurve hold_segment(const ForceCurve& raw, const LoadingBranch& branch) {
  ForceCurve hold;
  hold.source = raw.source;
  if (raw.time_s.empty() || branch.hold_samples == 0) return hold;
  hold = slice(raw, branch.end_index, branch.end_index + branch.hold_samples);
  const double t0 = hold.time_s.front();
  for (auto& t : hold.time_s) t -= t0;
  for (auto& d : hold.depth_m) d -= branch.contact_travel_m;
  for (auto& f : hold.force_N) f -= branch.baseline_N;
  return hold;
}

double loading_speed(const LoadingBranch& branch) {
  const auto& t = branch.curve.time_s;
  const auto& z = branch.curve.depth_m;
  if (t.size() != z.size() || t.size() < 2) {
    throw InputError(branch.curve.source + ": no time column, give the speed explicitly");
  }
  double mt = 0, mz = 0;
  for (std::size_t i = 0; i < t.size(); ++i) mt += t[i], mz += z[i];
  mt /= static_cast<double>(t.size());
  mz /= static_cast<double>(t.size());
  double stz = 0, stt = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    stz += (t[i] - mt) * (z[i] - mz);
    stt += (t[i] - mt) * (t[i] - mt);
  }
  if (stt <= 0.0 || stz <= 0.0) {
    throw InputError(branch.curve.source + ": the travel does not advance with time");
  }
  return stz / stt;
}

}  // namespace mneedle
