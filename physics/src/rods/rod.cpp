#include "sewn/physics/rods/rod.hpp"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <Eigen/SparseCholesky>

#include "sewn/physics/errors.hpp"
#include "../format.hpp"

namespace sewn::physics::rods {

namespace {

// LDLᵀ solve of (T + shift·I) p = −g for a tridiagonal T (diagonal `diag`, `sub[k]` coupling
// k and k+1). False if a pivot is not positive (the shifted matrix is not positive definite).
bool tridiagonal_descent(const std::vector<double>& diag, const std::vector<double>& sub, const Eigen::VectorXd& g,
                         double shift, Eigen::VectorXd& step) {
  const std::size_t n = diag.size();
  std::vector<double> d(n), l(n, 0.0);
  step.resize(static_cast<Eigen::Index>(n));
  for (std::size_t k = 0; k < n; ++k) {
    d[k] = diag[k] + shift - (k > 0 ? l[k - 1] * sub[k - 1] : 0.0);
    if (!(d[k] > 0)) return false;
    if (k + 1 < n) l[k] = sub[k] / d[k];
    step[static_cast<Eigen::Index>(k)] = -g[static_cast<Eigen::Index>(k)] - (k > 0 ? l[k - 1] * step[static_cast<Eigen::Index>(k - 1)] : 0.0);
  }
  for (std::size_t k = n; k-- > 0;) {
    step[static_cast<Eigen::Index>(k)] /= d[k];
    if (k + 1 < n) step[static_cast<Eigen::Index>(k)] -= l[k] * step[static_cast<Eigen::Index>(k + 1)];
  }
  return true;
}

}  // namespace

Rod::Rod(const Points& rest, bool closed, const Section& section, std::span<const Vec3> rest_directors)
    : closed_(closed), section_(section) {
  const int n = static_cast<int>(rest.cols());
  if (n < (closed ? 3 : 2))
    throw InputError("rods::Rod: " + std::string(closed ? "a closed" : "an open") + " rod needs at least " +
                     (closed ? "3" : "2") + " vertices, got " + std::to_string(n));
  if (!rest.allFinite()) throw InputError("rods::Rod: a rest position is not finite");
  const int m = closed ? n : n - 1;
  if (!rest_directors.empty() && static_cast<int>(rest_directors.size()) != m)
    throw InputError("rods::Rod: " + std::to_string(rest_directors.size()) + " rest directors given for " +
                     std::to_string(m) + " edges");
  rest_length_.resize(static_cast<std::size_t>(m));
  tangent_.resize(static_cast<std::size_t>(m));
  director_.resize(static_cast<std::size_t>(m));
  theta_.assign(static_cast<std::size_t>(m), 0.0);
  theta_fixed_.assign(static_cast<std::size_t>(m), 0);
  for (int j = 0; j < m; ++j) {
    const Vec3 e = rest.col((j + 1) % n) - rest.col(j);
    const double l = e.norm();
    if (!(l > 0)) throw InputError("rods::Rod: edge " + std::to_string(j) + " has zero rest length");
    rest_length_[static_cast<std::size_t>(j)] = l;
    tangent_[static_cast<std::size_t>(j)] = e / l;
  }
  // Space-parallel reference frames along the rest shape.
  auto project = [&](const Vec3& d, int j) -> Vec3 {
    const Vec3& t = tangent_[static_cast<std::size_t>(j)];
    const Vec3 p = d - d.dot(t) * t;
    if (!(p.norm() > 1e-9 * d.norm()) || !d.allFinite())
      throw InputError("rods::Rod: the rest director of edge " + std::to_string(j) + " is zero, not finite or parallel to its edge");
    return p.normalized();
  };
  director_[0] = rest_directors.empty() ? any_perpendicular(tangent_[0]) : project(rest_directors[0], 0);
  for (int j = 1; j < m; ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    if (1 + tangent_[k - 1].dot(tangent_[k]) < 1e-8)
      throw InputError("rods::Rod: the rest shape folds back on itself at vertex " + std::to_string(j));
    director_[k] = parallel_transport(tangent_[k - 1], tangent_[k], director_[k - 1]);
  }
  if (!rest_directors.empty())
    for (int j = 0; j < m; ++j) {
      const std::size_t k = static_cast<std::size_t>(j);
      theta_[k] = signed_angle(director_[k], project(rest_directors[k], j), tangent_[k]);
    }
  // Stencils with the rest state's curvatures and twist as their natural values.
  const int ns = closed ? n : n - 2;
  stencils_.resize(static_cast<std::size_t>(std::max(ns, 0)));
  for (int s = 0; s < ns; ++s) {
    const auto [e0, e1] = stencil_edges(s);
    if (1 + tangent_[static_cast<std::size_t>(e0)].dot(tangent_[static_cast<std::size_t>(e1)]) < 1e-8)
      throw InputError("rods::Rod: the rest shape folds back on itself at vertex " + std::to_string(stencil_vertices(s)[1]));
    Stencil& st = stencils_[static_cast<std::size_t>(s)];
    refresh_stencil_frames(s);
    const auto [v0, v1, v2] = stencil_vertices(s);
    st.frames.reference_twist = 0;  // the raw value, in (−π, π]
    const MaterialStrains ms = material_strains(rest.col(v0), rest.col(v1), rest.col(v2), theta_[static_cast<std::size_t>(e0)],
                                                theta_[static_cast<std::size_t>(e1)], st.frames);
    st.frames.reference_twist = ms.reference_twist;
    st.rest.kappa1 = ms.kappa1;
    st.rest.kappa2 = ms.kappa2;
    st.rest.twist = ms.twist;
    st.rest.voronoi = 0.5 * (rest_length_[static_cast<std::size_t>(e0)] + rest_length_[static_cast<std::size_t>(e1)]);
    st.rest.EI1 = section.EI1;
    st.rest.EI2 = section.EI2;
    st.rest.GJ = section.GJ;
  }
}

std::array<int, 3> Rod::stencil_vertices(int s) const {
  const int n = num_vertices();
  if (closed_) return {(s + n - 1) % n, s, (s + 1) % n};
  return {s, s + 1, s + 2};
}

std::array<int, 2> Rod::stencil_edges(int s) const {
  const int m = num_edges();
  if (closed_) return {(s + m - 1) % m, s};
  return {s, s + 1};
}

void Rod::refresh_stencil_frames(int s) {
  const auto [e0, e1] = stencil_edges(s);
  BendTwistFrames& f = stencils_[static_cast<std::size_t>(s)].frames;
  f.tangent0 = tangent_[static_cast<std::size_t>(e0)];
  f.director0 = director_[static_cast<std::size_t>(e0)];
  f.tangent1 = tangent_[static_cast<std::size_t>(e1)];
  f.director1 = director_[static_cast<std::size_t>(e1)];
}

void Rod::set_natural_strains(int s, double kappa1, double kappa2, double twist) {
  if (s < 0 || s >= num_stencils() || !std::isfinite(kappa1) || !std::isfinite(kappa2) || !std::isfinite(twist))
    throw InputError("rods::Rod::set_natural_strains: stencil " + std::to_string(s) + " of " +
                     std::to_string(num_stencils()) + ", values " + detail::format_number(kappa1) + ", " + detail::format_number(kappa2) + ", " + detail::format_number(twist));
  BendTwistRest& r = stencils_[static_cast<std::size_t>(s)].rest;
  r.kappa1 = kappa1;
  r.kappa2 = kappa2;
  r.twist = twist;
}

void Rod::set_theta(int edge, double value) {
  if (edge < 0 || edge >= num_edges() || !std::isfinite(value))
    throw InputError("rods::Rod::set_theta: edge " + std::to_string(edge) + " of " + std::to_string(num_edges()) +
                     ", value " + detail::format_number(value));
  theta_[static_cast<std::size_t>(edge)] = value;
}

void Rod::fix_theta(int edge, bool fixed) {
  if (edge < 0 || edge >= num_edges())
    throw InputError("rods::Rod::fix_theta: edge " + std::to_string(edge) + " out of range (" + std::to_string(num_edges()) + " edges)");
  theta_fixed_[static_cast<std::size_t>(edge)] = fixed ? 1 : 0;
}

BendTwistEval Rod::eval_stencil(const Points& x, int s, Want want) const {
  const auto [v0, v1, v2] = stencil_vertices(s);
  const auto [e0, e1] = stencil_edges(s);
  const Stencil& st = stencils_[static_cast<std::size_t>(s)];
  return bend_twist(x.col(v0), x.col(v1), x.col(v2), theta_[static_cast<std::size_t>(e0)],
                    theta_[static_cast<std::size_t>(e1)], st.rest, st.frames, want);
}

double Rod::energy(const Points& x) const {
  double E = 0;
  const int n = num_vertices();
  for (int j = 0; j < num_edges(); ++j)
    E += stretch(x.col(j), x.col((j + 1) % n), section_.EA, rest_length_[static_cast<std::size_t>(j)], false).energy;
  for (int s = 0; s < num_stencils(); ++s) E += eval_stencil(x, s, Want::energy).energy;
  return E;
}

double Rod::evaluate(const Points& x, Eigen::VectorXd& g, std::vector<Eigen::Triplet<double>>* H) const {
  const int n = num_vertices();
  g.setZero(num_dofs());
  double E = 0;
  for (int j = 0; j < num_edges(); ++j) {
    const int a = j, b = (j + 1) % n;
    const StretchEval s = stretch(x.col(a), x.col(b), section_.EA, rest_length_[static_cast<std::size_t>(j)], H != nullptr);
    E += s.energy;
    g.segment<3>(3 * a) += s.gradient.head<3>();
    g.segment<3>(3 * b) += s.gradient.tail<3>();
    if (H)
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c)
          H->emplace_back(3 * (r < 3 ? a : b) + r % 3, 3 * (c < 3 ? a : b) + c % 3, s.hessian(r, c));
  }
  for (int s = 0; s < num_stencils(); ++s) {
    const BendTwistEval b = eval_stencil(x, s, H ? Want::hessian : Want::gradient);
    E += b.energy;
    const auto v = stencil_vertices(s);
    const auto e = stencil_edges(s);
    int dof[11];
    for (int k = 0; k < 9; ++k) dof[k] = 3 * v[static_cast<std::size_t>(k / 3)] + k % 3;
    dof[9] = 3 * n + e[0];
    dof[10] = 3 * n + e[1];
    for (int k = 0; k < 11; ++k) g[dof[k]] += b.gradient[k];
    if (H)
      for (int r = 0; r < 11; ++r)
        for (int c = 0; c < 11; ++c) H->emplace_back(dof[r], dof[c], b.hessian(r, c));
  }
  return E;
}

