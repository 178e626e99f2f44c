#include "mneedle/base/memory.h"

#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include "mneedle/base/error.h"

namespace mneedle {

namespace {

// OpenBLAS's work buffer (BUFFER_SIZE of Debian's build, seen in its mmap calls).
constexpr std::size_t kBlasBufferBytes = std::size_t{128} << 20;
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

// The threads OpenBLAS runs, as it counts them: OPENBLAS_NUM_THREADS, GOTO_NUM_THREADS or
// OMP_NUM_THREADS when set, else the CPUs this process may use.
std::size_t blas_threads() {
  for (const char* name : {"OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"})
    if (const char* value = std::getenv(name); value != nullptr)
      if (const auto count = parse_count(value); count && *count > 0) return *count;
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  if (sched_getaffinity(0, sizeof(cpus), &cpus) == 0 && CPU_COUNT(&cpus) > 0)
    return static_cast<std::size_t>(CPU_COUNT(&cpus));
  return std::max(1u, std::thread::hardware_concurrency());
}

std::string read_text(const char* path) {
  std::ifstream in(path);
  if (!in) return {};
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// This process's cgroup folders for the memory controller, from its own group up to the
// hierarchy's root: cgroup v2 ("0::/path" in /proc/self/cgroup, under /sys/fs/cgroup) or v1
// ("N:...memory...:/path", under /sys/fs/cgroup/memory). A limit on any of them caps the process.
std::vector<std::string> own_cgroups(bool v2) {
  std::istringstream lines(read_text("/proc/self/cgroup"));
  std::string path;
  for (std::string line; std::getline(lines, line);) {
    const auto first = line.find(':'), second = line.find(':', first + 1);
    if (first == std::string::npos || second == std::string::npos) continue;
    const std::string controllers = line.substr(first + 1, second - first - 1);
    bool memory = false;
    for (std::size_t at = 0; at <= controllers.size();) {
      const auto end = std::min(controllers.find(',', at), controllers.size());
      memory = memory || controllers.substr(at, end - at) == "memory";
      at = end + 1;
    }
    if (v2 ? line.rfind("0::", 0) == 0 : memory) path = line.substr(second + 1);
  }
  if (path.empty() || path.front() != '/') return {};
  const std::string mount = v2 ? "/sys/fs/cgroup" : "/sys/fs/cgroup/memory";
  std::vector<std::string> chain;
  for (;;) {
    chain.push_back(mount + (path == "/" ? "" : path));
    if (path == "/") break;
    path = path.substr(0, std::max<std::size_t>(path.rfind('/'), 1));
  }
  return chain;
}

// The value of `key` at a line's start in a memory.stat text, nullopt when absent.
std::optional<std::size_t> stat_value(std::string_view stat, std::string_view key) {
  for (std::size_t at = stat.find(key); at != std::string_view::npos; at = stat.find(key, at + 1)) {
    if (at != 0 && stat[at - 1] != '\n') continue;
    std::string_view value = stat.substr(at + key.size());
    if (value.empty() || value.front() != ' ') continue;  // a longer key
    return parse_count(value.substr(1, value.find('\n') - 1));
  }
  return std::nullopt;
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
  const std::size_t cache =
      stat_value(stat, "active_file").value_or(0) + stat_value(stat, "inactive_file").value_or(0);
  const std::size_t held = *used > cache ? *used - cache : 0;
  return *limit > held ? *limit - held : 0;
}

std::optional<std::size_t> cgroup_v1_room_bytes(std::string_view limit_in_bytes,
                                                std::string_view usage_in_bytes,
                                                std::string_view stat) {
  const auto limit = parse_count(limit_in_bytes);
  const auto used = parse_count(usage_in_bytes);
  // No limit reads as the page counter's maximum (9223372036854771712 on 4 KiB pages).
  if (!limit || !used || *limit >= (std::size_t{1} << 62)) return std::nullopt;
  // The hierarchy's page cache (total_*) where the kernel gives it, else the group's own.
  const auto total_active = stat_value(stat, "total_active_file");
  const auto total_inactive = stat_value(stat, "total_inactive_file");
  const std::size_t cache = total_active || total_inactive
                                ? total_active.value_or(0) + total_inactive.value_or(0)
                                : stat_value(stat, "active_file").value_or(0) +
                                      stat_value(stat, "inactive_file").value_or(0);
  const std::size_t held = *used > cache ? *used - cache : 0;
  return *limit > held ? *limit - held : 0;
}

std::optional<std::size_t> available_memory_bytes() {
  std::optional<std::size_t> room = meminfo_available_bytes(read_text("/proc/meminfo"));
  auto take = [&room](std::optional<std::size_t> other) {
    if (other) room = room ? std::min(*room, *other) : *other;
  };
  for (const std::string& group : own_cgroups(true))
    take(cgroup_room_bytes(read_text((group + "/memory.max").c_str()),
                           read_text((group + "/memory.current").c_str()),
                           read_text((group + "/memory.stat").c_str())));
  for (const std::string& group : own_cgroups(false))
    take(cgroup_v1_room_bytes(read_text((group + "/memory.limit_in_bytes").c_str()),
                              read_text((group + "/memory.usage_in_bytes").c_str()),
                              read_text((group + "/memory.stat").c_str())));
  // An address-space limit (ulimit -v, as batch systems set): mappings count, resident or not.
  // OpenBLAS maps a work buffer per thread on first use and, when the limit refuses it, retries
  // for ever (Debian's 0.3.21), so room for one per thread and one more is kept back; buffers
  // already mapped are then counted twice, which errs on refusing.
  if (rlimit space{}; getrlimit(RLIMIT_AS, &space) == 0 && space.rlim_cur != RLIM_INFINITY) {
    const auto limit = static_cast<std::size_t>(space.rlim_cur);
    const std::size_t held = statm_bytes(0) + kBlasBufferBytes * (blas_threads() + 1);
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
int g_reserve_waiters = 0;

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

int reserve_memory_waiters() {
  const std::lock_guard<std::mutex> lock(g_reserved_mutex);
  return g_reserve_waiters;
}

MemoryReservation reserve_memory(double bytes, std::string_view what, std::string_view remedy) {
  if (!(bytes > 0.0)) return {};
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
    // when the block fits beside what is allocated now, and never while this thread holds one
    // (two threads holding and waiting would wait for ever).
    const auto mine = g_reserved_by_thread.find(std::this_thread::get_id());
    const bool own = mine != g_reserved_by_thread.end();
    if (bytes > left || own || g_reserved <= 0.0)
      throw OutOfMemoryError(std::string(what) + " needs " + memory_size_text(bytes) +
                             ", more than the " + memory_size_text(std::max(left, 0.0)) +
                             " of memory left to this process; " + std::string(remedy));
    ++g_reserve_waiters;
    g_reserved_released.wait(lock);
    --g_reserve_waiters;
  }
}

void require_memory(double bytes, std::string_view what, std::string_view remedy) {
  reserve_memory(bytes, what, remedy).release();
}

}  // namespace mneedle
