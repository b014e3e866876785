#include "sewn/physics/obstacles/obstacles.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"
#include "../format.hpp"

namespace sewn::physics::obstacles {

namespace {

constexpr double smooth_min_power = 8;

// One face's depth d_f > 0 with its gradient and Hessian.
struct Face {
  double d;
  Vec3 g;
  Eigen::Matrix3d H;
};

// p-norm smooth minimum of positive face depths: d = (Σ d_f^(−p))^(−1/p), computed relative to
// the smallest so that nothing overflows; ∇d = Σ w_f g_f with w_f = (d/d_f)^(p+1), and
// ∇²d = (p+1)[∇d∇dᵀ/d − Σ w_f g_f g_fᵀ/d_f] + Σ w_f ∇²d_f.
template <std::size_t K>
Depth smooth_min(const std::array<Face, K>& faces) {
  const double p = smooth_min_power;
  double dmin = faces[0].d;
  for (const Face& f : faces) dmin = std::min(dmin, f.d);
  double S = 0;
  for (const Face& f : faces) S += std::pow(dmin / f.d, p);
  Depth out;
  out.depth = dmin * std::pow(S, -1 / p);
  Eigen::Matrix3d curv = Eigen::Matrix3d::Zero(), outer = Eigen::Matrix3d::Zero();
  for (const Face& f : faces) {
    const double w = std::pow(out.depth / f.d, p + 1);
    out.gradient += w * f.g;
    outer += (w / f.d) * f.g * f.g.transpose();
    curv += w * f.H;
  }
  out.hessian = (p + 1) * (out.gradient * out.gradient.transpose() / out.depth - outer) + curv;
  return out;
}

Depth plane_depth(const Plane& s, const Vec3& x) {
  Depth out;
  const double phi = s.normal.dot(x - s.point);
  if (phi >= 0) return out;
  out.depth = -phi;
  out.gradient = -s.normal;
  return out;
}

Depth sphere_depth(const Sphere& s, const Vec3& x) {
  Depth out;
  const Vec3 r = x - s.center;
  const double rho = r.norm();
  if (rho >= s.radius) return out;
  out.depth = s.radius - rho;
  if (rho < 1e-12 * s.radius) return out;  // the centre: every direction is as deep (gradient 0)
  const Vec3 u = r / rho;
  out.gradient = -u;
  out.hessian = -(Eigen::Matrix3d::Identity() - u * u.transpose()) / rho;
  return out;
}

Depth box_depth(const Box& s, const Vec3& x) {
  const Vec3 y = s.rotation.transpose() * (x - s.center);
  if ((y.cwiseAbs().array() >= s.half_extents.array()).any()) return {};
  std::array<Face, 6> faces;
  for (int a = 0; a < 3; ++a) {
    const Vec3 axis = s.rotation.col(a);
    faces[static_cast<std::size_t>(2 * a)] = {s.half_extents[a] - y[a], -axis, Eigen::Matrix3d::Zero()};
    faces[static_cast<std::size_t>(2 * a + 1)] = {s.half_extents[a] + y[a], axis, Eigen::Matrix3d::Zero()};
  }
  return smooth_min(faces);
}

Depth cone_depth(const Cone& s, const Vec3& x) {
  const Vec3 q = x - s.apex;
  const double h = q.dot(s.axis);
  const Vec3 radial = q - h * s.axis;
  const double r = radial.norm();
  const double sa = std::sin(s.half_angle), ca = std::cos(s.half_angle);
  const double lateral = h * sa - r * ca, base = s.height - h;
  if (!(lateral > 0 && base > 0)) return {};
  Face lat{lateral, sa * s.axis, Eigen::Matrix3d::Zero()};
  if (r > 1e-12 * s.height) {  // off the axis, where r is smooth
    const Vec3 rh = radial / r;
    lat.g -= ca * rh;
    lat.H = -ca * (Eigen::Matrix3d::Identity() - s.axis * s.axis.transpose() - rh * rh.transpose()) / r;
  }
  return smooth_min(std::array<Face, 2>{lat, Face{base, -s.axis, Eigen::Matrix3d::Zero()}});
}

Eigen::Matrix3d project_psd(const Eigen::Matrix3d& H) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(H);
  return es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
}

Vec3 node_vec(std::span<const double> a, Index i) { return {a[3 * i], a[3 * i + 1], a[3 * i + 2]}; }

// Friction force and its velocity Jacobian for normal force λ, coefficient μ, unit normal n.
void friction(const Vec3& v, const Vec3& n, double mu_lambda, double eps, Vec3& F, Eigen::Matrix3d* J) {
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - n * n.transpose();
  const Vec3 vt = P * v;
  const double speed = vt.norm();
  const double y = speed / eps;
  // f1(y)/|v_T| and f1'(y)/ε, with f1(y) = 2y − y² (y < 1), 1 (y ≥ 1).
  const double ratio = y < 1 ? (2 - y) / eps : 1 / speed;
  F = -mu_lambda * ratio * vt;
  if (!J) return;
  if (speed == 0) {
    *J = -mu_lambda * (2 / eps) * P;
    return;
  }
  const Vec3 t = vt / speed;
  const double slope = y < 1 ? (2 - 2 * y) / eps : 0.0;
  *J = -mu_lambda * (slope * t * t.transpose() + ratio * (P - t * t.transpose()));
}

}  // namespace

