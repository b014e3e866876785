// Seed 002 (Fléchon et al. 2013) mass-spring cases: cost per step of the semi-implicit and the
// linearly implicit Euler steps, h = 1 ms, E = 100 MPa, ν = 0.3, ρ = 1000, g = 9.8, the
// seed's per-spring viscosity, one face clamped. Meshes: 1 hexahedron of 10 cm (8 particles,
// 16 springs) and the 8x8x10 grid of 1.25 cm cubes (891 particles, 2394 edge + 2560 diagonal
// springs). "ours" steps a sewn::physics::System; "peer" is the fastest bare loop over plain
// arrays for the same semi-implicit step (same data, gravity, viscosity and clamp; no health
// checks), so ours/peer is the library's overhead.
//
// h = 1 ms is ~30x the explicit limit of the 8x8x10 mesh (PHYSICS_NOTES §1.6): the stability
// refusal and the energy watchdog are opted out and the state is restored (untimed) every
// 16 steps, before it could overflow. This measures cost, not a usable simulation.
#include <benchmark/benchmark.h>

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#if defined(__AVX512F__) && defined(__AVX512VL__)
#include <immintrin.h>
#endif

#ifdef SEWN_BENCH_HARNESS
#include "sewn_bench.hpp"
#endif

#include "sewn/physics/physics.hpp"

