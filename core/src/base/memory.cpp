#include "mneedle/base/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <utility>

#include "mneedle/base/error.h"

namespace mneedle {

namespace {

// The limit set by set_memory_limit_bytes; 0 = none (a zero budget is not a useful limit).
std::atomic<std::size_t> g_limit{0};

std::optional<std::size_t> parse_count(std::string_view text) {
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  std::size_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc{} || end != text.data() + text.size() || text.empty()) return std::nullopt;
  return value;
}

std::string read_text(const char* path) {
  std::ifstream in(path);
  if (!in) return {};
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// This process's cgroup v2 folder ("0::/path" in /proc/self/cgroup), empty when not on v2.
std::string own_cgroup() {
  std::istringstream lines(read_text("/proc/self/cgroup"));
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("0::", 0) == 0) return "/sys/fs/cgroup" + line.substr(3);
  return {};
}

// The resident set now (bytes): /proc/self/statm's second field, in pages.
std::size_t resident_bytes() {
  const std::string text = read_text("/proc/self/statm");
  const auto space = text.find(' ');
  if (space == std::string::npos) return 0;
  const std::string rest = text.substr(space + 1);
  const auto pages = parse_count(rest.substr(0, rest.find(' ')));
  const long page = sysconf(_SC_PAGESIZE);
  return pages && page > 0 ? *pages * static_cast<std::size_t>(page) : 0;
}

}  // namespace

std::size_t peak_memory_bytes() {
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) != 0) return 0;
  return static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // Linux counts ru_maxrss in KiB
}

std::size_t parse_memory_size(std::string_view text) {
  const std::string quoted = "'" + std::string(text) + "'";
  std::string_view rest = text;
  while (!rest.empty() && (rest.front() == ' ' || rest.front() == '\t')) rest.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(rest.data(), rest.data() + rest.size(), value);
  if (error != std::errc{} || !std::isfinite(value) || value <= 0.0)
    throw InputError(quoted + ": expected a positive size with a unit, e.g. '4 GiB'");
  std::string_view unit(end, static_cast<std::size_t>(rest.data() + rest.size() - end));
  while (!unit.empty() && (unit.front() == ' ' || unit.front() == '\t')) unit.remove_prefix(1);
  while (!unit.empty() && (unit.back() == ' ' || unit.back() == '\t')) unit.remove_suffix(1);
  constexpr std::pair<std::string_view, double> kUnits[] = {
      {"B", 1.0},         {"kB", 1e3},           {"MB", 1e6},
      {"GB", 1e9},        {"TB", 1e12},          {"KiB", 1024.0},
      {"MiB", 1048576.0}, {"GiB", 1073741824.0}, {"TiB", 1099511627776.0}};
  for (const auto& [name, scale] : kUnits)
    if (unit == name) {
      const double bytes = value * scale;
      if (bytes >= 1e18) throw InputError(quoted + ": larger than any machine's memory");
      if (bytes < 1.0) throw InputError(quoted + ": less than a byte");
      return static_cast<std::size_t>(bytes);
    }
  throw InputError(
      quoted + ": " +
      (unit.empty() ? std::string("no unit") : "unknown unit '" + std::string(unit) + "'") +
      " (B, kB, MB, GB, TB, KiB, MiB, GiB or TiB)");
}

std::optional<std::size_t> meminfo_available_bytes(std::string_view meminfo) {
  constexpr std::string_view key = "MemAvailable:";
  const auto at = meminfo.find(key);
  if (at == std::string_view::npos) return std::nullopt;
  std::string_view line = meminfo.substr(at + key.size());
  line = line.substr(0, line.find('\n'));
  const auto unit = line.find("kB");
  if (unit == std::string_view::npos) return std::nullopt;
  const auto kib = parse_count(line.substr(0, unit));
  if (!kib) return std::nullopt;
  return *kib * 1024;
}

std::optional<std::size_t> cgroup_room_bytes(std::string_view max, std::string_view current,
                                             std::string_view stat) {
  const auto limit = parse_count(max);  // "max" does not parse: no limit
  const auto used = parse_count(current);
  if (!limit || !used) return std::nullopt;
  // memory.current counts the group's page cache, which the kernel drops on demand: a container
  // that has just compiled the project sits near its limit with little of it held.
  std::size_t cache = 0;
  for (const std::string_view key : {"active_file ", "inactive_file "}) {
    for (std::size_t at = stat.find(key); at != std::string_view::npos;
         at = stat.find(key, at + 1)) {
      if (at != 0 && stat[at - 1] != '\n') continue;  // a key at a line's start only
      std::string_view value = stat.substr(at + key.size());
      value = value.substr(0, value.find('\n'));
      if (const auto bytes = parse_count(value)) cache += *bytes;
      break;
    }
  }
  const std::size_t held = *used > cache ? *used - cache : 0;
  return *limit > held ? *limit - held : 0;
}

std::optional<std::size_t> available_memory_bytes() {
  std::optional<std::size_t> room = meminfo_available_bytes(read_text("/proc/meminfo"));
  auto take = [&room](std::optional<std::size_t> other) {
    if (other) room = room ? std::min(*room, *other) : *other;
  };
  const std::string group = own_cgroup();
  if (!group.empty())
    take(cgroup_room_bytes(read_text((group + "/memory.max").c_str()),
                           read_text((group + "/memory.current").c_str()),
                           read_text((group + "/memory.stat").c_str())));
  if (const std::size_t limit = g_limit.load(); limit > 0) {
    // The process's own budget counts what it holds now against it.
    const std::size_t held = resident_bytes();
    take(limit > held ? limit - held : 0);
  }
  return room;
}

void set_memory_limit_bytes(std::optional<std::size_t> bytes) {
  g_limit.store(bytes.value_or(0));
}

}  // namespace mneedle
