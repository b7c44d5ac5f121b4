// simplify under mpirun or srun (docs/cluster.md): rank R of K runs part R/K of the
// run, and rank 0 merges the parts once every rank has succeeded. The MPI side is a
// module (mpi_ranks.cpp, built when CMake finds Open MPI) loaded only under a
// launcher; without it, a program launched by mpirun is K independent copies, and
// says so.
#pragma once

#include <functional>
#include <string>

#include "oocsimp/oocsimp.hpp"

namespace oocsimp_cli {

/// Whether this process was started by an MPI launcher (its environment says so).
bool launched_by_mpi();

/// What a distributed simplify does on each rank: run part `part` (index and count
/// set by the rank) and, on rank 0 after every part succeeded, the merge; each
/// returns an exit status. `work_dir` is the folder the ranks share.
struct MpiJob {
  std::string work_dir;  ///< empty: a new folder under `temp_dir`, removed afterwards
  std::string temp_dir;  ///< where that folder goes (default_temp_dir() when empty)
  std::function<int(const oocsimp::PartOptions& part)> run_part;
  std::function<int(const std::string& work_dir)> merge;
  /// For a run that cannot be spread (run_part null): rank 0 runs it whole.
  std::function<int()> whole;
};

/// Runs `job` on every rank of MPI_COMM_WORLD and returns the job's exit status,
/// the same on every rank: the first failing rank's status (after rank 0 names each
/// failed rank on stderr), else the merge's. Returns -1 without MPI or with one rank:
/// the caller then runs as one process.
int run_mpi_job(const MpiJob& job);

}  // namespace oocsimp_cli