Depth depth(const Shape& shape, const Vec3& x) {
  return std::visit(
      [&](const auto& s) -> Depth {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Plane>) return plane_depth(s, x);
        if constexpr (std::is_same_v<T, Sphere>) return sphere_depth(s, x);
        if constexpr (std::is_same_v<T, Box>) return box_depth(s, x);
        if constexpr (std::is_same_v<T, Cone>) return cone_depth(s, x);
      },
      shape);
}

std::string_view type_name(const Shape& shape) {
  constexpr std::string_view names[] = {"plane", "sphere", "box", "cone"};
  return names[shape.index()];
}

Obstacles::Obstacles(double stiffness, double friction_velocity) : k_(stiffness), eps_v_(friction_velocity) {
  if (!(std::isfinite(k_) && k_ > 0)) throw InputError("obstacles: stiffness must be finite and > 0 N/m, got " + detail::format_number(k_));
  if (!(std::isfinite(eps_v_) && eps_v_ > 0))
    throw InputError("obstacles: friction velocity must be finite and > 0 m/s, got " + detail::format_number(eps_v_));
}

Index Obstacles::add(const Shape& shape_in) {
  Shape shape = shape_in;
  const std::string who = "obstacles: obstacle " + std::to_string(shapes_.size()) + " (" + std::string(type_name(shape)) + "): ";
  auto unit = [&](Vec3& v, const char* what) {
    if (!v.allFinite() || !(v.norm() > 0)) throw InputError(who + what + " must be finite and non-zero");
    v.normalize();
  };
  auto point = [&](const Vec3& v, const char* what) {
    if (!v.allFinite()) throw InputError(who + what + " must be finite");
  };
  auto positive = [&](double v, const char* what) {
    if (!(std::isfinite(v) && v > 0)) throw InputError(who + what + " must be finite and > 0, got " + detail::format_number(v));
  };
  std::visit(
      [&](auto& s) {
        using T = std::decay_t<decltype(s)>;
        if constexpr (std::is_same_v<T, Plane>) {
          point(s.point, "point");
          unit(s.normal, "normal");
          if (!(std::isfinite(s.friction) && s.friction >= 0)) throw InputError(who + "friction must be finite and >= 0, got " + detail::format_number(s.friction));
        } else if constexpr (std::is_same_v<T, Sphere>) {
          point(s.center, "center");
          positive(s.radius, "radius");
        } else if constexpr (std::is_same_v<T, Box>) {
          point(s.center, "center");
          for (int a = 0; a < 3; ++a) positive(s.half_extents[a], "every half extent");
          if (!s.rotation.allFinite() || (s.rotation.transpose() * s.rotation - Eigen::Matrix3d::Identity()).norm() > 1e-9 ||
              s.rotation.determinant() < 0)
            throw InputError(who + "rotation must be a rotation matrix");
        } else {
          point(s.apex, "apex");
          unit(s.axis, "axis");
          if (!(std::isfinite(s.half_angle) && s.half_angle > 0 && s.half_angle < std::numbers::pi / 2))
            throw InputError(who + "half angle must be in (0, pi/2) rad, got " + detail::format_number(s.half_angle));
          positive(s.height, "height");
        }
      },
      shape);
  shapes_.push_back(shape);
  lambda_known_ = false;
  touch_parameters();
  return static_cast<Index>(shapes_.size() - 1);
}

bool Obstacles::has_friction() const {
  return std::any_of(shapes_.begin(), shapes_.end(), [](const Shape& s) {
    return std::holds_alternative<Plane>(s) && std::get<Plane>(s).friction > 0;
  });
}

void Obstacles::step_accepted(const StateView& s) { refresh_lambda(s); }

void Obstacles::refresh_lambda(const StateView& s) const {
  if (!has_friction()) return;
  lambda_.assign(std::size_t{s.size()} * shapes_.size(), 0.0);
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;
    const Vec3 x = node_vec(s.x, i);
    for (std::size_t o = 0; o < shapes_.size(); ++o)
      if (const Plane* p = std::get_if<Plane>(&shapes_[o]); p && p->friction > 0)
        lambda_[i * shapes_.size() + o] = k_ * plane_depth(*p, x).depth;
  }
  lambda_known_ = true;
}

void Obstacles::ensure_lambda(const StateView& s) const {
  if (lambda_known_ && lambda_.size() == std::size_t{s.size()} * shapes_.size()) return;
  refresh_lambda(s);
}

