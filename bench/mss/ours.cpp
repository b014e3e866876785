#include "ours.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sewn/physics/mss_model.hpp"

namespace sewn::bench::mss {

using physics::Index;

// The library's mass-spring system living on the combinatorial map (physics::MssModel<3>): the
// map's attributes name the particles and springs, which live in a physics::System stepped by
// the library's integrators. The suite fixes the clamped points on its node table.
struct Ours::Impl {
  std::unique_ptr<physics::MssModel<3>> model;
  std::vector<Index> node_of_point;
  std::vector<double> saved_x, saved_v;
  physics::System& sys;
  physics::Springs* springs;

  explicit Impl(const ModelSpec& spec) : model(build(spec)), sys(model->system()), springs(&model->springs()) {
    for (std::uint32_t p = 0; p < spec.mesh.num_points(); ++p) node_of_point.push_back(model->node_of_point(p));
    for (std::uint32_t p = 0; p < spec.fixed.size(); ++p)
      if (spec.fixed[p] != 0) sys.nodes().fix(node_of_point[p]);
    sys.refresh();
  }

  static std::unique_ptr<physics::MssModel<3>> build(const ModelSpec& spec) {
    physics::MaterialParams material;
    material.young = spec.material.young;
    material.poisson = spec.material.poisson;
    material.density = spec.material.density;
    physics::MssOptions options;
    options.damping = physics::DampingModel::viscous;  // the seed's per-spring viscosity
    options.environment = spec.environment;
    options.gravity = Eigen::Vector3d(spec.gravity[0], spec.gravity[1], spec.gravity[2]);
    options.source = spec.name;
    return std::make_unique<physics::MssModel<3>>(spec.mesh, std::vector<physics::MaterialParams>{material},
                                                  std::vector<std::uint32_t>{}, options);
  }
};

const char* Ours::builder() { return "physics::MssModel<3> (the system built on the combinatorial map)"; }

Ours::Ours(const ModelSpec& spec) : impl_(std::make_unique<Impl>(spec)) { save(); }
Ours::~Ours() = default;

const physics::MssModel<3>& Ours::model() const { return *impl_->model; }
physics::MssModel<3>& Ours::model() { return *impl_->model; }

physics::System& Ours::system() { return impl_->sys; }
Index Ours::node(std::uint32_t p) const { return impl_->node_of_point[p]; }

Counts Ours::counts() const {
  return {impl_->sys.nodes().num_alive(), impl_->springs->num_alive()};
}

void Ours::set_state(const State& s) {
  physics::NodeTable& nodes = impl_->sys.nodes();
  for (std::uint32_t p = 0; p < impl_->node_of_point.size(); ++p) {
    const Index n = impl_->node_of_point[p];
    nodes.set_position(n, {s.x[3 * p], s.x[3 * p + 1], s.x[3 * p + 2]});
    // set_velocity on a fixed axis prescribes a motion: keep fixed points at rest
    if (nodes.fixed(n) == 0) nodes.set_velocity(n, {s.v[3 * p], s.v[3 * p + 1], s.v[3 * p + 2]});
  }
}

State Ours::state() const {
  const physics::NodeTable& nodes = impl_->sys.nodes();
  State s;
  for (const Index n : impl_->node_of_point) {
    const Eigen::Vector3d x = nodes.position(n), v = nodes.velocity(n);
    s.x.insert(s.x.end(), {x[0], x[1], x[2]});
    s.v.insert(s.v.end(), {v[0], v[1], v[2]});
  }
  return s;
}

void Ours::save() {
  const physics::NodeTable& nodes = impl_->sys.nodes();
  impl_->saved_x.assign(nodes.x().begin(), nodes.x().end());
  impl_->saved_v.assign(nodes.v().begin(), nodes.v().end());
}

void Ours::restore() {
  physics::NodeTable& nodes = impl_->sys.nodes();
  std::copy(impl_->saved_x.begin(), impl_->saved_x.end(), nodes.x().begin());
  std::copy(impl_->saved_v.begin(), impl_->saved_v.end(), nodes.v().begin());
}

std::vector<double> Ours::forces() {
  impl_->sys.compute_forces();
  const physics::NodeTable& nodes = impl_->sys.nodes();
  std::vector<double> f;
  for (const Index n : impl_->node_of_point) {
    const Eigen::Vector3d fn = nodes.force(n);
    f.insert(f.end(), {fn[0], fn[1], fn[2]});
  }
  return f;
}

std::vector<double> Ours::masses() const {
  std::vector<double> m;
  for (const Index n : impl_->node_of_point) m.push_back(impl_->sys.nodes().mass(n));
  return m;
}

LinearSystemSample Ours::linear_system(double h, std::span<const double> p) {
  physics::System& sys = impl_->sys;
  physics::NodeTable& nodes = sys.nodes();
  sys.compute_forces();
  const std::size_t n3 = nodes.x().size();
  // The assembly of LinearlyImplicitEuler::step, with its default JacobianOptions.
  physics::BlockMatrix& A = sys.matrix();
  A.set_zero();
  std::vector<double> kv(n3, 0.0), pn(n3, 0.0), q(n3, 0.0);
  physics::JacobianRequest req;
  req.matrix = &A;
  req.cx = -h * h;
  req.cv = -h;
  req.product_in = nodes.v();
  req.product_out = kv;
  sys.add_jacobians(req);
  for (Index i = 0; i < nodes.size(); ++i) A.block(A.diagonal(i)).diagonal().array() += nodes.masses()[i];
  for (std::uint32_t pt = 0; pt < impl_->node_of_point.size(); ++pt)
    for (std::size_t a = 0; a < 3; ++a) pn[3 * std::size_t{impl_->node_of_point[pt]} + a] = p[3 * pt + a];
  A.multiply(pn, q);
  LinearSystemSample out;
  out.product.assign(3 * impl_->node_of_point.size(), 0.0);
  out.rhs.assign(out.product.size(), 0.0);
  const auto f = nodes.f();
  for (std::uint32_t pt = 0; pt < impl_->node_of_point.size(); ++pt) {
    const Index n = impl_->node_of_point[pt];
    for (std::size_t a = 0; a < 3; ++a) {
      if ((nodes.fixed(n) >> a) & 1u) continue;
      const std::size_t k = 3 * std::size_t{n} + a;
      out.product[3 * pt + a] = q[k];
      out.rhs[3 * pt + a] = h * (f[k] + h * kv[k]);
    }
  }
  return out;
}

double Ours::max_abs_position() const {
  double m = 0;
  for (double c : impl_->sys.nodes().x()) m = std::max(m, std::abs(c));
  return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
}

}  // namespace sewn::bench::mss
