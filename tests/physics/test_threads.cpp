// Multi-core kernels (sewn/physics/threads.hpp): the thread count's API and environment
// variable, bitwise-equal products and Jacobians for any count, forces equal to round-off, and
// trajectories (semi-implicit and implicit, with and without a cut) that repeat bitwise at 2
// threads and agree with 1 thread to round-off (1000 semi-implicit, 30 implicit steps).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "sewn/physics/cg.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/threads.hpp"

namespace test_threads {

using namespace sewn;
using namespace sewn::physics;

namespace threads_test {

// Sets the thread count for a scope and restores the previous one.
struct Threads {
  int previous;
  explicit Threads(int n) : previous(thread_count()) { set_thread_count(n); }
  Threads(const Threads&) = delete;
  Threads& operator=(const Threads&) = delete;
  ~Threads() { set_thread_count(previous); }
};

// 12×12×14 cubes of 5 mm by default (2535 particles, ~19k springs: every kernel splits in two
// at 2 threads), clamped at x = 0, under gravity, with the paper's material.
std::unique_ptr<MssModel<3>> block_model(Index nx = 12, Index ny = 12, Index nz = 14) {
  auto m = std::make_unique<MssModel<3>>(hex_grid(nx, ny, nz, {{0.005, 0.005, 0.005}, {}}),
                                         std::vector<MaterialParams>{{1e6, 0.3, 1000}}, std::vector<std::uint32_t>{});
  for (Index i = 0; i < m->nodes().size(); ++i)
    if (m->rest_position(i).x() <= 1e-12) m->nodes().fix(i);
  return m;
}

// The block with every position moved by up to 0.2 mm and random velocities (up to 2 cm/s):
// springs in every direction, stretched and compressed.
std::unique_ptr<MssModel<3>> jiggled_block(unsigned seed, Index nx = 12, Index ny = 12, Index nz = 14) {
  auto m = block_model(nx, ny, nz);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> jitter(-2e-4, 2e-4);
  auto x = m->nodes().x();
  auto v = m->nodes().v();
  for (std::size_t k = 0; k < x.size(); ++k) {
    x[k] += jitter(rng);
    v[k] = 100 * jitter(rng);
  }
  return m;
}

// A cut as the cutting code makes one: the particles of the plane x = 0.03 above z = 0.035
// are duplicated (mass shared) and the springs reaching them from x > 0.03 move to the copies.
void cut_plane(MssModel<3>& m) {
  NodeTable& nodes = m.nodes();
  Springs& springs = m.springs();
  const Index n = nodes.size();
  std::vector<Index> copy(n, invalid_index);
  for (Index i = 0; i < n; ++i) {
    const Eigen::Vector3d r = m.rest_position(i);
    if (std::abs(r.x() - 0.03) > 1e-9 || r.z() <= 0.035) continue;
    const double half = nodes.mass(i) / 2;
    nodes.set_mass(i, half);
    copy[i] = nodes.add(nodes.position(i), nodes.velocity(i), half);
  }
  for (Index s = 0; s < springs.size(); ++s) {
    if (!springs.is_alive(s)) continue;
    const Index a = springs.node_i(s), b = springs.node_j(s);
    if (copy[a] != invalid_index && nodes.position(b).x() > nodes.position(a).x() + 1e-9) springs.move_endpoint(s, a, copy[a]);
    else if (copy[b] != invalid_index && nodes.position(a).x() > nodes.position(b).x() + 1e-9) springs.move_endpoint(s, b, copy[b]);
  }
}

// The block's springs and two more on pairs already joined (ends swapped), in a shuffled order
// in a System of their own: no thread's range of springs keeps to a region of nodes, so most
// of the threaded Jacobian's additions go through its stash.
std::unique_ptr<System> shuffled_springs(unsigned seed) {
  auto m = jiggled_block(seed);
  auto sys = std::make_unique<System>();
  const NodeTable& from = m->nodes();
  for (Index i = 0; i < from.size(); ++i) {
    const Index k = sys->nodes().add(from.position(i), from.velocity(i), from.mass(i));
    if (from.fixed(i) != no_axes) sys->nodes().fix(k, from.fixed(i));
  }
  const Springs& block = m->springs();
  std::vector<Index> order;
  for (Index s = 0; s < block.size(); ++s)
    if (block.is_alive(s)) order.push_back(s);
  order.push_back(order[order.size() / 2]);  // two pairs joined twice
  order.push_back(order[order.size() / 3]);
  std::shuffle(order.begin(), order.end(), std::mt19937(seed));
  auto& springs = sys->add<Springs>(SpringDamping::viscous);
  std::vector<bool> seen(block.size(), false);
  for (const Index s : order) {
    const bool again = seen[s];
    seen[s] = true;
    const Index i = again ? block.node_j(s) : block.node_i(s), j = again ? block.node_i(s) : block.node_j(s);
    springs.add(i, j, block.stiffness(s), block.rest_length(s), SpringKind::edge, block.viscosity(s));
  }
  return sys;
}

// The springs' Jacobian of `sys` at its state, as the solvers ask for it (or exact: the
// non-symmetric general path), at the current thread count: the assembled matrix values (none
// when `matrix` is false: a product-only request), ∂F/∂x·v, and A·v.
struct Assembled {
  std::vector<double> values, product, matvec;
};
Assembled assemble(System& sys, bool exact, bool matrix) {
  const std::size_t dofs = 3 * std::size_t{sys.nodes().size()};
  Assembled out;
  out.product.assign(dofs, 0.0);
  JacobianRequest req;
  req.cx = -1e-6;
  req.cv = -1e-3;
  req.product_in = sys.nodes().v();
  req.product_out = out.product;
  if (exact) req.options = JacobianOptions{false, false};
  BlockMatrix* A = matrix ? &sys.matrix() : nullptr;
  if (A != nullptr) {
    A->set_zero();
    req.matrix = A;
  }
  sys.add_jacobians(req);
  if (A == nullptr) return out;
  out.matvec.assign(dofs, 0.0);
  A->multiply(sys.nodes().v(), out.matvec);
  for (Index b = 0; b < A->num_blocks(); ++b) out.values.insert(out.values.end(), A->block_data(b), A->block_data(b) + 9);
  return out;
}

// Every request of assemble() at 2 to 4 threads against 1 thread's, bitwise.
void check_jacobians_bitwise(System& sys) {
  for (const bool exact : {false, true})
    for (const bool matrix : {true, false}) {
      CAPTURE(exact);
      CAPTURE(matrix);
      Assembled one;
      {
        Threads scope(1);
        one = assemble(sys, exact, matrix);
      }
      CHECK(std::any_of(one.product.begin(), one.product.end(), [](double a) { return a != 0.0; }));
      for (const int threads : {2, 3, 4}) {
        CAPTURE(threads);
        Threads scope(threads);
        const Assembled many = assemble(sys, exact, matrix);
        CHECK(many.values == one.values);
        CHECK(many.product == one.product);
        CHECK(many.matvec == one.matvec);
      }
    }
}

// A = M − h ∂F/∂v − h² ∂F/∂x of `sys` at its state (h = 1 ms), as the implicit step builds it,
// its block-Jacobi inverse and filter, and a right-hand side of 1 N on every free axis.
struct LinearSystem {
  std::vector<double> b, free_dof, precond;
};
LinearSystem implicit_system(System& sys) {
  JacobianRequest req;
  BlockMatrix& A = sys.matrix();
  A.set_zero();
  req.matrix = &A;
  req.cx = -1e-6;
  req.cv = -1e-3;
  sys.add_jacobians(req);
  const NodeTable& nodes = sys.nodes();
  LinearSystem out;
  for (Index i = 0; i < nodes.size(); ++i) {
    A.block(A.diagonal(i)).diagonal().array() += nodes.mass(i);
    for (unsigned a = 0; a < 3; ++a) out.free_dof.push_back(((nodes.fixed(i) >> a) & 1u) != 0 ? 0.0 : 1.0);
  }
  out.b = out.free_dof;
  out.precond.resize(9 * std::size_t{nodes.size()});
  block_jacobi_inverse(A, out.free_dof, out.precond);
  return out;
}

// x after `iterations` CG iterations (no tolerance stops them) at `threads` threads.
std::vector<double> cg_iterates(System& sys, const LinearSystem& ls, int threads, int iterations, CgWorkspace& ws) {
  Threads scope(threads);
  std::vector<double> x(ls.b.size(), 0.0);
  const CgResult r = filtered_pcg(sys.matrix(), ls.b, x, ls.free_dof, ls.precond, 1e-300, iterations, ws);
  CHECK(r.iterations == iterations);
  return x;
}

struct Run {
  std::vector<double> x;
  double displacement = 0;  // largest particle displacement from the start
};

// `steps` steps of the block from rest, with `threads` threads; cut at a third of them if asked.
Run trajectory(int threads, bool implicit, bool cut, int steps) {
  Threads scope(threads);
  auto m = block_model();
  const std::vector<double> x0(m->nodes().x().begin(), m->nodes().x().end());
  SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  SymplecticEuler semi(so);
  ImplicitEulerOptions io;
  io.solver = solve::Backend::jacobi;
  io.cg_tolerance = 1e-9;  // round-off, not the solver's tolerance, sets the difference
  io.cg_absolute_tolerance = 0;
  LinearlyImplicitEuler lin(io);
  for (int step = 0; step < steps; ++step) {
    if (cut && step == steps / 3) cut_plane(*m);
    if (implicit)
      (void)lin.step(m->system(), 2e-5);
    else
      (void)semi.step(m->system(), 2e-6);
  }
  Run out;
  out.x.assign(m->nodes().x().begin(), m->nodes().x().end());
  for (std::size_t k = 0; k < x0.size(); ++k) out.displacement = std::max(out.displacement, std::abs(out.x[k] - x0[k]));
  return out;
}

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t k = 0; k < a.size(); ++k) d = std::max(d, std::abs(a[k] - b[k]));
  return d;
}

}  // namespace threads_test

