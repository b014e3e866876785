#include "sewn/physics/rods/static_solve.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <Eigen/SparseCholesky>

#include "sewn/physics/errors.hpp"
#include "../format.hpp"

namespace sewn::physics::rods {

namespace {

using Trips = std::vector<Eigen::Triplet<double>>;

struct MomentFrame {
  Vec3 a, b;
  double psi = 0;  // tracked angle at the last accepted iterate
};

void check_problem(const Rod& rod, const StaticProblem& p) {
  const int n = rod.num_vertices();
  if (!p.fixed.empty() && static_cast<int>(p.fixed.size()) != n)
    throw InputError("rods::solve_static: " + std::to_string(p.fixed.size()) + " fixed masks for " + std::to_string(n) + " vertices");
  if (p.forces.cols() != 0 && (p.forces.cols() != n || !p.forces.allFinite()))
    throw InputError("rods::solve_static: loads must be 3×" + std::to_string(n) + " and finite");
  for (const EdgeMoment& m : p.moments)
    if (m.edge < 0 || m.edge >= rod.num_edges() || !m.axis.allFinite() || !(m.axis.norm() > 0) || !std::isfinite(m.moment))
      throw InputError("rods::solve_static: moment on edge " + std::to_string(m.edge) + " has a bad edge, axis or value");
}

class Potential {
 public:
  Potential(const Rod& rod, const StaticProblem& p, const Points& x) : rod_(rod), p_(p) {
    for (const EdgeMoment& m : p.moments) {
      const Vec3 axis = m.axis.normalized();
      MomentFrame f;
      f.a = any_perpendicular(axis);
      f.b = axis.cross(f.a);
      frames_.push_back(f);
    }
    accept(x);
  }
  // Records the tracked angles at an accepted iterate.
  void accept(const Points& x) {
    for (std::size_t k = 0; k < frames_.size(); ++k) frames_[k].psi = psi(x, k);
  }
  [[nodiscard]] double psi(const Points& x, std::size_t k) const {
    const Vec3 e = edge(x, p_.moments[k].edge);
    return unwrap_angle(std::atan2(e.dot(frames_[k].b), e.dot(frames_[k].a)), frames_[k].psi);
  }
  // Loads' potential, its gradient and (optionally) Hessian, added in rod DOF order.
  double add_loads(const Points& x, Eigen::VectorXd& g, Trips* H) const {
    double V = 0;
    if (p_.forces.cols() != 0)
      for (int i = 0; i < rod_.num_vertices(); ++i) {
        V -= p_.forces.col(i).dot(x.col(i));
        g.segment<3>(3 * i) -= p_.forces.col(i);
      }
    for (std::size_t k = 0; k < frames_.size(); ++k) {
      const EdgeMoment& m = p_.moments[k];
      const Vec3 e = edge(x, m.edge);
      const double u = e.dot(frames_[k].a), w = e.dot(frames_[k].b), r2 = u * u + w * w;
      V -= m.moment * psi(x, k);
      const Vec3 dpsi = (-w * frames_[k].a + u * frames_[k].b) / r2;
      const int i0 = m.edge, i1 = (m.edge + 1) % rod_.num_vertices();
      g.segment<3>(3 * i0) += m.moment * dpsi;
      g.segment<3>(3 * i1) -= m.moment * dpsi;
      if (!H) continue;
      Eigen::Matrix<double, 3, 2> P;
      P << frames_[k].a, frames_[k].b;
      Eigen::Matrix2d H2;
      H2 << 2 * u * w, w * w - u * u, w * w - u * u, -2 * u * w;
      const Eigen::Matrix3d He = -m.moment * P * (H2 / (r2 * r2)) * P.transpose();
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          H->emplace_back(3 * i0 + r, 3 * i0 + c, He(r, c));
          H->emplace_back(3 * i1 + r, 3 * i1 + c, He(r, c));
          H->emplace_back(3 * i0 + r, 3 * i1 + c, -He(r, c));
          H->emplace_back(3 * i1 + r, 3 * i0 + c, -He(r, c));
        }
    }
    return V;
  }

 private:
  [[nodiscard]] Vec3 edge(const Points& x, int j) const { return x.col((j + 1) % rod_.num_vertices()) - x.col(j); }
  const Rod& rod_;
  const StaticProblem& p_;
  std::vector<MomentFrame> frames_;
};

// Rod DOF -> reduced (free) index, or −1.
std::vector<int> free_dofs(const Rod& rod, const StaticProblem& p, int& nf) {
  const int n = rod.num_vertices();
  std::vector<int> map(static_cast<std::size_t>(rod.num_dofs()), -1);
  nf = 0;
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a)
      if (p.fixed.empty() || !(p.fixed[static_cast<std::size_t>(i)] & (1 << a))) map[static_cast<std::size_t>(3 * i + a)] = nf++;
  for (int j = 0; j < rod.num_edges(); ++j)
    if (!rod.theta_fixed(j)) map[static_cast<std::size_t>(3 * n + j)] = nf++;
  return map;
}

