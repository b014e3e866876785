// The petsc backend on the program's MPI ranks (CTest runs this file's executable as
// `mpirun -n 2`, SEWN_EXPECT_RANKS=2): every rank assembles the same system, PETSc solves it
// across the ranks, and each rank checks the gathered answer against a serial solve of its own.
#include <doctest/doctest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "solve_helpers.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

namespace test_solve_mpi {

namespace {

using namespace sewn::physics;
using namespace sewn::physics::test::solve_helpers;

// The serial reference of this test: CHOLMOD when built in, else block-Jacobi CG, at 1e-12.
solve::Backend serial_backend() {
  return solve::available(solve::Backend::cholmod) ? solve::Backend::cholmod : solve::Backend::jacobi;
}

}  // namespace

TEST_CASE("petsc runs on the ranks it was started with") {
  if (!solve::available(solve::Backend::petsc)) return;
  const int ranks = solve::solver_ranks();
  MESSAGE("petsc solves on " << ranks << " MPI rank(s)");
  if (const char* expect = std::getenv("SEWN_EXPECT_RANKS")) CHECK(ranks == std::atoi(expect));
}

TEST_CASE("petsc on every rank solves the 8x8x10 beam's system as a serial solve does") {
  if (!solve::available(solve::Backend::petsc)) return;
  auto m = beam_8x8x10();
  assemble(m->system(), 1e-3);
  const BlockMatrix& A = m->system().matrix();
  for (double fixed_fraction : {0.0, 0.2}) {
    CAPTURE(fixed_fraction);
    const Problem p = random_problem(A, &m->nodes(), fixed_fraction, 11);
    solve::SolverOptions tight;
    tight.tolerance = 1e-12;
    tight.absolute_tolerance = 0;
    std::vector<double> serial = p.x0;
    REQUIRE(solve::make_solver(serial_backend(), tight)->solve(A, p.b, serial, p.free_dof).converged);
    solve::SolverOptions o;
    o.tolerance = 1e-8;
    o.absolute_tolerance = 0;
    auto petsc = solve::make_solver(solve::Backend::petsc, o);
    std::vector<double> x = p.x0;
    const solve::SolveReport r = petsc->solve(A, p.b, x, p.free_dof, p.mass);
    CHECK(r.converged);
    CHECK(r.iterations > 0);
    CHECK(r.factorizations == 1);
    CHECK(r.symbolic_analyses == 1);
    for (std::size_t k = 0; k < x.size(); ++k)
      if (p.free_dof[k] == 0.0) REQUIRE(x[k] == p.x0[k]);
    CHECK(relative_residual(A, p, x) <= 1e-8 * 1.0001);
    double diff = 0, norm = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
      diff += (x[k] - serial[k]) * (x[k] - serial[k]);
      norm += serial[k] * serial[k];
    }
    // the error is bounded by the residual times the condition number (≤ ~1e4 here)
    CHECK(std::sqrt(diff) <= 1e5 * 1e-8 * std::sqrt(norm));
    // a second solve on the same pattern builds nothing but the preconditioner
    x = p.x0;
    const solve::SolveReport again = petsc->solve(A, p.b, x, p.free_dof, p.mass);
    CHECK(again.symbolic_analyses == 0);
    CHECK(relative_residual(A, p, x) <= 1e-8 * 1.0001);
  }
}

TEST_CASE("petsc's trajectory on every rank follows a tight serial solve's") {
  if (!solve::available(solve::Backend::petsc)) return;
  auto run = [](solve::Backend b, double tolerance, double floor) {
    auto m = beam_8x8x10();
    LinearlyImplicitEuler ie;
    ie.options().solver = b;
    ie.options().cg_tolerance = tolerance;
    ie.options().cg_absolute_tolerance = floor;
    for (int s = 0; s < 30; ++s) REQUIRE(ie.step(m->system(), 1e-3).cg_converged);
    Eigen::VectorXd u(3 * Eigen::Index{m->nodes().size()});
    for (Index i = 0; i < m->nodes().size(); ++i) u.segment<3>(3 * i) = m->nodes().position(i) - m->rest_position(i);
    return u;
  };
  const Eigen::VectorXd ref = run(serial_backend(), 1e-12, 0.0);
  REQUIRE(ref.norm() > 0);
  const Eigen::VectorXd u = run(solve::Backend::petsc, 1e-6, solve::default_absolute_tolerance);
  CHECK((u - ref).norm() <= 30 * 1e-6 * ref.norm());
}

TEST_CASE("petsc notices a new pattern and refuses an indefinite matrix naming where") {
  if (!solve::available(solve::Backend::petsc)) return;
  auto petsc = solve::make_solver(solve::Backend::petsc);
  for (unsigned seed : {3u, 4u}) {  // two patterns in turn
    BlockMatrix A;
    random_spd(A, 90 + 20 * seed, seed);
    const Problem p = random_problem(A, nullptr, 0.1, seed + 10);
    std::vector<double> x = p.x0;
    const auto r = petsc->solve(A, p.b, x, p.free_dof);
    CHECK(r.symbolic_analyses == 1);
    CHECK(relative_residual(A, p, x) <= 1e-6 * 1.0001);
  }
  BlockMatrix A;
  random_spd(A, 40, 31);
  A.block(A.diagonal(17))(1, 1) = -1e6;
  const Problem p = random_problem(A, nullptr, 0.0, 32);
  std::vector<double> x = p.x0;
  CHECK_THROWS_WITH_AS(petsc->solve(A, p.b, x, p.free_dof), doctest::Contains("node 17, axis y"), SolverError);
  CHECK(x == p.x0);
}

}  // namespace test_solve_mpi
