#include "mneedle/screening_mpi.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "mneedle/base/error.h"
#include "mneedle/base/provenance.h"
#include "mneedle/blas_threads.h"
#include "mpi_dealer.h"
#include "screening_batch.h"

#if MNEEDLE_HAVE_MPI
#include <mpi.h>
#endif

namespace mneedle {

namespace {

// The first of `names` set to a whole number in [minimum, 2^24).
std::optional<int> launcher_number(std::initializer_list<const char*> names, long minimum) {
  for (const char* name : names) {
    const char* value = std::getenv(name);
    if (value == nullptr) continue;
    char* end = nullptr;
    const long n = std::strtol(value, &end, 10);
    if (end != value && *end == '\0' && n >= minimum && n < 1 << 24) return static_cast<int>(n);
  }
  return std::nullopt;
}

}  // namespace

// Open MPI's mpirun, then MPICH's hydra; both set these in every process they start.
std::optional<int> mpi_launch_size() {
  return launcher_number({"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}, 1);
}

int mpi_launch_rank() {
  return launcher_number({"OMPI_COMM_WORLD_RANK", "PMI_RANK"}, 0).value_or(0);
}

#if MNEEDLE_HAVE_MPI

namespace {

// The messages (docs/performance.md, "Screening on a cluster"): a thread of rank r > 0 sends
// kRequest and waits for kIndex (a task's index, or -1: no more tasks); when it has run the task
// it sends kResult, "index\n" followed by the result's text.
constexpr int kRequest = 1;
constexpr int kIndex = 2;
constexpr int kResult = 3;

// Rank 0: deals tasks to its own threads and to every other rank's threads, and records every
// result. Its main thread only talks MPI (polling, so that a result is recorded the moment it
// arrives); `jobs` threads run tasks.
void coordinate_loop(const MpiSession& session, int jobs, const DealtTasks& tasks,
                     const char* command) {
  std::vector<std::thread> pool;
  for (int j = 0; j < jobs; ++j)
    pool.emplace_back([&] {
      while (const auto i = tasks.claim()) {
        try {
          tasks.run_here(*i);
        } catch (...) {
          // Must not happen (run_here catches its own); the caller finds the task without a
          // result and says so, rather than the exception ending the process.
        }
      }
    });
  // Every thread of every other rank asks until it is told -1; a result is owed for every index
  // dealt. Both must be settled before rank 0 may stop listening.
  const long remote_threads = static_cast<long>(session.size() - 1) * jobs;
  try {
    long stopped = 0;
    long owed = 0;
    while (stopped < remote_threads || owed > 0) {
      int arrived = 0;
      MPI_Status status;
      MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &arrived, &status);
      if (!arrived) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      if (status.MPI_TAG == kRequest) {
        int nothing = 0;
        MPI_Recv(&nothing, 1, MPI_INT, status.MPI_SOURCE, kRequest, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        const auto i = tasks.claim();
        long long index = i ? static_cast<long long>(*i) : -1;
        (i ? owed : stopped) += 1;
        MPI_Send(&index, 1, MPI_LONG_LONG, status.MPI_SOURCE, kIndex, MPI_COMM_WORLD);
      } else if (status.MPI_TAG == kResult) {
        int bytes = 0;
        MPI_Get_count(&status, MPI_CHAR, &bytes);
        std::string message(static_cast<std::size_t>(bytes), '\0');
        MPI_Recv(message.data(), bytes, MPI_CHAR, status.MPI_SOURCE, kResult, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        --owed;
        // Our own ranks wrote it; a message that names no task would be a bug in this file, and
        // is dropped rather than recorded anywhere (the caller finds the task without a result).
        const auto newline = message.find('\n');
        std::size_t i = tasks.count;
        try {
          i = std::stoul(message.substr(0, newline));
        } catch (const std::exception&) {
        }
        if (newline == std::string::npos || i >= tasks.count) continue;
        tasks.record_text(i, message.substr(newline + 1));
      }
    }
  } catch (const std::exception& e) {
    // Out of memory or the like in the loop itself: the other ranks wait on rank 0 and would
    // wait for ever, so the job ends here, before the threads are left unjoined (results
    // already written stay written).
    std::fprintf(stderr, "mneedle: internal error: %s --mpi, rank 0: %s\n", command, e.what());
    std::fflush(stderr);
    MPI_Abort(MPI_COMM_WORLD, 4);
  }
  for (auto& t : pool) t.join();
}

// Rank r > 0: `jobs` threads, each asking rank 0 for a task, running it and sending the result
// back. MPI calls are serialised by one mutex (MPI_THREAD_SERIALIZED); a thread holds it from
// its request to the answer, so every answer reaches the thread that asked.
void work(int jobs, const DealtTasks& tasks) {
  std::mutex mpi;
  auto worker = [&] {
    for (;;) {
      long long index = -1;
      {
        std::lock_guard<std::mutex> lock(mpi);
        int nothing = 0;
        MPI_Send(&nothing, 1, MPI_INT, 0, kRequest, MPI_COMM_WORLD);
        MPI_Recv(&index, 1, MPI_LONG_LONG, 0, kIndex, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      }
      if (index < 0) return;
      // The ranks agreed on the tasks, so rank 0 deals only indices below count; one beyond it
      // would be a bug, answered with no text (rank 0 drops it) rather than a read past the end.
      const auto i = static_cast<std::size_t>(index);
      std::string text;
      try {
        if (i < tasks.count) text = tasks.run_for_rank0(i);
      } catch (...) {
        // Must not happen (run_for_rank0 catches its own); should it, the task still gets its
        // answer: empty text, which rank 0 records as an unreadable result.
      }
      const std::string message = std::to_string(index) + "\n" + text;
      std::lock_guard<std::mutex> lock(mpi);
      MPI_Send(message.data(), static_cast<int>(message.size()), MPI_CHAR, 0, kResult,
               MPI_COMM_WORLD);
    }
  };
  std::vector<std::thread> pool;
  for (int j = 1; j < jobs; ++j) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

}  // namespace

bool mpi_built_in() {
  return true;
}

MpiSession::MpiSession(int jobs) {
  int provided = MPI_THREAD_SINGLE;
  const int needed = jobs > 1 ? MPI_THREAD_SERIALIZED : MPI_THREAD_FUNNELED;
  MPI_Init_thread(nullptr, nullptr, needed, &provided);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (provided < needed) {
    MPI_Finalize();
    throw InputError(std::string("--mpi: this MPI library does not support ") +
                     (jobs > 1 ? "MPI_THREAD_SERIALIZED (threads that call MPI in turn), which "
                                 "--jobs > 1 needs; use --jobs 1"
                               : "MPI_THREAD_FUNNELED (one thread calling MPI while others "
                                 "evaluate)"));
  }
}

MpiSession::~MpiSession() {
  MPI_Finalize();
}

MpiSession::Agreement MpiSession::agree(bool ok) const {
  int mine[2] = {ok ? 1 : 0, ok || rank_ != 0 ? 1 : 0};
  int all[2] = {0, 0};
  MPI_Allreduce(mine, all, 2, MPI_INT, MPI_LAND, MPI_COMM_WORLD);
  return {all[0] == 1, all[1] == 1};
}

void deal_over_ranks(const MpiSession& session, int jobs, const DealtTasks& tasks,
                     const char* command) {
  jobs = std::max(1, jobs);
  if (session.rank() != 0) {
    work(jobs, tasks);
    return;
  }
  coordinate_loop(session, jobs, tasks, command);
}

bool MpiSession::matches_rank0(const std::string& definition) const {
  std::string mine = sha256_hex(definition);  // 64 hex digits
  mine.resize(64, ' ');
  std::string rank0 = mine;
  MPI_Bcast(rank0.data(), 64, MPI_CHAR, 0, MPI_COMM_WORLD);
  return mine == rank0;
}

std::vector<ScreeningRow> screen_designs_mpi(
    const MpiSession& session, const std::vector<DesignInput>& designs, const Scene& scene,
    const std::filesystem::path& scene_file, const PluginRegistry& registry,
    const ScreeningOptions& options, const std::function<void(const ScreeningRow&)>& on_row) {
  const int jobs = std::max(1, options.jobs);
  // Several ranks on one machine, or several threads in one rank: one OpenBLAS thread each, as
  // in the serial screen with --jobs > 1 (the same factorisations, so the same rows).
  std::optional<BlasThreadLimit> blas;
  if (jobs > 1 || session.size() > 1) blas.emplace(1);
  const bool coordinator = session.rank() == 0;
  // A rank whose batch cannot start (an unwritable --out), or that sees other designs than rank 0
  // (another folder listing, a file changed in between), must not leave the others waiting.
  std::optional<ScreeningBatch> batch;
  std::string failure;
  std::string fingerprint;
  try {
    batch.emplace(designs, scene, scene_file, registry, options, on_row, coordinator);
    fingerprint = batch->fingerprint();
  } catch (const std::exception& e) {
    failure = e.what();
  }
  // Collective: every rank takes part, whether its batch started or not.
  // --jobs too: rank 0 counts every other rank's threads as its own number.
  if (!session.matches_rank0(fingerprint + "|jobs=" + std::to_string(jobs)) && failure.empty())
    failure = "screen --mpi: rank " + std::to_string(session.rank()) +
              " sees other designs, another scene or another --jobs than rank 0 (every rank must "
              "read the same files)";
  const auto agreement = session.agree(failure.empty());
  if (!agreement.all) {
    if (!failure.empty() && (coordinator || agreement.rank0)) throw InputError(failure);
    if (coordinator)
      throw InputError("screen --mpi: another rank could not start (its line says why)");
    throw RankStopped();
  }
  DealtTasks tasks;
  tasks.count = batch->size();
  tasks.claim = [&] { return batch->claim(); };
  tasks.run_here = [&](std::size_t i) { batch->record(i, batch->evaluate(i)); };
  tasks.run_for_rank0 = [&](std::size_t i) { return batch->evaluate(i).json; };
  tasks.record_text = [&](std::size_t i, const std::string& text) {
    try {
      batch->record(i, screening_row_from_json(text));
    } catch (const std::exception& e) {
      batch->record(
          i, screening_error_row(batch->design(i), std::string("the row sent by another rank is "
                                                               "unreadable (") +
                                                       e.what() + ")"));
    }
  };
  deal_over_ranks(session, jobs, tasks, "screen");
  if (!coordinator) return {};
  // Every design dealt had its row back; should one ever not, it gets an error row rather than
  // an empty one.
  for (std::size_t i = 0; i < batch->size(); ++i)
    if (!batch->recorded(i))
      batch->record(i, screening_error_row(batch->design(i), "no row came back for this design"));
  return batch->take_rows();
}

#else  // built without MPI

bool mpi_built_in() {
  return false;
}

MpiSession::MpiSession(int) {
  throw InputError(
      "--mpi: this mneedle was built without MPI (configure with -DMNEEDLE_MPI=ON and "
      "libopenmpi-dev installed; docs/performance.md, \"Screening on a cluster\")");
}

MpiSession::~MpiSession() = default;

void deal_over_ranks(const MpiSession&, int, const DealtTasks&, const char*) {
  throw InputError("--mpi: this mneedle was built without MPI");
}

MpiSession::Agreement MpiSession::agree(bool ok) const {
  return {ok, ok};
}

bool MpiSession::matches_rank0(const std::string&) const {
  return true;
}

std::vector<ScreeningRow> screen_designs_mpi(const MpiSession&, const std::vector<DesignInput>&,
                                             const Scene&, const std::filesystem::path&,
                                             const PluginRegistry&, const ScreeningOptions&,
                                             const std::function<void(const ScreeningRow&)>&) {
  throw InputError("--mpi: this mneedle was built without MPI");
}

#endif

}  // namespace mneedle