Eigen::SparseMatrix<double> reduce(const Trips& full, const std::vector<int>& map, int nf) {
  Trips red;
  red.reserve(full.size());
  for (const auto& t : full) {
    const int r = map[static_cast<std::size_t>(t.row())], c = map[static_cast<std::size_t>(t.col())];
    if (r >= 0 && c >= 0) red.emplace_back(r, c, t.value());
  }
  Eigen::SparseMatrix<double> A(nf, nf);
  A.setFromTriplets(red.begin(), red.end());
  return A;
}

}  // namespace

StaticResult solve_static(Rod& rod, Points& x, const StaticProblem& problem) {
  check_problem(rod, problem);
  const int n = rod.num_vertices(), m = rod.num_edges();
  int nf = 0;
  const std::vector<int> map = free_dofs(rod, problem, nf);
  Potential loads(rod, problem, x);
  double mean_length = 0;
  for (int j = 0; j < m; ++j) mean_length += rod.rest_length(j) / m;
  auto total = [&](const Points& y, Eigen::VectorXd* g, Trips* H) {
    Eigen::VectorXd scratch;
    Eigen::VectorXd& gg = g ? *g : scratch;
    const double E = rod.evaluate(y, gg, H);
    return E + loads.add_loads(y, gg, H);
  };
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  StaticResult res;
  Eigen::VectorXd g;
  Trips H;
  for (int it = 0; it < problem.max_iterations; ++it) {
    H.clear();
    const double Pi = total(x, &g, &H);
    Eigen::VectorXd gr = Eigen::VectorXd::Zero(nf);
    for (int d = 0; d < rod.num_dofs(); ++d)
      if (map[static_cast<std::size_t>(d)] >= 0) gr[map[static_cast<std::size_t>(d)]] = g[d];
    const Eigen::SparseMatrix<double> A = reduce(H, map, nf);
    double diag_max = 0;
    for (int k = 0; k < nf; ++k) diag_max = std::max(diag_max, std::abs(A.coeff(k, k)));
    Eigen::VectorXd step;
    for (double shift = 0; shift < 1e6 * diag_max; shift = std::max(1e-10 * diag_max, 10 * shift)) {
      Eigen::SparseMatrix<double> S = A;
      for (int k = 0; k < nf; ++k) S.coeffRef(k, k) += shift;
      ldlt.compute(S);
      if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0).all()) {
        step = -ldlt.solve(gr);
        break;
      }
    }
    if (step.size() == 0 || !step.allFinite()) throw SolveError("rods::solve_static: the Hessian could not be factored at iteration " + std::to_string(it));
    // Size of the step: positions in mean edge lengths, angles in radians.
    double size = 0, limit = 1;
    for (int d = 0; d < rod.num_dofs(); ++d) {
      const int r = map[static_cast<std::size_t>(d)];
      if (r < 0) continue;
      const bool angle = d >= 3 * n;
      const double s = std::abs(step[r]) / (angle ? 1.0 : mean_length);
      size = std::max(size, s);
      limit = std::min(limit, (angle ? std::numbers::pi / 4 : 0.5) / std::max(s, 1e-300));
    }
    res.iterations = it;
    if (size < problem.tolerance) {
      res.potential = Pi;
      res.energy = rod.energy(x);
      return res;
    }
    const Points x0 = x;
    std::vector<double> th0(rod.theta().begin(), rod.theta().end());
    auto apply = [&](double alpha) {
      for (int d = 0; d < rod.num_dofs(); ++d) {
        const int r = map[static_cast<std::size_t>(d)];
        if (r < 0) continue;
        if (d < 3 * n)
          x(d % 3, d / 3) = x0(d % 3, d / 3) + alpha * step[r];
        else
          rod.set_theta(d - 3 * n, th0[static_cast<std::size_t>(d - 3 * n)] + alpha * step[r]);
      }
    };
    const double slope = gr.dot(step);
    double alpha = std::min(1.0, limit);
    bool accepted = false;
    for (int ls = 0; ls < 50; ++ls, alpha *= 0.5) {
      apply(alpha);
      const double Pt = total(x, nullptr, nullptr);
      if (std::isfinite(Pt) && Pt <= Pi + 1e-4 * alpha * slope + 1e-13 * (std::abs(Pi) + rod.energy(x0))) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      apply(0);
      throw SolveError("rods::solve_static: no descent at iteration " + std::to_string(it) + " (step size " + detail::format_number(size) + ")");
    }
    if (alpha * size < problem.tolerance) {
      res.iterations = it + 1;
      res.potential = total(x, nullptr, nullptr);
      res.energy = rod.energy(x);
      return res;
    }
    rod.update_frames(x);
    loads.accept(x);
  }
  throw SolveError("rods::solve_static: no convergence in " + std::to_string(problem.max_iterations) + " iterations");
}

int unstable_modes(const Rod& rod, const Points& x, const StaticProblem& problem) {
  check_problem(rod, problem);
  int nf = 0;
  const std::vector<int> map = free_dofs(rod, problem, nf);
  Potential loads(rod, problem, x);
  Eigen::VectorXd g;
  Trips H;
  (void)rod.evaluate(x, g, &H);
  (void)loads.add_loads(x, g, &H);
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(reduce(H, map, nf));
  if (ldlt.info() != Eigen::Success) throw SolveError("rods::unstable_modes: the Hessian could not be factored");
  return static_cast<int>((ldlt.vectorD().array() < 0).count());
}

}  // namespace sewn::physics::rods
