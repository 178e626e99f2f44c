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

// The field as a number in SI (times the column's unit `scale`). A depth or force (`bounded`)
// beyond kLargestSample in SI is no measurement (a force of 10^308 N once passed as a puncture, its
// work 5e302 J) and a value that overflows only in SI (10^308 kN) would be dropped as noise two
// checks later: both are refused here, on their own line.
constexpr double kLargestSample = 1e9;  // N or m: far beyond any insertion recording

double parse_number(const std::string& field, const std::string& column, const std::string& source,
                    std::size_t line, double scale, bool bounded = true) {
  double value = 0.0;
  const char* end = field.data() + field.size();
  const auto [ptr, ec] = std::from_chars(field.data(), end, value);
  if (field.empty() || ec != std::errc() || ptr != end || !std::isfinite(value)) {
    throw InputError(where(source, line) + ": column '" + column + "': '" + field +
                     "' is not a number");
  }
  const double si = scale * value;
  if (!std::isfinite(si) || (bounded && !(std::abs(si) <= kLargestSample))) {
    throw InputError(where(source, line) + ": column '" + column + "': '" + field +
                     (std::isfinite(si)
                          ? "' is beyond any measurement (its size in SI is above 1e9)"
                          : "' overflows in SI units"));
  }
  return si;
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

// Whether the first m forces climb rather than stay flat: the straight line fitted through them
// (least squares against the sample index) rises across them by more than noise_factor times
// their robust spread about that line and by more than min_rise_fraction of the peak above their
// lowest force. The spread is taken about the line, not about the median, so that a climbing
// head does not pass its own rise off as noise. Needs m >= 4 (3 points leave the spread
// about a line no degree of freedom to show).
bool head_rises(const std::vector<double>& force, std::size_t m, double highest,
                const LoadingBranchOptions& options) {
  const double xm = 0.5 * static_cast<double>(m - 1);
  double ym = 0.0;
  for (std::size_t i = 0; i < m; ++i) ym += force[i];
  ym /= static_cast<double>(m);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double dx = static_cast<double>(i) - xm;
    sxy += dx * (force[i] - ym);
    sxx += dx * dx;
  }
  const double slope = sxy / sxx;
  std::vector<double> residual(m);
  for (std::size_t i = 0; i < m; ++i)
    residual[i] = force[i] - (ym + slope * (static_cast<double>(i) - xm));
  const double centre = median(residual);
  for (auto& r : residual) r = std::abs(r - centre);
  const double spread = 1.4826 * median(residual);
  const double lowest =
      *std::min_element(force.begin(), force.begin() + static_cast<std::ptrdiff_t>(m));
  const double rise = slope * static_cast<double>(m - 1);
  return rise > options.noise_factor * spread &&
         rise > options.min_rise_fraction * (highest - lowest);
}

struct Baseline {
  double level_N = 0.0;  // sensor offset
  double noise_N = 0.0;  // robust standard deviation about it
};

// Median and scaled median absolute deviation of the first `head` forces.
Baseline head_baseline(const std::vector<double>& force, std::size_t head) {
  std::vector<double> leading(force.begin(), force.begin() + static_cast<std::ptrdiff_t>(head));
  Baseline b;
  b.level_N = median(leading);
  for (auto& f : leading) f = std::abs(f - b.level_N);
  b.noise_N = 1.4826 * median(leading);
  return b;
}

// The force rises at the first sample above the baseline by more than max(noise_factor noise,
// min_rise_fraction of the peak); contact is the last sample before that within one noise
// deviation of the baseline (or the first sample). nullopt when the force never rises.
std::optional<std::size_t> find_contact(const std::vector<double>& force, const Baseline& base,
                                        double highest, const LoadingBranchOptions& options) {
  const double peak = highest - base.level_N;
  if (!(peak > 0.0)) return std::nullopt;
  const double threshold =
      std::max(options.noise_factor * base.noise_N, options.min_rise_fraction * peak);
  std::size_t contact = 0;
  while (contact < force.size() && !(force[contact] - base.level_N > threshold)) ++contact;
  if (contact == force.size()) return std::nullopt;
  // Walk back to where the force was last within the noise: that is where the needle touched.
  while (contact > 0 && force[contact - 1] - base.level_N > base.noise_N) --contact;
  if (contact > 0) --contact;
  return contact;
}

// The travel must grow into the tissue. A recording whose deepest travel is its first sample and
// which then goes shallower (a retraction alone, rows in reverse order, or a depth axis pointing
// out of the tissue) has no loading branch; say so before looking at the force, whose rise would
// otherwise be searched for in the wrong direction.
void require_advancing_travel(const ForceCurve& raw) {
  const auto& z = raw.depth_m;
  if (deepest_index(z, 0) != 0) return;
  std::size_t shallowest = 0;
  for (std::size_t i = 1; i < z.size(); ++i)
    if (z[i] < z[shallowest]) shallowest = i;
  if (shallowest == 0) return;  // constant travel: reported as not advancing after contact
  std::size_t first_step = 1;
  while (z[first_step] >= z[0]) ++first_step;
  const std::string column =
      raw.depth_column.empty() ? "the depth" : "column '" + raw.depth_column + "'";
  throw InputError(where(raw.source, raw.line[first_step]) + ": " + column +
                   " decreases from its first sample (" +
                   format_quantity(z[0] + 0.0, Dimension::Length) + " at line " +
                   std::to_string(raw.line[0]) + " to " +
                   format_quantity(z[shallowest], Dimension::Length) + " at line " +
                   std::to_string(raw.line[shallowest]) +
                   ") and never goes deeper: depth must increase into the tissue (rows reversed, "
                   "a retraction alone, or an axis pointing out of the tissue?)");
}

