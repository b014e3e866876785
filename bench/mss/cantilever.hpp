#pragma once
// Speed against error on a cantilever under gravity (PHYSICS_NOTES §4): L = 1 m, b = h = 0.1 m,
// E = 100 MPa, ν = 0.3, ρ = 1000 kg/m³, g = 9.81 m/s², clamped at x = 0, meshed as 10N×N×N
// cubes. Registered by mss.cpp after the cost cases.
//   mss/cantilever/static/N<n>/ours          the MSS's own static equilibrium (the reference
//                                            family): time of the solve, tip deflection
//   mss/cantilever/N<n>/<integrator>/ours    a damped dynamic run from rest to rest: time of
//                                            the run, per step, per simulated second, tip
// The derive script (bench/mss/derive) turns the tips into errors against the extrapolated
// reference and draws the Pareto plot.
//
// The elastic suite (issue 15) registers the statics and 10 ms implicit runs under its own name
// (register_cantilever_springs), to compare them with the StVK tets against Timoshenko.
//
// The hard suite (issue 17) registers the same family extended with the implicit midpoint
// integrator and the volume term (κ = E on every hexahedron corner), under its own name:
//   hard/cantilever/static{,_volume}/N<n>/ours
//   hard/cantilever/N<n>/{implicit,midpoint}_h1e<k>{,_volume}/ours

#include "sewn_bench.hpp"

namespace sewn::bench::mss {

void register_cantilever(Scale scale);
void register_cantilever_integrators(Scale scale);
/// The elastic suite's mass-spring family (issue 15), beside its StVK tets and against the same
/// Timoshenko answer: `<suite>/cantilever/static/N<n>/ours` (N = 2, 4, smoke; 8, small; 16,
/// full) and implicit runs to rest at h = 10 ms (N = 2; 4 from small on) for the cost per
/// simulated second.
void register_cantilever_springs(const char* in_suite, Scale scale);

}  // namespace sewn::bench::mss