TEST_CASE("threads: the count is set by the API or SEWN_THREADS, and bad values are named") {
  using threads_test::Threads;
  CHECK(parse_thread_count("2", "SEWN_THREADS") == 2);
  CHECK(parse_thread_count("256", "SEWN_THREADS") == 256);
  for (const char* bad : {"", "0", "-1", "257", "2x", "two", " 2"})
    CHECK_THROWS_WITH_AS(static_cast<void>(parse_thread_count(bad, "SEWN_THREADS")),
                         doctest::Contains("SEWN_THREADS: expected a thread count"), InputError);
  Threads scope(3);
  CHECK(thread_count() == 3);
  CHECK_THROWS_AS(set_thread_count(0), InputError);
  CHECK_THROWS_AS(set_thread_count(max_threads + 1), InputError);
  CHECK(thread_count() == 3);  // unchanged by the refused calls
}

TEST_CASE("threads: below the library's team size a library's OpenMP region with its own num_threads runs on one thread") {
  using threads_test::Threads;
  // CHOLMOD opens its regions with num_threads(4): at 1 or 2 threads they must not wake more
  // threads than asked, whatever the clause says; outside the guard, or at 4 threads, nothing changes.
  const int open = library_team_size(cholmod_team);
  CHECK(open == (parallel_build() ? cholmod_team : 1));
  for (const int count : {1, 2, cholmod_team - 1}) {
    Threads scope(count);
    const SerialLibraryRegions outer;
    CHECK(library_team_size(cholmod_team) == 1);
    {
      const SerialLibraryRegions inner;  // nested: still one, and the outer one restores
      CHECK(library_team_size(cholmod_team) == 1);
    }
    CHECK(library_team_size(cholmod_team) == 1);
  }
  CHECK(library_team_size(cholmod_team) == open);
  {
    Threads four(cholmod_team);
    const SerialLibraryRegions guard;
    CHECK(library_team_size(cholmod_team) == open);
  }
  Threads two(2);
  const SerialLibraryRegions wide(2);  // a library whose team the run's count covers
  CHECK(library_team_size(2) == (parallel_build() ? 2 : 1));
}