int Rod::solve_twist(const Points& x, std::span<const unsigned char> held) {
  const int m = num_edges();
  if (!held.empty() && held.size() != theta_.size())
    throw InputError("rods::Rod::solve_twist: " + std::to_string(held.size()) + " held flags for " + std::to_string(m) + " edges");
  std::vector<int> free_index(static_cast<std::size_t>(m), -1);
  int nf = 0;
  for (int j = 0; j < m; ++j) {
    const auto k = static_cast<std::size_t>(j);
    if (!theta_fixed_[k] && (held.empty() || !held[k])) free_index[k] = nf++;
  }
  if (nf == 0 || num_stencils() == 0) return 0;
  // With no angle held and an energy that turning every angle together leaves unchanged, the
  // θ block is singular along (1, ..., 1): the exact gradient has no component there, but its
  // round-off does, and a solve through the tiny shift below would turn that into a step of
  // any size along it. Newton then wanders along the free direction without converging. The
  // solve is kept orthogonal to it instead: the angles' mean stays where it was.
  const bool gauge = nf == m && turns_freely();
  auto theta_energy = [&] {
    double E = 0;
    for (int s = 0; s < num_stencils(); ++s) E += eval_stencil(x, s, Want::energy).energy;
    return E;
  };
  // Open rods: the free angles' Hessian is tridiagonal in their order (a Thomas solve); closed
  // rods add one corner pair, solved by a sparse LDLᵀ.
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> ldlt;
  std::vector<Eigen::Triplet<double>> trips;
  std::vector<double> diag(static_cast<std::size_t>(nf)), sub(static_cast<std::size_t>(std::max(nf - 1, 0)));
  Eigen::VectorXd g(nf);
  double E = theta_energy();
  for (int it = 0; it < 100; ++it) {
    g.setZero();
    trips.clear();
    std::fill(diag.begin(), diag.end(), 0.0);
    std::fill(sub.begin(), sub.end(), 0.0);
    double diag_max = 0;
    for (int s = 0; s < num_stencils(); ++s) {
      const BendTwistEval b = eval_stencil(x, s, Want::angle_hessian);
      const auto e = stencil_edges(s);
      for (int r = 0; r < 2; ++r) {
        const int fr = free_index[static_cast<std::size_t>(e[static_cast<std::size_t>(r)])];
        if (fr < 0) continue;
        g[fr] += b.gradient[9 + r];
        for (int c = 0; c < 2; ++c) {
          const int fc = free_index[static_cast<std::size_t>(e[static_cast<std::size_t>(c)])];
          if (fc < 0) continue;
          const double h = b.hessian(9 + r, 9 + c);
          if (closed_)
            trips.emplace_back(fr, fc, h);
          else if (fr == fc)
            diag[static_cast<std::size_t>(fr)] += h;
          else if (fc == fr + 1)
            sub[static_cast<std::size_t>(fr)] += h;
          if (r == c) diag_max = std::max(diag_max, h);
        }
      }
    }
    if (gauge) g.array() -= g.mean();
    // The θ block is PSD for twist alone and may lose definiteness where bending couples in;
    // a shift that grows until the factorisation is positive keeps every step a descent step.
    Eigen::SparseMatrix<double> A(nf, nf);
    if (closed_) A.setFromTriplets(trips.begin(), trips.end());
    Eigen::VectorXd step;
    double shift = 1e-12 * std::max(diag_max, 1e-300);
    for (int attempt = 0; attempt < 40; ++attempt, shift *= 10) {
      if (!closed_) {
        if (tridiagonal_descent(diag, sub, g, shift, step)) break;
        step.resize(0);
        continue;
      }
      Eigen::SparseMatrix<double> S = A;
      for (int k = 0; k < nf; ++k) S.coeffRef(k, k) += shift;
      ldlt.compute(S);
      if (ldlt.info() == Eigen::Success && (ldlt.vectorD().array() > 0).all()) {
        step = -ldlt.solve(g);
        break;
      }
    }
    if (step.size() == 0 || !step.allFinite()) throw SolveError("rods::Rod::solve_twist: the twist Hessian could not be factored");
    if (gauge) step.array() -= step.mean();
    if (step.lpNorm<Eigen::Infinity>() < 1e-13) return it;
    // Armijo backtracking; steps limited to π/4 per edge so no angle aliases.
    double alpha = std::min(1.0, (std::numbers::pi / 4) / step.lpNorm<Eigen::Infinity>());
    const std::vector<double> start = theta_;
    const double slope = g.dot(step);
    bool accepted = false;
    for (int ls = 0; ls < 40; ++ls, alpha *= 0.5) {
      for (int j = 0; j < m; ++j)
        if (free_index[static_cast<std::size_t>(j)] >= 0)
          theta_[static_cast<std::size_t>(j)] = start[static_cast<std::size_t>(j)] + alpha * step[free_index[static_cast<std::size_t>(j)]];
      const double Et = theta_energy();
      // Compare with a round-off allowance: near the minimum the decrease is below the
      // energy's rounding error and Newton's step is then accepted on its own size.
      if (Et <= E + 1e-4 * alpha * slope + 1e-14 * std::abs(E)) {
        E = Et;
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      theta_ = start;
      if (step.lpNorm<Eigen::Infinity>() < 1e-8) return it;
      throw SolveError("rods::Rod::solve_twist: no descent along the Newton direction (|step| = " +
                       detail::format_number(step.lpNorm<Eigen::Infinity>()) + " rad)");
    }
    if (alpha * step.lpNorm<Eigen::Infinity>() < 1e-13) return it + 1;
  }
  throw SolveError("rods::Rod::solve_twist: no convergence in 100 Newton iterations");
}

bool Rod::turns_freely() const {
  // the same bound the rest curvatures of a straight rod built from mesh points stay under
  constexpr double straight = 1e-12;
  for (const Stencil& st : stencils_)
    if (st.rest.EI1 != st.rest.EI2 || std::abs(st.rest.kappa1) > straight || std::abs(st.rest.kappa2) > straight) return false;
  return true;
}

void Rod::update_frames(const Points& x) {
  const int n = num_vertices();
  std::vector<double> mref(stencils_.size());
  for (int s = 0; s < num_stencils(); ++s) mref[static_cast<std::size_t>(s)] = reference_twist(x, s);
  for (int j = 0; j < num_edges(); ++j) {
    const std::size_t k = static_cast<std::size_t>(j);
    const Vec3 t = (x.col((j + 1) % n) - x.col(j)).normalized();
    director_[k] = parallel_transport(tangent_[k], t, director_[k]);
    // Re-orthonormalise against drift over many steps.
    director_[k] = (director_[k] - director_[k].dot(t) * t).normalized();
    tangent_[k] = t;
  }
  for (int s = 0; s < num_stencils(); ++s) {
    refresh_stencil_frames(s);
    stencils_[static_cast<std::size_t>(s)].frames.reference_twist = mref[static_cast<std::size_t>(s)];
  }
}

Rod::State Rod::state() const {
  State s{theta_, tangent_, director_, {}};
  for (const Stencil& st : stencils_) s.reference_twist.push_back(st.frames.reference_twist);
  return s;
}

void Rod::restore(const State& s) {
  const std::size_t m = theta_.size();
  if (s.theta.size() != m || s.tangent.size() != m || s.director.size() != m || s.reference_twist.size() != stencils_.size())
    throw InputError("rods::Rod::restore: a state of " + std::to_string(s.theta.size()) + " angles, " + std::to_string(s.tangent.size()) +
                     " tangents, " + std::to_string(s.director.size()) + " directors and " + std::to_string(s.reference_twist.size()) +
                     " reference twists, for a rod of " + std::to_string(m) + " edges and " + std::to_string(stencils_.size()) + " stencils");
  for (std::size_t k = 0; k < m; ++k)
    if (!std::isfinite(s.theta[k]) || !s.tangent[k].allFinite() || !s.director[k].allFinite())
      throw InputError("rods::Rod::restore: edge " + std::to_string(k) + "'s angle or frame is not finite");
  for (std::size_t k = 0; k < stencils_.size(); ++k)
    if (!std::isfinite(s.reference_twist[k]))
      throw InputError("rods::Rod::restore: stencil " + std::to_string(k) + "'s reference twist is not finite");
  theta_ = s.theta;
  tangent_ = s.tangent;
  director_ = s.director;
  for (int k = 0; k < num_stencils(); ++k) {
    refresh_stencil_frames(k);
    stencils_[static_cast<std::size_t>(k)].frames.reference_twist = s.reference_twist[static_cast<std::size_t>(k)];
  }
}

Vec3 Rod::reference_director(const Points& x, int edge) const {
  const std::size_t k = static_cast<std::size_t>(edge);
  const Vec3 t = (x.col((edge + 1) % num_vertices()) - x.col(edge)).normalized();
  return parallel_transport(tangent_[k], t, director_[k]);
}

std::pair<Vec3, Vec3> Rod::material_directors(const Points& x, int edge) const {
  const Vec3 t = (x.col((edge + 1) % num_vertices()) - x.col(edge)).normalized();
  const Vec3 a1 = reference_director(x, edge), a2 = t.cross(a1);
  const double th = theta_[static_cast<std::size_t>(edge)];
  return {std::cos(th) * a1 + std::sin(th) * a2, -std::sin(th) * a1 + std::cos(th) * a2};
}

double Rod::reference_twist(const Points& x, int s) const { return eval_stencil(x, s, Want::energy).reference_twist; }

}  // namespace sewn::physics::rods
