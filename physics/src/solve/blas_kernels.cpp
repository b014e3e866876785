#include "sewn/physics/solve/blas_kernels.hpp"

#include <cstdlib>

#include <unistd.h>

#ifdef SEWN_CHOLMOD_BLAS_OPTIMIZED
extern "C" char* openblas_get_corename(void);
#endif

namespace sewn::physics::solve {

std::string openblas_kernels() {
#ifdef SEWN_CHOLMOD_BLAS_OPTIMIZED
  const char* name = openblas_get_corename();
  return name ? std::string(name) : std::string();
#else
  return {};
#endif
}

std::string openblas_coretype_wanted() {
  if (std::getenv("OPENBLAS_CORETYPE") != nullptr) return {};
  // OpenBLAS names its generic x86-64 fallback "Prescott" (any case across releases).
  std::string chosen = openblas_kernels();
  for (char& c : chosen) c = static_cast<char>(c | 0x20);
  if (chosen != "prescott") return {};
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw") &&
      __builtin_cpu_supports("avx512vl"))
    return "SkylakeX";
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return "Haswell";
#endif
  return {};
}

void restart_with_cpu_kernels(char** argv) {
  const std::string core = openblas_coretype_wanted();
  if (core.empty() || setenv("OPENBLAS_CORETYPE", core.c_str(), 0) != 0) return;
  execv("/proc/self/exe", argv);
  unsetenv("OPENBLAS_CORETYPE");
}

}  // namespace sewn::physics::solve