TEST_CASE("threads: the block-sparse product and the springs' Jacobian are bitwise equal at 1 to 4 threads") {
  using threads_test::Threads;
  auto m = threads_test::jiggled_block(7);
  System& sys = m->system();
  REQUIRE(m->springs().num_alive() >= 2 * 4096);  // the springs split at 2 threads
  REQUIRE(m->nodes().size() >= 2 * 1024);
  threads_test::check_jacobians_bitwise(sys);
  // the exact Jacobian took the other path
  Threads scope(1);
  const auto symmetric = threads_test::assemble(sys, false, true), exact = threads_test::assemble(sys, true, true);
  CHECK(exact.values != symmetric.values);
  CHECK(std::any_of(symmetric.values.begin(), symmetric.values.end(), [](double a) { return a != 0.0; }));
}

TEST_CASE("threads: the springs' Jacobian stays bitwise equal with springs in any order, on a repeated pair, on either one-thread path, and after a cut") {
  SUBCASE("shuffled springs, two pairs joined twice") {
    auto sys = threads_test::shuffled_springs(11);
    threads_test::check_jacobians_bitwise(*sys);
  }
  SUBCASE("a model small enough for the chunked one-thread path, split in two phases at 2 threads") {
    MssModel<3> m(hex_grid(11, 11, 10, {{0.005, 0.005, 0.005}, {}}), std::vector<MaterialParams>{{1e6, 0.3, 1000}},
                  std::vector<std::uint32_t>{});
    REQUIRE(m.springs().num_alive() >= 2 * 4096);   // split at 2 threads
    REQUIRE(m.springs().num_alive() < 16384);      // below the two phases' size at one thread
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-2e-4, 2e-4);
    auto x = m.nodes().x();
    auto v = m.nodes().v();
    for (std::size_t k = 0; k < x.size(); ++k) {
      x[k] += jitter(rng);
      v[k] = 100 * jitter(rng);
    }
    threads_test::check_jacobians_bitwise(m.system());
  }
  SUBCASE("the block cut, its springs re-attached to the copies") {
    auto m = threads_test::jiggled_block(13);
    threads_test::Threads scope(2);
    (void)threads_test::assemble(m->system(), false, true);  // a plan for the uncut springs
    threads_test::cut_plane(*m);
    threads_test::check_jacobians_bitwise(m->system());
  }
}