namespace {

using namespace sewn::physics;

constexpr double kE = 1e8, kNu = 0.3, kRho = 1000, kH = 1e-3, kG = -9.8;
constexpr int kExplicitReset = 16;
constexpr int kImplicitReset = 50;

struct Mesh {
  Index nx, ny, nz;
  double a;
};

struct Scene {
  System sys;
  BoxLattice lattice;
  std::vector<double> x0, v0;
  void restore() {
    std::copy(x0.begin(), x0.end(), sys.nodes().x().begin());
    std::copy(v0.begin(), v0.end(), sys.nodes().v().begin());
  }
};

std::unique_ptr<Scene> make_scene(const Mesh& m) {
  auto sc = std::make_unique<Scene>();
  BoxLatticeSpec spec;
  spec.nx = m.nx;
  spec.ny = m.ny;
  spec.nz = m.nz;
  spec.lx = spec.ly = spec.lz = m.a;
  spec.E = kE;
  spec.nu = kNu;
  spec.rho = kRho;
  spec.damping = SpringDamping::viscous;
  sc->lattice = build_box_lattice(sc->sys, spec);
  sc->sys.add<Gravity>(Eigen::Vector3d(0, 0, kG));
  for (Index j = 0; j <= m.ny; ++j)
    for (Index i = 0; i <= m.nx; ++i) sc->sys.nodes().fix(sc->lattice.node(i, j, 0));
  sc->x0.assign(sc->sys.nodes().x().begin(), sc->sys.nodes().x().end());
  sc->v0.assign(sc->sys.nodes().v().begin(), sc->sys.nodes().v().end());
  return sc;
}

void set_counters(benchmark::State& st, const Scene& sc) {
  st.counters["particles"] = sc.sys.nodes().size();
  st.counters["springs"] = sc.lattice.springs->num_alive();
}

void semi_implicit_ours(benchmark::State& st, Mesh m) {
  auto sc = make_scene(m);
  SymplecticEulerOptions opt;
  opt.enforce_stable_step = false;
  opt.health.energy_check_interval = 0;
  SymplecticEuler se(opt);
  int k = 0;
  for (auto _ : st) {
    (void)se.step(sc->sys, kH);
    if (++k == kExplicitReset) {
      st.PauseTiming();
      sc->restore();
      k = 0;
      st.ResumeTiming();
    }
  }
  set_counters(st, *sc);
}

void implicit_ours(benchmark::State& st, Mesh m) {
  auto sc = make_scene(m);
  LinearlyImplicitEuler ie;  // CG to 1e-6, block Jacobi, warm start
  int k = 0;
  double iterations = 0;
  for (auto _ : st) {
    const StepReport r = ie.step(sc->sys, kH);
    iterations += r.cg_iterations;
    if (++k == kImplicitReset) {
      st.PauseTiming();
      sc->restore();
      ie.reset();
      k = 0;
      st.ResumeTiming();
    }
  }
  set_counters(st, *sc);
  st.counters["cg_iterations"] = benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}

// ------------------------------------------------------------------ the bare loop

// Plain arrays copied from the same scene. Fixed axes have inverse mass 0; gravity is the
// accumulator's initial value; forces go to a 4-wide accumulator read directly by the update.
struct Bare {
  std::size_t n = 0, springs = 0;
  AlignedVector<double> x, v, inv_mass, gravity, acc, k, l, g;
  AlignedVector<Index> i, j;
};

Bare make_bare(const Scene& sc) {
  Bare b;
  const NodeTable& nd = sc.sys.nodes();
  const Springs& sp = *sc.lattice.springs;
  b.n = nd.size();
  b.x.assign(nd.x().begin(), nd.x().end());
  b.v.assign(nd.v().begin(), nd.v().end());
  b.inv_mass.assign(nd.inverse_mass_dof().begin(), nd.inverse_mass_dof().end());
  b.gravity.assign(4 * b.n, 0.0);
  for (std::size_t p = 0; p < b.n; ++p) b.gravity[4 * p + 2] = nd.masses()[p] * kG;
  b.acc.assign(4 * b.n, 0.0);
  b.springs = sp.size();
  for (Index s = 0; s < sp.size(); ++s) {
    b.i.push_back(sp.node_i(s));
    b.j.push_back(sp.node_j(s));
    b.k.push_back(sp.stiffness(s));
    b.l.push_back(sp.rest_length(s));
    b.g.push_back(sp.viscosity(s));
  }
  return b;
}

#if defined(__AVX512F__) && defined(__AVX512VL__)
inline void bare_springs(Bare& b) {
  const double* __restrict x = b.x.data();
  const double* __restrict v = b.v.data();
  double* __restrict acc = b.acc.data();
  const __m256d one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5), th = _mm256_set1_pd(1.5),
                zero = _mm256_setzero_pd();
  std::size_t s = 0;
  for (; s + 4 <= b.springs; s += 4) {
    std::size_t I[4], J[4];
    __m256d d[4], u[4];
    for (int q = 0; q < 4; ++q) {
      I[q] = b.i[s + q];
      J[q] = b.j[s + q];
      d[q] = _mm256_sub_pd(_mm256_maskz_loadu_pd(7, x + 3 * J[q]), _mm256_maskz_loadu_pd(7, x + 3 * I[q]));
      u[q] = _mm256_sub_pd(_mm256_maskz_loadu_pd(7, v + 3 * J[q]), _mm256_maskz_loadu_pd(7, v + 3 * I[q]));
    }
    __m256d t0 = _mm256_unpacklo_pd(d[0], d[1]), t1 = _mm256_unpackhi_pd(d[0], d[1]);
    __m256d t2 = _mm256_unpacklo_pd(d[2], d[3]), t3 = _mm256_unpackhi_pd(d[2], d[3]);
    const __m256d dx = _mm256_permute2f128_pd(t0, t2, 0x20), dz = _mm256_permute2f128_pd(t0, t2, 0x31),
                  dy = _mm256_permute2f128_pd(t1, t3, 0x20);
    t0 = _mm256_unpacklo_pd(u[0], u[1]);
    t1 = _mm256_unpackhi_pd(u[0], u[1]);
    t2 = _mm256_unpacklo_pd(u[2], u[3]);
    t3 = _mm256_unpackhi_pd(u[2], u[3]);
    const __m256d ux = _mm256_permute2f128_pd(t0, t2, 0x20), uz = _mm256_permute2f128_pd(t0, t2, 0x31),
                  uy = _mm256_permute2f128_pd(t1, t3, 0x20);
    const __m256d d2 = _mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx)));
    const __m256d hd = _mm256_mul_pd(half, d2);
    __m256d y = _mm256_rsqrt14_pd(d2);
    y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), th));
    y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hd, _mm256_mul_pd(y, y), th));
    const __m256d w = _mm256_mul_pd(_mm256_fmadd_pd(uz, dz, _mm256_fmadd_pd(uy, dy, _mm256_mul_pd(ux, dx))),
                                    _mm256_mul_pd(y, y));
    const __m256d c = _mm256_fmadd_pd(_mm256_loadu_pd(&b.g[s]), w,
                                      _mm256_mul_pd(_mm256_loadu_pd(&b.k[s]),
                                                    _mm256_fnmadd_pd(_mm256_loadu_pd(&b.l[s]), y, one)));
    const __m256d fx = _mm256_mul_pd(c, dx), fy = _mm256_mul_pd(c, dy), fz = _mm256_mul_pd(c, dz);
    t0 = _mm256_unpacklo_pd(fx, fy);
    t1 = _mm256_unpackhi_pd(fx, fy);
    t2 = _mm256_unpacklo_pd(fz, zero);
    t3 = _mm256_unpackhi_pd(fz, zero);
    const __m256d r[4] = {_mm256_permute2f128_pd(t0, t2, 0x20), _mm256_permute2f128_pd(t1, t3, 0x20),
                          _mm256_permute2f128_pd(t0, t2, 0x31), _mm256_permute2f128_pd(t1, t3, 0x31)};
    for (int q = 0; q < 4; ++q) {
      double* ai = acc + 4 * I[q];
      double* aj = acc + 4 * J[q];
      _mm256_store_pd(ai, _mm256_add_pd(_mm256_load_pd(ai), r[q]));
      _mm256_store_pd(aj, _mm256_sub_pd(_mm256_load_pd(aj), r[q]));
    }
  }
  for (; s < b.springs; ++s) {
    const std::size_t i = b.i[s], j = b.j[s];
    const double dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1], dz = x[3 * j + 2] - x[3 * i + 2];
    const double ux = v[3 * j] - v[3 * i], uy = v[3 * j + 1] - v[3 * i + 1], uz = v[3 * j + 2] - v[3 * i + 2];
    const double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double c = b.k[s] * (1.0 - b.l[s] * inv) + b.g[s] * (ux * dx + uy * dy + uz * dz) * inv * inv;
    acc[4 * i] += c * dx;
    acc[4 * i + 1] += c * dy;
    acc[4 * i + 2] += c * dz;
    acc[4 * j] -= c * dx;
    acc[4 * j + 1] -= c * dy;
    acc[4 * j + 2] -= c * dz;
  }
}
#else
inline void bare_springs(Bare& b) {
  const double* __restrict x = b.x.data();
  const double* __restrict v = b.v.data();
  double* __restrict acc = b.acc.data();
  for (std::size_t s = 0; s < b.springs; ++s) {
    const std::size_t i = b.i[s], j = b.j[s];
    const double dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1], dz = x[3 * j + 2] - x[3 * i + 2];
    const double ux = v[3 * j] - v[3 * i], uy = v[3 * j + 1] - v[3 * i + 1], uz = v[3 * j + 2] - v[3 * i + 2];
    const double inv = 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    const double c = b.k[s] * (1.0 - b.l[s] * inv) + b.g[s] * (ux * dx + uy * dy + uz * dz) * inv * inv;
    acc[4 * i] += c * dx;
    acc[4 * i + 1] += c * dy;
    acc[4 * i + 2] += c * dz;
    acc[4 * j] -= c * dx;
    acc[4 * j + 1] -= c * dy;
    acc[4 * j + 2] -= c * dz;
  }
}
#endif