ForceCurve slice(const ForceCurve& raw, std::size_t first, std::size_t last) {
  ForceCurve out;
  out.source = raw.source;
  out.depth_column = raw.depth_column;
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
  if (b.contact_before_first_sample) {
    s << "; already loaded at the first sample: contact at travel 0, no baseline removed";
  } else if (b.starts_at_contact) {
    s << "; fewer than 3 samples before contact: no baseline removed";
  }
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
  const auto found_time = find_column(header, columns.time, {"time", "t"});
  if (!columns.time.empty() && !found_time) {
    require_column(header, columns.time, {}, "time", curve.source);
  }
  // A column found by its name alone (`time`, `time_stamp`, `t_C`) whose unit is no time is not
  // the recording's clock: it is left unread (it blocked files whose time no command needed;
  // one that needs the speed then asks for --speed). A column named by the caller must read.
  const bool clock = [&] {
    if (!found_time || !columns.time.empty()) return found_time.has_value();
    try {
      column_scale(header[*found_time], "", Dimension::Time, curve.source);
      return true;
    } catch (const InputError&) {
      return false;
    }
  }();
  const std::size_t time_index = clock ? *found_time : 0;
  const double depth_scale =
      column_scale(header[depth_col], columns.depth_unit, Dimension::Length, curve.source);
  const double force_scale =
      column_scale(header[force_col], columns.force_unit, Dimension::Force, curve.source);
  const double time_scale =
      clock ? column_scale(header[time_index], "", Dimension::Time, curve.source) : 1.0;
  curve.depth_column = header[depth_col];
  for (const auto& row : table.rows) {
    const auto& fields = row.fields;
    const std::size_t line_number = row.line;
    curve.depth_m.push_back(
        parse_number(fields[depth_col], header[depth_col], curve.source, line_number, depth_scale));
    curve.force_N.push_back(
        parse_number(fields[force_col], header[force_col], curve.source, line_number, force_scale));
    if (clock) {
      // Clock time (Unix seconds, 1.7e9) is a time too: only a non-finite one is refused.
      curve.time_s.push_back(parse_number(fields[time_index], header[time_index], curve.source,
                                          line_number, time_scale, false));
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
  require_advancing_travel(raw);
  // The approach (before any force) gives the sensor offset and its noise: the first 5 % of the
  // samples, but only while they are flat and only those before contact (docs/model.md, "Curve
  // reading"). A head whose force climbs along it is halved until it does not; a contact found
  // inside the head means it holds loaded samples, so the baseline is taken again from the
  // samples before that contact, until they all precede it.
  const double highest = *std::max_element(raw.force_N.begin(), raw.force_N.end());
  std::size_t head = std::clamp<std::size_t>(n / 20, 3, 200);
  while (head >= 4 && head_rises(raw.force_N, head, highest, options)) head /= 2;
  LoadingBranch b;
  b.starts_at_contact = head < 3;
  Baseline base;
  std::optional<std::size_t> found;
  if (!b.starts_at_contact) {
    base = head_baseline(raw.force_N, head);
    found = find_contact(raw.force_N, base, highest, options);
    if (!found) {
      throw InputError(where(raw.source, raw.line.back()) +
                       ": no loading branch: the force never rises above the noise (baseline " +
                       std::to_string(base.level_N) + " N, noise " + std::to_string(base.noise_N) +
                       " N)");
    }
    while (*found < head) {
      if (*found < 3) {
        b.starts_at_contact = true;
        break;
      }
      head = *found;
      const Baseline shorter = head_baseline(raw.force_N, head);
      const auto again = find_contact(raw.force_N, shorter, highest, options);
      if (!again) break;  // too few samples left to see the rise against: keep the longer head
      base = shorter;
      found = again;
    }
  }
  if (b.starts_at_contact) {
    // Fewer than 3 flat samples precede contact: the force rises from (about) the first sample
    // and the recording has no unloaded part to measure an offset on. Its force is taken as
    // already zeroed, as `mneedle simulate --csv` and `mneedle force --csv` write it, and contact
    // is the last sample at or below zero force before the rise, or the first sample.
    base = Baseline{};
    found = find_contact(raw.force_N, base, highest, options).value_or(0);
  }
  b.baseline_N = base.level_N;
  b.noise_N = base.noise_N;
  const std::size_t contact = *found;
  b.contact_index = contact;
  // Already loaded at the first sample, which lies within one step of travel 0: the recording
  // was written from the surface on (depth below the surface, as `mneedle simulate --csv` writes
  // it from its first step), so the surface at travel 0 is the contact.
  const auto& z = raw.depth_m;
  b.contact_before_first_sample = b.starts_at_contact && contact == 0 && raw.force_N[0] > 0.0 &&
                                  z[0] > 0.0 && z[0] <= z[1] - z[0];
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
  b.contact_travel_m = b.contact_before_first_sample ? 0.0 : raw.depth_m[contact];
  b.curve = slice(raw, contact, b.end_index);
  for (auto& d : b.curve.depth_m) d -= b.contact_travel_m;
  for (auto& f : b.curve.force_N) f -= b.baseline_N;
  b.summary = describe_cut(raw, b);
  return b;
}

double force_at(const ForceCurve& c, double z) {
  const auto& d = c.depth_m;
  if (z <= d.front()) return c.force_N.front();
  if (z >= d.back()) return c.force_N.back();
  const auto i = static_cast<std::size_t>(std::upper_bound(d.begin(), d.end(), z) - d.begin());
  const double t = (z - d[i - 1]) / (d[i] - d[i - 1]);
  return c.force_N[i - 1] + t * (c.force_N[i] - c.force_N[i - 1]);
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