TEST_CASE("threads: spring forces at 2 threads equal 1 thread's to round-off, and repeat bitwise") {
  using threads_test::Threads;
  auto m = threads_test::jiggled_block(11);
  const auto forces = [&](int threads) {
    Threads scope(threads);
    m->system().compute_forces();
    return std::vector<double>(m->nodes().f().begin(), m->nodes().f().end());
  };
  const std::vector<double> one = forces(1), two = forces(2), again = forces(2);
  REQUIRE(m->springs().num_in_runs() > 0);  // the chunked kernel, which is what splits
  CHECK(two == again);
  double scale = 0;
  for (double f : one) scale = std::max(scale, std::abs(f));
  REQUIRE(scale > 0);
  // A node touched by both ranges sums its springs in another order: a few ulps of the
  // largest spring force, which is about the largest net force here.
  CHECK(threads_test::max_difference(one, two) <= 1e-13 * scale);
  CHECK(forces(1) == one);
}

TEST_CASE("threads: spring forces set and added at 1 to 4 threads, after a cut, agree to round-off and repeat bitwise") {
  using threads_test::Threads;
  // ~2400 chunks: 4 ranges of ~630 nodes at 4 threads, each longer than the ~190-node seam
  // (a grid layer) where the range before's springs add; the cut leaves springs in the rest list.
  auto m = threads_test::jiggled_block(5);
  threads_test::cut_plane(*m);
  const StateView st = m->nodes().state();
  const std::size_t n3 = st.x.size();
  std::vector<double> preset(n3);
  for (std::size_t k = 0; k < n3; ++k) preset[k] = std::sin(0.37 * static_cast<double>(k));
  const auto forces = [&](int threads, bool add) {
    Threads scope(threads);
    std::vector<double> f = add ? preset : std::vector<double>(n3, 7.0);
    if (add)
      m->springs().add_forces(st, f);
    else
      m->springs().set_forces(st, f);
    return f;
  };
  const std::vector<double> one = forces(1, false);
  REQUIRE(m->springs().num_in_runs() > 0);  // the plan, built by the first call, has chunks
  double scale = 0;
  for (double f : one) scale = std::max(scale, std::abs(f));
  REQUIRE(scale > 0);
  for (const int threads : {1, 2, 3, 4}) {
    CAPTURE(threads);
    const std::vector<double> set = forces(threads, false), added = forces(threads, true);
    CHECK(forces(threads, false) == set);  // bitwise, and the accumulators were left at zero
    CHECK(threads_test::max_difference(one, set) <= 1e-13 * scale);
    std::vector<double> expected = preset;
    for (std::size_t k = 0; k < n3; ++k) expected[k] += one[k];
    CHECK(threads_test::max_difference(expected, added) <= 1e-13 * (scale + 1));
  }
}

