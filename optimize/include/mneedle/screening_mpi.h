#pragma once
// Screening shared by the processes of an MPI job (`mpirun -n N mneedle screen … --mpi`;
// docs/performance.md, "Screening on a cluster"). Rank 0 deals designs one at a time to whichever
// thread of any rank asks next (a long design holds up only its own thread), and is the one
// writer: every row is written by rank 0 the moment it arrives. No MPI type crosses this header.

#include <exception>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "mneedle/screening.h"

namespace mneedle {

/// True when this mneedle was built with MPI (CMake option MNEEDLE_MPI).
bool mpi_built_in();

/// The process count of an MPI launcher this process was started by (Open MPI's or MPICH's
/// environment), or nothing: a command that was not asked for --mpi can refuse to run N
/// copies of itself.
std::optional<int> mpi_launch_size();

/// This process's rank as the launcher's environment gives it (0 when there is none): before
/// MPI is initialised, only rank 0 need say why a run cannot start.
int mpi_launch_rank();

/// Thrown on a rank > 0 when the run stops for a reason rank 0 reports (rank 0 could not start,
/// or another rank could not): the rank should exit quietly and with status 0, so that the job's
/// status and its one error line are rank 0's.
class RankStopped : public std::exception {
 public:
  const char* what() const noexcept override { return "stopped: rank 0 reports why"; }
};

/// MPI for the lifetime of the object: MPI_Init_thread and MPI_Finalize. Rank 0 talks MPI from
/// one thread while others evaluate (MPI_THREAD_FUNNELED); with `jobs` > 1 the evaluating threads
/// of the other ranks talk in turn (MPI_THREAD_SERIALIZED). InputError when mneedle was built
/// without MPI or the library gives less thread support than that.
class MpiSession {
 public:
  explicit MpiSession(int jobs);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }

  /// Whether every rank, and whether rank 0, got through a step: called by every rank at the same
  /// point with its own `ok`, so that a rank whose input failed does not leave the others waiting.
  struct Agreement {
    bool all = true;
    bool rank0 = true;
  };
  Agreement agree(bool ok) const;

  /// Whether `definition` (what the ranks must share: the inputs' bytes and settings) is the
  /// same as rank 0's; called by every rank at the same point. Compares a hash, not the text.
  bool matches_rank0(const std::string& definition) const;

 private:
  int rank_ = 0;
  int size_ = 1;
};

/// screen_designs over every rank of the session: the same rows, written to the same files as the
/// serial run (rank 0 writes; --resume as on one machine). Every rank must pass the same designs
/// and scene (checked: a rank that sees other files stops the run with an InputError). Rank 0
/// returns every row in input order; the other ranks return an empty vector. `on_row` is called on
/// rank 0 only. Each rank evaluates with `options.jobs` threads (one OpenBLAS thread each when the
/// job has more than one thread in all).
std::vector<ScreeningRow> screen_designs_mpi(
    const MpiSession& session, const std::vector<DesignInput>& designs, const Scene& scene,
    const std::filesystem::path& scene_file, const PluginRegistry& registry,
    const ScreeningOptions& options, const std::function<void(const ScreeningRow&)>& on_row = {});

}  // namespace mneedle
