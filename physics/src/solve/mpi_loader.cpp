// Loads the MPI backends' module (mpi_module.hpp) on first use.

#include "mpi_module.hpp"

#include <dlfcn.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "sewn/physics/errors.hpp"

namespace sewn::physics::solve::detail {

namespace {

const MpiBackends& load() {
  std::vector<std::string> paths;
  if (const char* chosen = std::getenv("SEWN_MPI_SOLVERS")) paths.emplace_back(chosen);
  else paths = {SEWN_MPI_MODULE_BUILT, SEWN_MPI_MODULE_INSTALLED};
  std::string tried;
  for (const std::string& path : paths) {
    // RTLD_GLOBAL: OpenMPI's own plugins look up libmpi's symbols in the global scope.
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
    if (handle == nullptr) {
      const char* why = dlerror();
      tried += "\n  " + path + ": " + (why ? why : "not loaded");
      continue;
    }
    using Entry = const MpiBackends* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, mpi_backends_entry));
    if (entry == nullptr) {
      tried += "\n  " + path + ": no entry point " + mpi_backends_entry;
      continue;
    }
    return *entry();  // the module stays loaded: its solvers may live until exit
  }
  throw SolverError("the hypre and PETSc backends' module could not be loaded (set SEWN_MPI_SOLVERS to its path):" + tried, 0, 0);
}

}  // namespace

const MpiBackends& mpi_backends() {
  static const MpiBackends& backends = load();
  return backends;
}

}  // namespace sewn::physics::solve::detail