TEST_CASE("threads: a slab's forces split only into ranges longer than a seam of a grid layer") {
  using threads_test::Threads;
  // 40×40×1 cubes: 3362 particles, ~3400 chunks, the seam (a layer, 1681 nodes, plus the body
  // diagonal) ~1736 nodes. Balanced by chunks, whose lower node is mostly in the bottom layer:
  // at 2 threads the ranges start at 0 and ~1300 (the second longer than a seam: split), at 3
  // at 0, ~730 and ~1460 (the middle one shorter: one range, bitwise as one thread).
  MssModel<3> m(hex_grid(40, 40, 1, {{0.005, 0.005, 0.005}, {}}), std::vector<MaterialParams>{{1e6, 0.3, 1000}},
                std::vector<std::uint32_t>{});
  auto x = m.nodes().x();
  for (std::size_t k = 0; k < x.size(); ++k) x[k] += 1e-4 * std::sin(1.3 * static_cast<double>(k));
  const StateView st = m.nodes().state();
  std::uint64_t regions = 0;
  const auto forces = [&](int threads) {
    Threads scope(threads);
    std::vector<double> f(st.x.size());
    const std::uint64_t before = split_regions();
    m.springs().set_forces(st, f);
    regions = split_regions() - before;
    return f;
  };
  const std::vector<double> one = forces(1);
  REQUIRE(m.springs().num_in_runs() > 0);
  double scale = 0;
  for (double f : one) scale = std::max(scale, std::abs(f));
  const std::vector<double> two = forces(2);
  CHECK(regions == 1);
  CHECK(threads_test::max_difference(one, two) <= 1e-13 * scale);
  CHECK(forces(3) == one);
  CHECK(regions == 0);
}