inline void bare_step(Bare& b) {
  std::memcpy(b.acc.data(), b.gravity.data(), 4 * b.n * sizeof(double));
  bare_springs(b);
  double* __restrict x = b.x.data();
  double* __restrict v = b.v.data();
  const double* __restrict im = b.inv_mass.data();
  const double* __restrict acc = b.acc.data();
  for (std::size_t p = 0; p < b.n; ++p)
    for (std::size_t a = 0; a < 3; ++a) {
      v[3 * p + a] += kH * im[3 * p + a] * acc[4 * p + a];
      x[3 * p + a] += kH * v[3 * p + a];
    }
}

void semi_implicit_bare(benchmark::State& st, Mesh m) {
  auto sc = make_scene(m);
  Bare b = make_bare(*sc);
  const AlignedVector<double> x0 = b.x, v0 = b.v;
  int k = 0;
  for (auto _ : st) {
    bare_step(b);
    benchmark::ClobberMemory();
    if (++k == kExplicitReset) {
      st.PauseTiming();
      b.x = x0;
      b.v = v0;
      k = 0;
      st.ResumeTiming();
    }
  }
  set_counters(st, *sc);
}

// The bare loop and the library must agree, or the comparison means nothing.
void check_same_step(const Mesh& m) {
  auto sc = make_scene(m);
  Bare b = make_bare(*sc);
  SymplecticEulerOptions opt;
  opt.enforce_stable_step = false;
  SymplecticEuler se(opt);
  for (int n = 0; n < 3; ++n) {
    (void)se.step(sc->sys, kH);
    bare_step(b);
  }
  double err = 0, scale = 0;
  for (std::size_t q = 0; q < b.x.size(); ++q) {
    err = std::max(err, std::abs(b.v[q] - sc->sys.nodes().v()[q]));
    scale = std::max(scale, std::abs(b.v[q]));
  }
  if (!(err <= 1e-9 * scale)) throw std::runtime_error("bench_mss: bare loop and library disagree");
}

