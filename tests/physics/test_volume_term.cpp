// Issue 17, the volume term (solids/volume_term): Teschner-style ½ κ w (J - 1)² per tetrahedron
// and per hexahedron corner. Energy, gradient and Hessian against central finite differences
// (inverted stencils included), the assembled Jacobian of a model against finite differences of
// its forces, its energy in the ledger's elastic energy, and the soft/stiff column: the region
// 10⁶ times softer than its load inverts without the term and not with it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include <Eigen/Geometry>

#include "elastic_helpers.hpp"
#include "helpers.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/mss_model.hpp"
#include "sewn/physics/solids/inversion.hpp"
#include "sewn/physics/solids/volume_term.hpp"

namespace test_volume_term {

using namespace sewn;
using namespace sewn::physics;
using Eigen::Vector3d;

TEST_CASE("volume term: energy, gradient and Hessian match finite differences, inverted stencils included") {
  std::mt19937 rng(1704);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 40; ++trial) {
    CAPTURE(trial);
    solids::CornerPositions X;
    X << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
    X += 0.2 * solids::CornerPositions::NullaryExpr([&] { return u(rng); });
    const solids::VolumeStencil rest{(X.rightCols<3>().colwise() - X.col(0)).determinant(), 2.5};
    solids::CornerPositions x = X + 0.4 * solids::CornerPositions::NullaryExpr([&] { return u(rng); });
    if (trial % 4 == 3) x.col(3) = 2.0 * x.col(0) - x.col(3);  // c pushed through: J < 0
    test::check_element<4>([&](const solids::CornerPositions& y) { return solids::volume_energy(y, rest); },
                           [&](const solids::CornerPositions& y) { return solids::volume_gradient(y, rest); },
                           [&](const solids::CornerPositions& y) { return solids::volume_hessian(y, rest); }, x, 1e-5, 1e-6);
    // the energy is ½ s (V/V̄ - 1)² with V the signed volume of the corner's edges
    const double J = (x.rightCols<3>().colwise() - x.col(0)).determinant() / rest.rest_det;
    CHECK(solids::volume_energy(x, rest) == doctest::Approx(0.5 * 2.5 * (J - 1) * (J - 1)).epsilon(1e-12));
    // a rigid motion keeps the volume: no energy, no force
    const solids::CornerPositions moved = (test::random_rotation(rng) * X).colwise() + Vector3d(1.0, -2.0, 0.5);
    CHECK(solids::volume_energy(moved, rest) < 1e-24);
    CHECK(solids::volume_gradient(moved, rest).norm() < 1e-12);
  }
}

TEST_CASE("volume term on a model: an affine deformation gives ½κV̄(det F - 1)², the Jacobian matches finite differences") {
  for (bool tets : {false, true}) {
    CAPTURE(tets);
    const GridSpec g{{0.1, 0.12, 0.11}, {}};
    MssOptions o;
    o.damping = DampingModel::none;
    o.gravity = Vector3d::Zero();
    MssModel<3> m(tets ? tet_grid(2, 1, 2, TetSplit::kuhn6, g) : hex_grid(2, 1, 2, g), {{1e6, 0.3, 1000}, {1e6, 0.3, 1000}},
                  {}, o);
    const std::vector<double> kappa{3e5, 0.0};
    solids::VolumePreservation* term = solids::add_volume_preservation(m, kappa);
    REQUIRE(term != nullptr);
    CHECK(term->size() == (tets ? 24 : 32));  // 24 tetrahedra, or 4 hexahedra of 8 corners
    CHECK(solids::add_volume_preservation(m, std::vector<double>{0.0, 0.0}) == nullptr);
    CHECK_THROWS_WITH_AS((void)solids::add_volume_preservation(m, std::vector<double>{-1.0, 0.0}),
                         doctest::Contains("material 0"), InputError);
    Eigen::Matrix3d F;
    F << 1.1, 0.05, 0.0, -0.02, 0.93, 0.1, 0.03, 0.0, 1.04;
    const double volume = 0.2 * 0.12 * 0.22;
    for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_position(i, F * m.rest_position(i));
    const StateView s = m.nodes().state();
    const double expect = 0.5 * 3e5 * volume * (F.determinant() - 1) * (F.determinant() - 1);
    CHECK(term->potential_energy(s) == doctest::Approx(expect).epsilon(1e-12));
    // the ledger's elastic energy is every internal term's: springs and the volume term
    CHECK(m.system().potential_energy(EnergyKind::internal) ==
          doctest::Approx(m.springs().potential_energy(s) + term->potential_energy(s)).epsilon(1e-14));
    // random positions: the assembled ∂F/∂x (exact options) against central differences
    std::mt19937 rng(tets ? 5 : 6);
    std::uniform_real_distribution<double> u(-0.02, 0.02);
    for (Index i = 0; i < m.nodes().size(); ++i)
      m.nodes().set_position(i, F * m.rest_position(i) + Vector3d(u(rng), u(rng), u(rng)));
    const JacobianOptions exact{false, false, false};
    const Eigen::MatrixXd K = test::assembled(m.system(), 1.0, 0.0, exact);
    const Eigen::MatrixXd K_fd = test::finite_difference(m.system(), false, 1e-7);
    CHECK(test::max_abs(K - K_fd) < 1e-5 * test::max_abs(K_fd));
  }
}