TEST_CASE("threads: CG's packed product at 1 to 4 threads agrees with one thread's to round-off, before and after a cut") {
  // 16³ cubes: 4 913 particles, 4 ranges of ~1 230 rows at 4 threads, each longer than the
  // grid layer (289 rows) earlier ranges' blocks reach; the cut changes the pattern, and with it
  // where each range's products spill.
  auto m = threads_test::jiggled_block(17, 16, 16, 16);
  System& sys = m->system();
  REQUIRE(m->nodes().size() >= 4 * 1024);
  CgWorkspace kept;  // one workspace across counts and the cut, as a solver keeps it
  for (const bool cut : {false, true}) {
    CAPTURE(cut);
    if (cut) threads_test::cut_plane(*m);
    sys.refresh();
    const threads_test::LinearSystem ls = threads_test::implicit_system(sys);
    CgWorkspace fresh;
    const std::vector<double> one = threads_test::cg_iterates(sys, ls, 1, 8, fresh);
    double scale = 0;
    for (double v : one) scale = std::max(scale, std::abs(v));
    REQUIRE(scale > 0);
    for (const int threads : {1, 2, 3, 4}) {
      CAPTURE(threads);
      const std::vector<double> x = threads_test::cg_iterates(sys, ls, threads, 8, kept);
      CHECK(threads_test::cg_iterates(sys, ls, threads, 8, kept) == x);  // repeats bitwise
      CHECK(threads_test::max_difference(one, x) <= 1e-12 * scale);
    }
  }
}

TEST_CASE("threads: trajectories repeat bitwise at 2 threads and agree with 1 thread to round-off") {
  // 1000 semi-implicit steps; implicit ones cost ~30 CG iterations each, with four meetings
  // of the threads per iteration, which on a loaded machine (CI) take a time slice each: 100
  // implicit steps took 20 s alone at a load of 20 on 2 cores and over 20 min inside ctest.
  const int implicit_steps = 30;
  for (const bool implicit : {false, true})
    for (const bool cut : {false, true}) {
      CAPTURE(implicit);
      CAPTURE(cut);
      const threads_test::Run one = threads_test::trajectory(1, implicit, cut, implicit ? implicit_steps : 1000);
      const threads_test::Run two = threads_test::trajectory(2, implicit, cut, implicit ? implicit_steps : 1000);
      const threads_test::Run again = threads_test::trajectory(2, implicit, cut, implicit ? implicit_steps : 1000);
      // the block moved: 30 implicit steps of 20 µs fall ½ g t² = 1.8 µm, 1000 semi-implicit ones more
      REQUIRE(one.displacement > 1e-6);
      CHECK(two.x == again.x);
      const double relative = threads_test::max_difference(one.x, two.x) / one.displacement;
      CAPTURE(relative);
      CHECK(relative < 1e-12);  // measured: 2e-16 to 1.2e-15
    }
}

}  // namespace test_threads

namespace test_threads {

TEST_CASE("threads: a small model's steps stay on one thread at 2 threads, the block's split") {
  using threads_test::Threads;
  Threads two(2);
  // 3×3×4 cubes: 80 particles, below every kernel's threshold (forces, Jacobian, product, CG)
  auto small = std::make_unique<MssModel<3>>(hex_grid(3, 3, 4, {{0.005, 0.005, 0.005}, {}}),
                                             std::vector<MaterialParams>{{1e6, 0.3, 1000}}, std::vector<std::uint32_t>{});
  small->nodes().fix(0);
  auto block = threads_test::block_model();
  SymplecticEulerOptions so;
  so.enforce_stable_step = false;
  ImplicitEulerOptions io;
  io.solver = solve::Backend::jacobi;
  for (const bool implicit : {false, true}) {
    CAPTURE(implicit);
    SymplecticEuler semi(so);
    LinearlyImplicitEuler lin(io);
    const auto step = [&](MssModel<3>& m) {
      if (implicit)
        (void)lin.step(m.system(), 2e-5);
      else
        (void)semi.step(m.system(), 2e-6);
    };
    const std::uint64_t before = split_regions();
    for (int s = 0; s < 3; ++s) step(*small);
    CHECK(split_regions() == before);
    lin.reset();
    for (int s = 0; s < 3; ++s) step(*block);
    CHECK(split_regions() > before);
  }
}

}  // namespace test_threads
