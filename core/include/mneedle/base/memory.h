#pragma once
// The process's memory use and the memory left to it, as the operating system counts them: for
// run reports, and for refusing a factorisation that cannot fit (docs/performance.md, "Memory").

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <thread>

namespace mneedle {

/// Peak resident set of this process so far (bytes): getrusage's ru_maxrss. It covers the whole
/// process, so a report of one run is exact only when the process did nothing bigger before.
std::size_t peak_memory_bytes();

/// The resident set now (bytes): /proc/self/statm; 0 where it cannot be read.
std::size_t resident_memory_bytes();

/// Memory this process may still take (bytes): the smallest of the kernel's MemAvailable
/// (/proc/meminfo), the room left under the memory limits of its cgroup and every ancestor
/// (cgroup v2 memory.max, v1 memory.limit_in_bytes), the room left in
/// its address-space limit (RLIMIT_AS, `ulimit -v`; less OpenBLAS's work buffers, 128 MiB per
/// OpenBLAS thread and one more) and the limit set with
/// set_memory_limit_bytes, of those that are known; nullopt when none is.
std::optional<std::size_t> available_memory_bytes();

/// A limit of this process's own below what the machine has (tests; a user's budget); nullopt
/// removes it. Process-wide.
void set_memory_limit_bytes(std::optional<std::size_t> bytes);

/// A size as refusals print it: whole MiB below a GiB, GiB to two decimals from there.
std::string memory_size_text(double bytes);

/// Memory promised to a block about to be allocated (reserve_memory), counted as taken until
/// released or destroyed: threads of one process that check at once (`screen --jobs N`) do not
/// all count the same room. Move-only.
class MemoryReservation {
 public:
  MemoryReservation() = default;
  ~MemoryReservation();
  MemoryReservation(MemoryReservation&& other) noexcept;
  MemoryReservation& operator=(MemoryReservation&& other) noexcept;
  MemoryReservation(const MemoryReservation&) = delete;
  MemoryReservation& operator=(const MemoryReservation&) = delete;
  /// Once the block is allocated: the kernel's counts hold it from then on.
  void release();

 private:
  friend MemoryReservation reserve_memory(double, std::string_view, std::string_view);
  MemoryReservation(double bytes, std::thread::id owner);
  double bytes_ = 0.0;
  std::thread::id owner_;
};

/// require_memory that keeps the room it found: the block counts against the memory left for
/// every other check until the reservation is released. A block that fits beside what is
/// allocated but not beside other threads' reservations waits for them (their blocks are then
/// allocated and counted); one that does not fit even so, or asked for by a thread that holds a
/// reservation itself, is refused. Nothing is held where the room is unknown.
MemoryReservation reserve_memory(double bytes, std::string_view what, std::string_view remedy);

/// Threads waiting in reserve_memory now (tests).
int reserve_memory_waiters();

/// Refuses, before it is allocated, what cannot fit: throws OutOfMemoryError "<what> needs <size>,
/// more than the <size> of memory left to this process; <remedy>" when `bytes` exceed
/// available_memory_bytes() less other threads' reservations (waiting for those as
/// reserve_memory does). Nothing when the room is unknown.
void require_memory(double bytes, std::string_view what, std::string_view remedy);

/// "<number> <unit>" in bytes, the unit one of B, kB, MB, GB, TB (powers of 1000) or KiB, MiB,
/// GiB, TiB (powers of 1024), at least one byte. Throws InputError naming the text for anything
/// else (a number without a unit among them).
std::size_t parse_memory_size(std::string_view text);

/// MemAvailable of a /proc/meminfo text, in bytes; nullopt when absent or malformed.
std::optional<std::size_t> meminfo_available_bytes(std::string_view meminfo);

/// Room under a cgroup v2 limit: memory.max's text ("max" = no limit) less memory.current's,
/// the page cache (memory.stat's active_file and inactive_file, which the kernel reclaims) not
/// counted as held; nullopt when there is no limit or max or current is malformed. 0 when the
/// group is at its limit.
std::optional<std::size_t> cgroup_room_bytes(std::string_view max, std::string_view current,
                                             std::string_view stat);

/// The same under a cgroup v1 memory controller: memory.limit_in_bytes less
/// memory.usage_in_bytes, the page cache (memory.stat's total_active_file and
/// total_inactive_file, else active_file and inactive_file) not counted; nullopt when unlimited
/// (2^62 bytes and more) or malformed.
std::optional<std::size_t> cgroup_v1_room_bytes(std::string_view limit_in_bytes,
                                                std::string_view usage_in_bytes,
                                                std::string_view stat);

}  // namespace mneedle
