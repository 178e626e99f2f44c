#include "mneedle/base/memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>

#include "mneedle/base/error.h"

namespace mneedle {

namespace {

// The limit set by set_memory_limit_bytes; 0 = none (a zero budget is not a useful limit).
// OpenBLAS's work buffer (BUFFER_SIZE of Debian's build, seen in its mmap calls).
constexpr std::size_t kBlasBufferBytes = std::size_t{128} << 20;
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

// Field `index` of /proc/self/statm (0: the address space, 1: the resident set), in bytes; 0
// where it cannot be read.
std::size_t statm_bytes(int index) {
  std::istringstream fields(read_text("/proc/self/statm"));
  std::string field;
  for (int i = 0; i <= index; ++i)
    if (!(fields >> field)) return 0;
  const auto pages = parse_count(field);
  const long page = sysconf(_SC_PAGESIZE);
  return pages && page > 0 ? *pages * static_cast<std::size_t>(page) : 0;
}

}  // namespace

std::size_t resident_memory_bytes() {
  return statm_bytes(1);
}

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
  // An address-space limit (ulimit -v, as batch systems set): mappings count, resident or not.
  // OpenBLAS maps a work buffer per calling thread on first use and, when the limit refuses
  // it, retries for ever (Debian's 0.3.21), so room for those is kept back.
  if (rlimit space{}; getrlimit(RLIMIT_AS, &space) == 0 && space.rlim_cur != RLIM_INFINITY) {
    const auto limit = static_cast<std::size_t>(space.rlim_cur);
    const std::size_t held =
        statm_bytes(0) + kBlasBufferBytes * (std::thread::hardware_concurrency() + 1);
    take(limit > held ? limit - held : 0);
  }
  if (const std::size_t limit = g_limit.load(); limit > 0) {
    // The process's own budget counts what it holds now against it.
    const std::size_t held = resident_memory_bytes();
    take(limit > held ? limit - held : 0);
  }
  return room;
}

void set_memory_limit_bytes(std::optional<std::size_t> bytes) {
  g_limit.store(bytes.value_or(0));
}

std::string memory_size_text(double bytes) {
  std::ostringstream out;
  out << std::fixed;
  if (bytes < 1024.0 * 1024.0 * 1024.0)
    out << std::setprecision(0) << bytes / (1024.0 * 1024.0) << " MiB";
  else
    out << std::setprecision(2) << bytes / (1024.0 * 1024.0 * 1024.0) << " GiB";
  return out.str();
}

namespace {

// Bytes reserved by reserve_memory and not yet released, in the whole process and by thread.
std::mutex g_reserved_mutex;
std::condition_variable g_reserved_released;
double g_reserved = 0.0;
std::unordered_map<std::thread::id, double> g_reserved_by_thread;

}  // namespace

MemoryReservation::MemoryReservation(double bytes, std::thread::id owner)
    : bytes_(bytes), owner_(owner) {}

MemoryReservation::~MemoryReservation() {
  release();
}

MemoryReservation::MemoryReservation(MemoryReservation&& other) noexcept
    : bytes_(std::exchange(other.bytes_, 0.0)), owner_(other.owner_) {}

MemoryReservation& MemoryReservation::operator=(MemoryReservation&& other) noexcept {
  if (this != &other) {
    release();
    bytes_ = std::exchange(other.bytes_, 0.0);
    owner_ = other.owner_;
  }
  return *this;
}

void MemoryReservation::release() {
  if (bytes_ <= 0.0) return;
  {
    const std::lock_guard<std::mutex> lock(g_reserved_mutex);
    g_reserved -= bytes_;
    const auto mine = g_reserved_by_thread.find(owner_);
    if (mine != g_reserved_by_thread.end() && (mine->second -= bytes_) <= 0.0)
      g_reserved_by_thread.erase(mine);
  }
  bytes_ = 0.0;
  g_reserved_released.notify_all();
}

MemoryReservation reserve_memory(double bytes, std::string_view what, std::string_view remedy) {
  std::unique_lock<std::mutex> lock(g_reserved_mutex);
  for (;;) {
    const std::optional<std::size_t> room = available_memory_bytes();
    const double left = room ? static_cast<double>(*room) : 0.0;
    if (!room || bytes <= left - g_reserved) {
      // Unknown room: nothing is checked, and nothing is held that others would wait for.
      if (!room) return {};
      g_reserved += bytes;
      g_reserved_by_thread[std::this_thread::get_id()] += bytes;
      return MemoryReservation(bytes, std::this_thread::get_id());
    }
    // Other threads' reservations turn into allocations the room then counts: wait for them
    // when the block fits beside what is allocated now, never for this thread's own.
    const auto mine = g_reserved_by_thread.find(std::this_thread::get_id());
    const double own = mine == g_reserved_by_thread.end() ? 0.0 : mine->second;
    if (bytes > left || g_reserved - own <= 0.0)
      throw OutOfMemoryError(std::string(what) + " needs " + memory_size_text(bytes) +
                             ", more than the " + memory_size_text(std::max(left, 0.0)) +
                             " of memory left to this process; " + std::string(remedy));
    g_reserved_released.wait(lock);
  }
}

void require_memory(double bytes, std::string_view what, std::string_view remedy) {
  reserve_memory(bytes, what, remedy).release();
}

}  // namespace mneedle
