#pragma once
// Starting a command's MPI session (screen --mpi, uncertainty --mpi; docs/performance.md,
// "Screening on a cluster"): a command started by mpirun without --mpi refuses (each copy would
// run every task), and only rank 0 says why a session cannot start.

#include <functional>
#include <optional>
#include <string>

#include "mneedle/screening_mpi.h"

namespace mneedle::cli {

/// With `requested`, emplaces the session (jobs threads per rank); without it, checks that no
/// MPI launcher started several copies (`each_would` says what each copy would do). Ranks > 0
/// throw QuietExit{0} where rank 0 reports.
void start_mpi(std::optional<MpiSession>& session, bool requested, int jobs,
               const std::string& command, const std::string& each_would);

/// Runs `setup` on this rank. Under MPI a rank whose setup fails must not leave the others
/// waiting: every rank says whether it got through; rank 0 reports its own error, another rank
/// only an error rank 0 does not share (the others exit quietly), and rank 0 says when another
/// rank could not start.
void setup_on_every_rank(const std::optional<MpiSession>& session,
                         const std::function<void()>& setup, const std::string& command);

}  // namespace mneedle::cli
