#include "mpi_run.hpp"

#include <dlfcn.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace oocsimp_cli {

bool launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(name)) return true;
  return false;
}

namespace {

using RunJob = int (*)(const MpiJob*);

// The MPI module (mpi_ranks.cpp): beside this program (the build folder), else where
// it is installed. Loaded with its symbols global: Open MPI's own plugins, loaded by
// MPI_Init, look up libmpi's.
RunJob load_mpi_module() {
#ifdef OOCSIMP_MPI_MODULE
  std::string self(4096, '\0');
  const ssize_t n = ::readlink("/proc/self/exe", self.data(), self.size() - 1);
  self.resize(n > 0 ? std::size_t(n) : 0);
  const std::string beside = self.substr(0, self.rfind('/') + 1) + OOCSIMP_MPI_MODULE;
  for (const std::string& path : {beside, std::string(OOCSIMP_MPI_MODULE_INSTALLED)}) {
    if (void* module = ::dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL))
      return reinterpret_cast<RunJob>(::dlsym(module, "oocsimp_mpi_run_job"));
  }
  std::fprintf(stderr,
               "oocsimp: warning: started by an MPI launcher, but %s cannot be loaded (%s): this rank runs "
               "the whole job alone\n",
               OOCSIMP_MPI_MODULE, ::dlerror());
#else
  std::fprintf(stderr,
               "oocsimp: warning: started by an MPI launcher, but built without MPI (libopenmpi-dev): this rank "
               "runs the whole job alone\n");
#endif
  return nullptr;
}

}  // namespace

int run_mpi_job(const MpiJob& job) {
  if (!launched_by_mpi()) return -1;
  const RunJob run = load_mpi_module();
  if (!run) return -1;
  MpiJob resolved = job;
  if (resolved.temp_dir.empty()) resolved.temp_dir = oocsimp::default_temp_dir();
  return run(&resolved);
}

}  // namespace oocsimp_cli
