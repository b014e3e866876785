// A rod split in two at a vertex and rejoined by a point connection with k_t = GJ/D, k_b = EI/D
// (D the Voronoi length of the joint) must twist exactly like the unsplit rod (the twist is
// solved over both halves' material angles and compared with the unsplit rod's own twist
// solve), and bend like it up to the difference of the two discrete curvature measures
// (the rod's 2 tan(φ/2), the connection's φ), which vanishes under refinement.

#include <cmath>
#include <vector>

#include <doctest/doctest.h>
#include <Eigen/Dense>

#include "sewn/connect/point.hpp"

namespace test_split_rod {

using namespace sewn;
using namespace sewn::connect;
using physics::rods::Points;
using physics::rods::Rod;
using physics::rods::Section;

namespace {

// A straight rod along x with uneven edges (lengths 0.1·(1 + 0.3 sin j)).
Points straight_rod(int n) {
  Points x(3, n);
  double s = 0;
  for (int j = 0; j < n; ++j) {
    x.col(j) = Eigen::Vector3d(s, 0, 0);
    s += 0.1 * (1 + 0.3 * std::sin(j));
  }
  return x;
}

struct SplitRod {
  Rod a, b;
  Points xa, xb;
  PointConnection joint;
  int k;  // the split vertex: a holds vertices 0..k, b holds k..n-1 (node ids k.. with offset k)

  static PointConnection make_joint(const Rod& a, const Points& xa, const Rod& b, const Points& xb, int k,
                                    const Section& sec) {
    const RodEdgeSide ea = rod_edge_side(a, xa, a.num_edges() - 1);
    const RodEdgeSide eb = rod_edge_side(b, xb, 0, static_cast<Index>(k));
    const double voronoi = 0.5 * (a.rest_length(a.num_edges() - 1) + b.rest_length(0));
    return PointConnection("split", ea, eb, {sec.GJ / voronoi, sec.EI1 / voronoi}, gather(xa, xb, a, b));
  }
  static Eigen::VectorXd gather(const Points& xa, const Points& xb, const Rod& a, const Rod& b) {
    Eigen::VectorXd q(14);
    const int la = static_cast<int>(xa.cols()) - 1;
    q.segment<3>(0) = xa.col(la - 1);
    q.segment<3>(3) = xa.col(la);
    q[6] = a.theta()[static_cast<std::size_t>(a.num_edges() - 1)];
    q.segment<3>(7) = xb.col(0);
    q.segment<3>(10) = xb.col(1);
    q[13] = b.theta()[0];
    return q;
  }
  SplitRod(const Points& x, int split, const Section& sec)
      : a(x.leftCols(split + 1), false, sec),
        b(x.rightCols(x.cols() - split), false, sec),
        xa(x.leftCols(split + 1)),
        xb(x.rightCols(x.cols() - split)),
        joint(make_joint(a, xa, b, xb, split, sec)),
        k(split) {}