namespace volume_term_test {

struct ColumnRun {
  Index most_inverted = 0;
  double least_corner_ratio = 1.0;  // the smallest J of the soft region's corners seen
};

// The soft/stiff column of test_inversion.cpp: 2x2x6 cubes of 5 cm on the ground, the lower
// half 1 kPa, the upper 1 GPa, stepped 1 s by the linearly implicit Euler at 1 ms.
ColumnRun run_column(double soft_kappa) {
  const IndexedMesh mesh = hex_grid(2, 2, 6, {{0.05, 0.05, 0.05}, {}});
  std::vector<std::uint32_t> material(mesh.num_cells());
  for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) material[c] = c < mesh.num_cells() / 2 ? 0 : 1;
  MssModel<3> m(mesh, {{1e3, 0.3, 1000}, {1e9, 0.3, 1000}}, material);
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).z() <= 1e-12) m.nodes().fix(i);
  const solids::VolumePreservation* term = solids::add_volume_preservation(m, std::vector<double>{soft_kappa, 0.0});
  LinearlyImplicitEuler euler;
  euler.options().cg_max_iterations = 10000;
  ColumnRun out;
  InversionMonitor monitor;
  for (int s = 1; s <= 1000; ++s) {
    (void)euler.step(m.system(), 1e-3);
    out.most_inverted = std::max(out.most_inverted, monitor.count(m).elements);
    if (term == nullptr) continue;
    for (Index e = 0; e < term->size(); ++e) {
      const solids::CornerPositions x = term->gather(m.nodes().state(), e);
      const double J = (x.rightCols<3>().colwise() - x.col(0)).determinant() / term->stencil(e).rest_det;
      out.least_corner_ratio = std::min(out.least_corner_ratio, J);
    }
  }
  return out;
}

}  // namespace volume_term_test

TEST_CASE("the soft/stiff column: inverted without the volume term, none with it") {
  // The stiff block presses on the soft region with ρ g h = 1000·9.81·0.15 ≈ 1.5 kPa, above the
  // soft springs' 1 kPa: they give way. A bulk stiffness κ = 100 kPa (a soft, nearly
  // incompressible solid: κ/E = 100) predicts a volume change of about p/κ ≈ 1.5 % there.
  const volume_term_test::ColumnRun without = volume_term_test::run_column(0.0);
  const volume_term_test::ColumnRun with = volume_term_test::run_column(1e5);
  MESSAGE("soft/stiff column, 1 s: at most " << without.most_inverted << " of 24 hexahedra inverted without the volume term, "
                                             << with.most_inverted << " with kappa = 100 kPa (smallest corner volume ratio "
                                             << with.least_corner_ratio << ")");
  CHECK(without.most_inverted > 0);
  CHECK(with.most_inverted == 0);
  CHECK(with.least_corner_ratio > 0.0);
}