void Obstacles::add_forces(const StateView& s, std::span<double> f) const {
  const bool fr = has_friction();
  if (fr) ensure_lambda(s);
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;  // removed node
    const Vec3 x = node_vec(s.x, i);
    Vec3 F = Vec3::Zero();
    for (std::size_t o = 0; o < shapes_.size(); ++o) {
      const Depth d = depth(shapes_[o], x);
      F -= k_ * d.depth * d.gradient;
      if (!fr) continue;
      const Plane* p = std::get_if<Plane>(&shapes_[o]);
      const double lam = p ? lambda_[i * shapes_.size() + o] : 0.0;
      if (lam > 0) {
        Vec3 Ff;
        friction(node_vec(s.v, i), p->normal, p->friction * lam, eps_v_, Ff, nullptr);
        F += Ff;
      }
    }
    for (int a = 0; a < 3; ++a) f[3 * i + static_cast<std::size_t>(a)] += F[a];
  }
}

double Obstacles::potential_energy(const StateView& s) const {
  double E = 0;
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;
    const Vec3 x = node_vec(s.x, i);
    for (const Shape& sh : shapes_) {
      const double d = depth(sh, x).depth;
      E += 0.5 * k_ * d * d;
    }
  }
  return E;
}

double Obstacles::dissipation(const StateView& s) const {
  if (!has_friction()) return 0.0;
  ensure_lambda(s);
  double psi = 0;
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;
    const Vec3 v = node_vec(s.v, i);
    for (std::size_t o = 0; o < shapes_.size(); ++o) {
      const Plane* p = std::get_if<Plane>(&shapes_[o]);
      const double lam = p ? lambda_[i * shapes_.size() + o] : 0.0;
      if (!(lam > 0)) continue;
      const double y = (v - p->normal.dot(v) * p->normal).norm() / eps_v_;
      psi += p->friction * lam * eps_v_ * (y < 1 ? y * y - y * y * y / 3 : y - 1.0 / 3);
    }
  }
  return psi;
}

void Obstacles::add_jacobians(const StateView& s, const JacobianRequest& req) const {
  const bool fr = has_friction();
  if (fr) ensure_lambda(s);
  const bool product = !req.product_in.empty();
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;
    const Vec3 x = node_vec(s.x, i);
    Eigen::Matrix3d K = Eigen::Matrix3d::Zero(), C = Eigen::Matrix3d::Zero();
    for (std::size_t o = 0; o < shapes_.size(); ++o) {
      const Depth d = depth(shapes_[o], x);
      if (d.depth > 0) {
        const Eigen::Matrix3d H = k_ * (d.gradient * d.gradient.transpose() + d.depth * d.hessian);
        K -= project_ ? project_psd(H) : H;
      }
      const Plane* p = fr ? std::get_if<Plane>(&shapes_[o]) : nullptr;
      const double lam = p ? lambda_[i * shapes_.size() + o] : 0.0;
      if (lam > 0) {
        Vec3 F;
        Eigen::Matrix3d J;
        friction(node_vec(s.v, i), p->normal, p->friction * lam, eps_v_, F, &J);
        C += J;
      }
    }
    if (req.matrix) req.matrix->block(req.matrix->diagonal(i)) += req.cx * K + req.cv * C;
    if (product) {
      const Vec3 y = K * node_vec(req.product_in, i);
      for (int a = 0; a < 3; ++a) req.product_out[3 * i + static_cast<std::size_t>(a)] += y[a];
    }
  }
}

void Obstacles::add_stability_rows(const StateView& s, StabilityRows& rows) const {
  const bool fr = has_friction();
  if (fr) ensure_lambda(s);
  for (Index i = 0; i < s.size(); ++i) {
    if (s.mass[i] == 0) continue;
    const Vec3 x = node_vec(s.x, i);
    for (std::size_t o = 0; o < shapes_.size(); ++o) {
      const Depth d = depth(shapes_[o], x);
      if (d.depth > 0)
        rows.add_diagonal(StabilityRows::stiffness, i, project_psd(k_ * (d.gradient * d.gradient.transpose() + d.depth * d.hessian)));
      const Plane* p = fr ? std::get_if<Plane>(&shapes_[o]) : nullptr;
      const double lam = p ? lambda_[i * shapes_.size() + o] : 0.0;
      if (lam > 0) rows.add_diagonal(StabilityRows::damping, i, Eigen::Matrix3d::Identity() * (2 * p->friction * lam / eps_v_));
    }
  }
}

void Obstacles::remap_nodes(std::span<const Index> old_to_new) {
  if (lambda_.empty()) return;
  std::vector<double> moved(lambda_.size(), 0.0);
  const std::size_t no = shapes_.size();
  Index alive = 0;
  for (std::size_t i = 0; i < old_to_new.size() && (i + 1) * no <= lambda_.size(); ++i)
    if (old_to_new[i] != invalid_index) {
      alive = std::max(alive, old_to_new[i] + 1);
      for (std::size_t o = 0; o < no; ++o) moved[old_to_new[i] * no + o] = lambda_[i * no + o];
    }
  moved.resize(std::size_t{alive} * no);
  lambda_ = std::move(moved);
}

}  // namespace sewn::physics::obstacles