  // Moves the split rod to the whole rod's positions x (the joint's two copies together).
  void move(const Points& x) {
    xa = x.leftCols(k + 1);
    xb = x.rightCols(x.cols() - k);
  }
  int num_theta() const { return a.num_edges() + b.num_edges(); }
  void set_theta(const Eigen::VectorXd& th) {
    for (int j = 0; j < a.num_edges(); ++j) a.set_theta(j, th[j]);
    for (int j = 0; j < b.num_edges(); ++j) b.set_theta(j, th[a.num_edges() + j]);
  }
  // Total energy and its gradient over all material angles (a's, then b's).
  double energy_and_gradient(Eigen::VectorXd& g) {
    Eigen::VectorXd ga, gb;
    double e = a.evaluate(xa, ga, nullptr) + b.evaluate(xb, gb, nullptr);
    const PointEval c = joint.evaluate(gather(xa, xb, a, b), TwistUpdate::incremental_ii, true);
    g.resize(num_theta());
    g.head(a.num_edges()) = ga.tail(a.num_edges());
    g.tail(b.num_edges()) = gb.tail(b.num_edges());
    g[a.num_edges() - 1] += c.gradient[6];
    g[a.num_edges()] += c.gradient[13];
    return e + c.energy;
  }
};

}  // namespace

TEST_CASE("a rod split by a point connection with k_t = GJ/D twists like the unsplit rod") {
  const Section sec = Section::circular(1e7, 0.3, 0.01);
  const int n = 13;
  const Points x = straight_rod(n);
  const double phi = 4.0;  // past π: the connection's increment is what counts, not the total

  Rod whole(x, false, sec);
  whole.set_theta(whole.num_edges() - 1, phi);
  whole.fix_theta(0);
  whole.fix_theta(whole.num_edges() - 1);
  (void)whole.solve_twist(x);
  const double e_whole = whole.energy(x);

  for (int split : {3, 6, 9}) {
    CAPTURE(split);
    SplitRod s(x, split, sec);
    const int m = s.num_theta();
    // Newton on the angles (the energy is quadratic in θ for a straight rod; Hessian by
    // central differences of the exact gradient), ends held at 0 and φ.
    Eigen::VectorXd th = Eigen::VectorXd::Zero(m);
    th[m - 1] = phi;
    std::vector<int> free;
    for (int j = 1; j < m - 1; ++j) free.push_back(j);
    Eigen::VectorXd g;
    for (int it = 0; it < 3; ++it) {
      s.set_theta(th);
      (void)s.energy_and_gradient(g);
      Eigen::MatrixXd H(free.size(), free.size());
      for (std::size_t c = 0; c < free.size(); ++c) {
        Eigen::VectorXd tp = th, tm = th, gp, gm;
        tp[free[c]] += 1e-5;
        tm[free[c]] -= 1e-5;
        s.set_theta(tp);
        (void)s.energy_and_gradient(gp);
        s.set_theta(tm);
        (void)s.energy_and_gradient(gm);
        for (std::size_t r = 0; r < free.size(); ++r) H(r, c) = (gp[free[r]] - gm[free[r]]) / 2e-5;
      }
      Eigen::VectorXd gf(free.size());
      for (std::size_t r = 0; r < free.size(); ++r) gf[r] = g[free[r]];
      const Eigen::VectorXd step = H.ldlt().solve(gf);
      for (std::size_t r = 0; r < free.size(); ++r) th[free[r]] -= step[r];
    }
    s.set_theta(th);
    const double e_split = s.energy_and_gradient(g);
    double g_free = 0;
    for (int j : free) g_free = std::max(g_free, std::abs(g[j]));
    CHECK(g_free < 1e-8 * sec.GJ);
    CHECK(e_split == doctest::Approx(e_whole).epsilon(1e-9));
    // Angle per edge: the split rod's a-edges then b-edges are the whole rod's edges in order.
    for (int j = 0; j < m; ++j) CHECK(th[j] == doctest::Approx(whole.theta()[static_cast<std::size_t>(j)]).epsilon(1e-9));
  }
  // The closed form for a straight rod: E = GJ φ² / (2 Σ D_i) over the interior vertices.
  double sum_d = 0;
  for (int i = 1; i + 1 < n; ++i) sum_d += 0.5 * ((x.col(i) - x.col(i - 1)).norm() + (x.col(i + 1) - x.col(i)).norm());
  CHECK(e_whole == doctest::Approx(sec.GJ * phi * phi / (2 * sum_d)).epsilon(1e-9));
}

TEST_CASE("a rod split by a point connection with k_b = EI/D bends like the unsplit rod, converging under refinement") {
  // A straight rod bent into a circular arc (radius 1, angle 1.5 rad) in the plane ⟂ its
  // directors, split at its middle vertex: the joint's bending is ½(EI/D)φ² against the rod's
  // ½(EI/D)(2 tan(φ/2))², φ the turning angle h/R, a relative difference ~φ²/6 in one of n
  // terms: the total energies agree to O(n^-3).
  const Section sec = Section::circular(1e7, 0.3, 0.01);
  double previous = 0;
  for (int n : {9, 17, 33}) {
    CAPTURE(n);
    const double arc = 1.5;
    Points rest(3, n), bent(3, n);
    for (int j = 0; j < n; ++j) {
      const double s = arc * j / (n - 1);
      rest.col(j) = Eigen::Vector3d(s, 0, 0);
      bent.col(j) = Eigen::Vector3d(std::sin(s), 1 - std::cos(s), 0);
    }
    const std::vector<Eigen::Vector3d> up(static_cast<std::size_t>(n - 1), Eigen::Vector3d(0, 0, 1));
    Rod whole(rest, false, sec, up);
    const double e_whole = whole.energy(bent);
    SplitRod s(rest, (n - 1) / 2, sec);
    s.move(bent);
    Eigen::VectorXd g;
    const double e_split = s.energy_and_gradient(g);
    const double rel = std::abs(e_split - e_whole) / e_whole;
    const double phi = arc / (n - 1);
    // The difference in closed form: only the joint vertex differs, by ½(EI/D)(φ² − 4 tan²(φ/2)).
    const double D = phi;  // the joint's rest Voronoi length: both rest edges are arc/(n−1) = φ
    const double expected = 0.5 * sec.EI1 / D * (phi * phi - 4 * std::tan(phi / 2) * std::tan(phi / 2));
    INFO("relative difference " << rel);
    CHECK(e_whole > 0);
    CHECK((e_split - e_whole) == doctest::Approx(expected).epsilon(1e-6));
    if (previous > 0) CHECK(rel < previous / 6);  // ~ n^-3: halving h divides it by ~8
    previous = rel;
  }
}

}  // namespace test_split_rod