namespace volume_term_test {

// A 4x2x2 beam of 5 cm cubes with the volume term on, cut through at x = 0.1 (every face there
// unsewn, so the beam falls apart in two), as the scene tool's plane cut does.
struct CutBeam {
  std::unique_ptr<MssModel<3>> model;
  solids::VolumePreservation* term = nullptr;
  Index nodes_before = 0;
};

CutBeam cut_beam() {
  MssOptions o;
  o.damping = DampingModel::none;
  o.gravity = Vector3d::Zero();
  CutBeam b;
  b.model = std::make_unique<MssModel<3>>(hex_grid(4, 2, 2, {{0.05, 0.05, 0.05}, {}}), std::vector<MaterialParams>{{1e6, 0.3, 1000}},
                                          std::vector<std::uint32_t>{}, o);
  MssModel<3>& m = *b.model;
  b.term = solids::add_volume_preservation(m, std::vector<double>{3e6});
  b.nodes_before = m.nodes().num_alive();
  const auto at_cut = [&](Dart d) { return std::abs(m.rest_position(m.node_of(d)).x() - 0.1) < 1e-12; };
  m.edit([&](auto& map) {
    for (Dart d : map.darts())
      if (map.beta(d, 3) && at_cut(d) && at_cut(map.beta(d, 1)) && at_cut(map.beta(d, 1, 1))) map.template unsew<3>(d);
  });
  return b;
}

// The model elements on the side x > 0.1 of the cut.
bool right_side(const MssModel<3>& m, Index element) { return m.element_centroid(element).x() > 0.1; }

}  // namespace volume_term_test

TEST_CASE("the volume term follows a cut: each stencil on its element's particles, energy and derivatives exact after it") {
  volume_term_test::CutBeam b = volume_term_test::cut_beam();
  MssModel<3>& m = *b.model;
  const solids::VolumePreservation& term = *b.term;
  // the 3x3 points of the cut plane were duplicated
  REQUIRE(m.nodes().num_alive() == b.nodes_before + 9);
  // no stencil refers to a node its element no longer has: each is its element's corners now,
  // and the two pieces share no node
  std::vector<int> side_of_node(m.nodes().size(), -1);
  for (Index e = 0; e < term.size(); ++e) {
    const auto& src = term.source(e);
    REQUIRE(src.element != invalid_index);
    const std::vector<Index> corners = m.element_nodes(src.element);
    const int side = volume_term_test::right_side(m, src.element) ? 1 : 0;
    for (int k = 0; k < 4; ++k) {
      const Index n = term.element_nodes(e)[static_cast<std::size_t>(k)];
      CHECK(n == corners[src.corners[static_cast<std::size_t>(k)]]);
      CHECK(m.nodes().is_alive(n));
      CHECK((side_of_node[n] == -1 || side_of_node[n] == side));
      side_of_node[n] = side;
    }
  }
  // pull the right piece 3 cm away, rigidly: no volume changed, so no energy and no force (a
  // stencil left on the other piece's particles would be stretched across the gap)
  for (Index i = 0; i < m.nodes().size(); ++i)
    if (side_of_node[i] == 1) m.nodes().set_position(i, m.nodes().position(i) + Vector3d(0.03, 0, 0));
  const StateView apart = m.nodes().state();
  CHECK(term.potential_energy(apart) < 1e-20);
  std::vector<double> f(3 * std::size_t{m.nodes().size()}, 0.0);
  term.add_forces(apart, f);
  CHECK(*std::max_element(f.begin(), f.end(), [](double p, double q) { return std::abs(p) < std::abs(q); }) == doctest::Approx(0.0));
  // jiggled: the forces are minus the energy's gradient, the assembled Jacobian the forces'
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.004, 0.004);
  for (Index i = 0; i < m.nodes().size(); ++i) m.nodes().set_position(i, m.nodes().position(i) + Vector3d(u(rng), u(rng), u(rng)));
  std::fill(f.begin(), f.end(), 0.0);
  term.add_forces(m.nodes().state(), f);
  auto x = m.nodes().x();
  double worst = 0, largest = 0;
  for (std::size_t k = 0; k < x.size(); ++k) {
    const double keep = x[k], d = 1e-7;
    x[k] = keep + d;
    const double ep = term.potential_energy(m.nodes().state());
    x[k] = keep - d;
    const double em = term.potential_energy(m.nodes().state());
    x[k] = keep;
    worst = std::max(worst, std::abs(-(ep - em) / (2 * d) - f[k]));
    largest = std::max(largest, std::abs(f[k]));
  }
  CHECK(largest > 0);
  CHECK(worst < 1e-6 * largest);
  const JacobianOptions exact{false, false, false};
  const Eigen::MatrixXd K = test::assembled(m.system(), 1.0, 0.0, exact);
  const Eigen::MatrixXd K_fd = test::finite_difference(m.system(), false, 1e-7);
  CHECK(test::max_abs(K - K_fd) < 1e-5 * test::max_abs(K_fd));
}

}  // namespace test_volume_term
