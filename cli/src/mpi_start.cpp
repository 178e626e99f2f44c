#include "mpi_start.h"

#include "commands.h"
#include "mneedle/base/error.h"

namespace mneedle::cli {

void start_mpi(std::optional<MpiSession>& session, bool requested, int jobs,
               const std::string& command, const std::string& each_would) {
  if (const auto n = mpi_launch_size(); n && *n > 1 && !requested) {
    if (mpi_launch_rank() != 0) throw QuietExit{0};  // rank 0 says why, once
    throw InputError(command + ": started by an MPI launcher as " + std::to_string(*n) +
                     " processes without --mpi: each would " + each_would + "; add --mpi");
  }
  if (!requested) return;
  // A rank > 0 exits quietly and with status 0 whenever rank 0 reports the reason: the job's one
  // error line and its status are rank 0's (Open MPI ends a job at the first non-zero exit,
  // which could cut rank 0 off before it has said why).
  try {
    session.emplace(jobs);
  } catch (const InputError&) {
    if (mpi_launch_rank() != 0) throw QuietExit{0};  // every rank fails alike here
    throw;
  }
}

void setup_on_every_rank(const std::optional<MpiSession>& session,
                         const std::function<void()>& setup, const std::string& command) {
  const bool writer = !session || session->rank() == 0;
  try {
    setup();
  } catch (const std::exception&) {
    if (!session) throw;
    const auto agreement = session->agree(false);
    if (writer || agreement.rank0) throw;
    throw QuietExit{0};  // rank 0 failed too and says so, once
  }
  if (session && !session->agree(true).all) {
    if (writer)
      throw InputError(command + " --mpi: another rank could not start (its line says why)");
    throw QuietExit{0};
  }
}

}  // namespace mneedle::cli
