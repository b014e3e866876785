// cholmod-pcg's kept factor on both engines (physics/src/solve/cholmod.cpp): BlockCholesky's
// below SolverOptions::block_factor_flops, CHOLMOD's above (0 forces it): the answer of an
// independent direct solve, a new analysis after a cut, the same iterates after a restore, and
// one format of the saved state for both.
#include <doctest/doctest.h>

#include <memory>
#include <vector>

#include "solve_helpers.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

namespace test_kept_factor {

using namespace sewn;
using namespace sewn::physics;

namespace {

using namespace sewn::physics::test::solve_helpers;

// A with every block between nodes on opposite sides of the plane z = cut dropped (a cut
// through the springs there; their diagonal parts stay, so the matrix stays positive definite).
BlockMatrix cut_through(const BlockMatrix& A, const NodeTable& nodes, double cut) {
  const auto side = [&nodes, cut](Index i) { return nodes.position(i).z() > cut; };
  std::vector<NodePair> pairs;
  for (Index i = 0; i < A.size(); ++i)
    for (Index k = A.row_offsets()[i]; k < A.row_offsets()[i + 1]; ++k)
      if (const Index j = A.columns()[k]; j > i && side(i) == side(j)) pairs.push_back({i, j});
  BlockMatrix B;
  B.build_pattern(A.size(), pairs);
  for (Index i = 0; i < B.size(); ++i)
    for (Index k = B.row_offsets()[i]; k < B.row_offsets()[i + 1]; ++k) B.block(k) = A.block(A.find(i, B.columns()[k]));
  return B;
}

// x solves p on M as the independent reference does, to the solver's tolerance.
void check_answer(const BlockMatrix& M, const Problem& p, const std::vector<double>& x, double tolerance) {
  CHECK(relative_residual(M, p, x) <= tolerance);
  const Eigen::VectorXd ref = reference_solve(M, p);
  const Eigen::VectorXd got = Eigen::Map<const Eigen::VectorXd>(x.data(), Eigen::Index(x.size()));
  CHECK((got - ref).norm() <= 1e5 * tolerance * ref.norm());  // condition ≤ ~1e4 (h = 1 ms)
  for (std::size_t k = 0; k < x.size(); ++k)
    if (p.free_dof[k] == 0.0) REQUIRE(x[k] == p.x0[k]);
}

}  // namespace

TEST_CASE("cholmod-pcg on BlockCholesky's and on CHOLMOD's factor: a direct solve's answer, after a cut, after a restore") {
  if (!solve::available(solve::Backend::cholmod_pcg)) return;
  auto mp = beam_8x8x10();
  MssModel<3>& m = *mp;
  assemble(m.system(), 1e-3);
  const BlockMatrix& A = m.system().matrix();
  BlockMatrix B = cut_through(A, m.nodes(), 0.06);
  REQUIRE(B.num_blocks() < A.num_blocks());
  const Problem pa = random_problem(A, &m.nodes(), 0.1, 61), pb = random_problem(B, &m.nodes(), 0.1, 62);
  solve::SolverState saved;  // the block engine's, restored into the CHOLMOD one below
  for (const double limit : {solve::SolverOptions{}.block_factor_flops, 0.0}) {
    CAPTURE(limit);
    solve::SolverOptions o;
    o.tolerance = 1e-10;
    o.absolute_tolerance = 0;
    o.block_factor_flops = limit;
    auto s = solve::make_solver(solve::Backend::cholmod_pcg, o);
    // the beam: one analysis, one factorization, CG preconditioned by A's own (float) factor
    std::vector<double> x = pa.x0;
    auto r = s->solve(A, pa.b, x, pa.free_dof);
    CHECK((r.symbolic_analyses == 1 && r.factorizations == 1 && r.iterations <= 3));
    check_answer(A, pa, x, o.tolerance);
    // after the cut: a new pattern, analysed and factored afresh
    x = pb.x0;
    r = s->solve(B, pb.b, x, pb.free_dof);
    CHECK((r.symbolic_analyses == 1 && r.factorizations == 1 && r.iterations <= 3));
    check_answer(B, pb, x, o.tolerance);
    // the values move on, the factor is kept: a restored solver continues bit for bit
    for (Index i = 0; i < B.size(); ++i) B.block(B.diagonal(i)) *= 1.05;
    const solve::SolverState st = s->state();
    auto resumed = solve::make_solver(solve::Backend::cholmod_pcg, o);
    resumed->restore(B, st);
    for (int round = 0; round < 2; ++round) {
      std::vector<double> y1 = pb.x0, y2 = pb.x0;
      const auto r1 = s->solve(B, pb.b, y1, pb.free_dof);
      const auto r2 = resumed->solve(B, pb.b, y2, pb.free_dof);
      if (round == 0) CHECK((r1.factorizations == 0 && r1.iterations > 0));  // a factor of the earlier values
      CHECK(r1.factorizations == r2.factorizations);  // the refresh rule's memory restored too
      CHECK(r1.iterations == r2.iterations);
      CHECK(y1 == y2);
      check_answer(B, pb, y1, o.tolerance);
    }
    // the saved values have one format: either engine takes up the other's
    if (!saved.factored.empty()) {
      CHECK(saved.factored.size() == st.factored.size());
      auto other = solve::make_solver(solve::Backend::cholmod_pcg, o);
      other->restore(B, saved);
      std::vector<double> y = pb.x0;
      CHECK(other->solve(B, pb.b, y, pb.free_dof).factorizations == 0);
      check_answer(B, pb, y, o.tolerance);
    }
    saved = st;
    for (Index i = 0; i < B.size(); ++i) B.block(B.diagonal(i)) /= 1.05;
  }
}

}  // namespace test_kept_factor
