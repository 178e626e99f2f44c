#include "mneedle/base/memory.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "mneedle/base/error.h"

namespace {

using mneedle::available_memory_bytes;
using mneedle::cgroup_room_bytes;
using mneedle::meminfo_available_bytes;
using mneedle::memory_size_text;
using mneedle::parse_memory_size;
using mneedle::require_memory;
using mneedle::set_memory_limit_bytes;

TEST(Memory, MeminfoAvailableIsReadInKibibytes) {
  const auto bytes = meminfo_available_bytes(
      "MemTotal:       23839628 kB\nMemFree:  100 kB\nMemAvailable:    2048 kB\nBuffers: 1 kB\n");
  ASSERT_TRUE(bytes.has_value());
  EXPECT_EQ(*bytes, 2048u * 1024u);
}

TEST(Memory, MeminfoWithoutAvailableOrItsUnitIsUnknown) {
  EXPECT_FALSE(meminfo_available_bytes("MemTotal: 100 kB\n").has_value());
  EXPECT_FALSE(meminfo_available_bytes("MemAvailable: 100\n").has_value());
  EXPECT_FALSE(meminfo_available_bytes("MemAvailable: lots kB\n").has_value());
  EXPECT_FALSE(meminfo_available_bytes("").has_value());
}

TEST(Memory, CgroupRoomIsItsLimitLessWhatItHoldsBesideItsPageCache) {
  EXPECT_EQ(cgroup_room_bytes("1000\n", "400\n", ""), std::optional<std::size_t>(600));
  EXPECT_EQ(cgroup_room_bytes("100\n", "400\n", ""), std::optional<std::size_t>(0));
  // A group that compiled the project: 900 of its 1000 are file cache the kernel drops.
  const std::string stat = "anon 50\nfile 850\nactive_file 300\ninactive_file 550\nshmem 0\n";
  EXPECT_EQ(cgroup_room_bytes("1000\n", "900\n", stat), std::optional<std::size_t>(950));
  EXPECT_FALSE(cgroup_room_bytes("max\n", "400\n", stat).has_value());  // no limit
  EXPECT_FALSE(cgroup_room_bytes("", "", "").has_value());              // not on cgroup v2
}

// cgroup v1's memory controller (hybrid hosts such as this project's CI VMs): the same room,
// read from limit_in_bytes and usage_in_bytes, the hierarchy's page cache not held.
TEST(Memory, CgroupV1RoomIsItsLimitLessWhatItHoldsBesideItsPageCache) {
  using mneedle::cgroup_v1_room_bytes;
  EXPECT_EQ(cgroup_v1_room_bytes("1000\n", "400\n", ""), std::optional<std::size_t>(600));
  EXPECT_EQ(cgroup_v1_room_bytes("100\n", "400\n", ""), std::optional<std::size_t>(0));
  const std::string stat =
      "cache 850\nrss 50\nactive_file 10\ninactive_file 20\n"
      "total_active_file 300\ntotal_inactive_file 550\n";
  EXPECT_EQ(cgroup_v1_room_bytes("1000\n", "900\n", stat), std::optional<std::size_t>(950));
  const std::string own = "cache 850\nactive_file 300\ninactive_file 550\n";  // no total_*
  EXPECT_EQ(cgroup_v1_room_bytes("1000\n", "900\n", own), std::optional<std::size_t>(950));
  EXPECT_FALSE(cgroup_v1_room_bytes("9223372036854771712\n", "400\n", stat).has_value());
  EXPECT_FALSE(cgroup_v1_room_bytes("", "", "").has_value());  // no v1 memory controller
}

TEST(Memory, SizesNeedOneOfTheByteUnits) {
  EXPECT_EQ(parse_memory_size("4 GiB"), 4ull * 1024 * 1024 * 1024);
  EXPECT_EQ(parse_memory_size("1.5 GB"), 1500000000ull);
  EXPECT_EQ(parse_memory_size("512MiB"), 512ull * 1024 * 1024);
  EXPECT_EQ(parse_memory_size("  100 B "), 100ull);
  EXPECT_EQ(parse_memory_size("\t2 KiB\t"), 2048ull);
  for (const char* bad :
       {"4", "4 gb", "4 GiBs", "GiB", "-1 GiB", "0 MB", "nan MB", "1e30 TB", "0.5 B"})
    EXPECT_THROW(parse_memory_size(bad), mneedle::InputError) << bad;
  try {
    parse_memory_size("300");
  } catch (const mneedle::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'300': no unit"), std::string::npos) << e.what();
  }
}

TEST(Memory, AProcessLimitCapsTheMemoryLeft) {
  const auto machine = available_memory_bytes();
  ASSERT_TRUE(machine.has_value());  // Linux: /proc/meminfo is always there
  EXPECT_GT(*machine, 0u);
  // A budget below what the process already holds leaves nothing; without it the machine's
  // memory is back.
  set_memory_limit_bytes(1);
  const auto capped = available_memory_bytes();
  set_memory_limit_bytes(std::nullopt);
  EXPECT_EQ(capped, std::optional<std::size_t>(0));
  ASSERT_TRUE(available_memory_bytes().has_value());
  EXPECT_GT(*available_memory_bytes(), 0u);
}

TEST(Memory, PeakMemoryIsTheProcessResidentPeak) {
  EXPECT_GT(mneedle::peak_memory_bytes(), 1u << 20);  // a test binary holds more than 1 MiB
  // Now, not the peak: the kernel updates the two counts at different times, so neither bounds
  // the other to the page.
  EXPECT_GT(mneedle::resident_memory_bytes(), 1u << 20);
}

TEST(Memory, SizesPrintInWholeMebibytesBelowAGibibyteAndInGibibytesAbove) {
  EXPECT_EQ(memory_size_text(0.0), "0 MiB");
  EXPECT_EQ(memory_size_text(69.4 * 1024 * 1024), "69 MiB");
  EXPECT_EQ(memory_size_text(31.384 * 1024 * 1024 * 1024), "31.38 GiB");
}

// What does not fit in the memory left is refused with what it needs, what there is and what
// to do; what fits, or anything where the room is unknown, passes.
TEST(Memory, RequireMemoryRefusesWhatExceedsTheMemoryLeftInOneLine) {
  EXPECT_NO_THROW(require_memory(1024.0, "a test block", "nothing to do"));
  set_memory_limit_bytes(1);
  try {
    require_memory(2.0 * 1024 * 1024, "a test block", "ask for less");
    set_memory_limit_bytes(std::nullopt);
    FAIL() << "expected an OutOfMemoryError";
  } catch (const mneedle::OutOfMemoryError& e) {
    set_memory_limit_bytes(std::nullopt);
    EXPECT_STREQ(e.what(),
                 "a test block needs 2 MiB, more than the 0 MiB of memory left to this process; "
                 "ask for less");
  }
}

// Threads checking at once (`screen --jobs N`) see each other's reservations: a block that
// fits beside what is allocated but not beside another thread's reservation waits for its
// release; a block asked for by a thread that holds one itself, or one larger than the room, is
// refused at once instead (two threads holding and waiting would wait for ever).
TEST(Memory, AnotherThreadsReservationIsWaitedForAndOnesOwnIsNot) {
  constexpr double kMiB = 1024.0 * 1024.0;
  const auto machine = available_memory_bytes();
  if (!machine || *machine < (std::size_t{512} << 20)) GTEST_SKIP() << "under 512 MiB left";
  set_memory_limit_bytes(mneedle::resident_memory_bytes() + (256u << 20));
  {
    mneedle::MemoryReservation first = mneedle::reserve_memory(160 * kMiB, "first", "-");
    EXPECT_THROW(mneedle::reserve_memory(300 * kMiB, "larger", "-"), mneedle::OutOfMemoryError);
    // Fits beside what is allocated, not beside first, which is this thread's own: refused.
    EXPECT_THROW(mneedle::reserve_memory(160 * kMiB, "this thread's", "-"),
                 mneedle::OutOfMemoryError);
    std::atomic<bool> released{false}, taken{false}, refused{false};
    std::thread other([&] {
      try {
        const mneedle::MemoryReservation second =
            mneedle::reserve_memory(160 * kMiB, "second", "-");
        taken = released.load();
      } catch (const mneedle::OutOfMemoryError&) {
        refused = true;
      }
    });
    // The other thread waits: it is seen waiting before the first reservation goes.
    for (int i = 0; i < 2000 && mneedle::reserve_memory_waiters() == 0 && !refused; ++i)
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    EXPECT_EQ(mneedle::reserve_memory_waiters(), 1);
    released = true;
    first.release();
    other.join();
    EXPECT_FALSE(refused.load());
    EXPECT_TRUE(taken.load());
  }
  set_memory_limit_bytes(std::nullopt);
}

}  // namespace
