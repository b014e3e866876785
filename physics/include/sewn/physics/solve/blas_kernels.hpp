#pragma once
// The dense kernels under CHOLMOD's supernodal factorization. OpenBLAS picks them when it loads,
// from the CPU's model number; a release older than the CPU falls back to its SSE3 "Prescott"
// kernels (Debian 12's 0.3.21 on an Emerald Rapids Xeon, family 6 model 207, which has AVX-512):
// factorizations run ~1.5x slower than with the kernels the CPU's vector units call for
// (docs/solvers.md). OpenBLAS reads OPENBLAS_CORETYPE only as it loads, before main() (glibc
// resets the environment after an executable's preinit functions), so a process can only fix
// the choice for a process it starts: `sewn run` re-executes itself with the variable set.

#include <string>

namespace sewn::physics::solve {

/// The OPENBLAS_CORETYPE value this process should have been started with, or "" if it is fine
/// as it is: no OpenBLAS linked, OPENBLAS_CORETYPE already set (the user's choice stands), or
/// OpenBLAS chose kernels other than its generic fallback. Otherwise "SkylakeX" on a CPU with
/// AVX-512 F/DQ/BW/VL, "Haswell" with AVX2 and FMA, else "". O(1).
[[nodiscard]] std::string openblas_coretype_wanted();

/// For an executable's main(), before any work: if openblas_coretype_wanted() names kernels,
/// sets OPENBLAS_CORETYPE to them and replaces the process by a new run of the same executable
/// with the same arguments (execv of /proc/self/exe), which then keeps what OpenBLAS chose.
/// Returns only if nothing was wanted or the exec failed (the environment then as it was).
void restart_with_cpu_kernels(char** argv);

/// The kernels OpenBLAS chose ("Prescott", "SkylakeX", ...), or "" without OpenBLAS. O(1).
[[nodiscard]] std::string openblas_kernels();

}  // namespace sewn::physics::solve