struct Case {
  const char* name;
  Mesh mesh;
};

void register_all() {
  std::vector<Case> cases = {{"hex1", {1, 1, 1, 0.1}}, {"hex8x8x10", {8, 8, 10, 0.0125}}};
#ifdef SEWN_BENCH_HARNESS
  if (sewn::bench::scale() == sewn::bench::Scale::smoke) cases = {{"hex1", {1, 1, 1, 0.1}}, {"hex2x2x3", {2, 2, 3, 0.0125}}};
#endif
  for (const Case& c : cases) {
    check_same_step(c.mesh);
    const std::string base = std::string(c.name);
    const Mesh m = c.mesh;
#ifdef SEWN_BENCH_HARNESS
    sewn::bench::ours("mss", base + "/semi_implicit", [m](benchmark::State& st) { semi_implicit_ours(st, m); })
        ->Unit(benchmark::kMicrosecond);
    sewn::bench::peer("mss", base + "/semi_implicit", "bare loop", [m](benchmark::State& st) { semi_implicit_bare(st, m); })
        ->Unit(benchmark::kMicrosecond);
    sewn::bench::ours("mss", base + "/implicit", [m](benchmark::State& st) { implicit_ours(st, m); })
        ->Unit(benchmark::kMicrosecond);
#else
    benchmark::RegisterBenchmark(("mss/" + base + "/semi_implicit/ours").c_str(),
                                 [m](benchmark::State& st) { semi_implicit_ours(st, m); })
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("mss/" + base + "/semi_implicit/peer").c_str(),
                                 [m](benchmark::State& st) { semi_implicit_bare(st, m); })
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("mss/" + base + "/implicit/ours").c_str(),
                                 [m](benchmark::State& st) { implicit_ours(st, m); })
        ->Unit(benchmark::kMicrosecond);
#endif
  }
}

#ifdef SEWN_BENCH_HARNESS
const sewn::bench::Registration registration(&register_all);
#else
const int registered = (register_all(), 0);
#endif

}  // namespace
