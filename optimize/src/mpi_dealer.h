#pragma once
// Tasks dealt over the ranks of an MPI job one at a time, to whichever thread of any rank asks
// next, so that a long task holds up only its own thread (docs/performance.md, "Screening on a
// cluster"): screen --mpi deals designs, uncertainty --mpi deals samples. Only a task's index
// and its result as text travel; every rank must hold the same tasks (the callers check).

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "mneedle/screening_mpi.h"

namespace mneedle {

struct DealtTasks {
  std::size_t count = 0;  // tasks 0 … count − 1
  /// Rank 0, thread-safe: the next task to deal, or nothing when every task is dealt.
  std::function<std::optional<std::size_t>()> claim;
  /// Rank 0's own threads: run the task and record its result. Must not throw.
  std::function<void(std::size_t)> run_here;
  /// The other ranks' threads: run the task, its result as text for rank 0. Must not throw.
  std::function<std::string(std::size_t)> run_for_rank0;
  /// Rank 0: record the text another rank sent for a task (index < count). Must not throw.
  std::function<void(std::size_t, const std::string&)> record_text;
};

/// Rank 0 deals and records, with `jobs` evaluating threads of its own besides the one that talks
/// MPI; every other rank runs `jobs` threads that ask, run and send. Returns on rank 0 when every
/// dealt task's result is back, on the others when nothing is left to deal. An error in rank 0's
/// own loop ends the job (MPI_Abort), since the other ranks would wait for ever; `command` names
/// it in that message.
void deal_over_ranks(const MpiSession& session, int jobs, const DealtTasks& tasks,
                     const char* command);

}  // namespace mneedle
