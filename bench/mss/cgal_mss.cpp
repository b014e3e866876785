// The seed's own approach (Fléchon, Zara, Damiand, Jaillet, WSCG 2013, §3-4), rebuilt on CGAL
// 5.5's Linear_cell_complex_for_combinatorial_map<3> and measured in the same binary as ours.
// CGAL stays in this translation unit; the rest of the suite sees only PeerModel (model.hpp).
//
// Reconstruction choices, each from the paper's text where it says something:
//
// Data ("3D LCC+MSS", §3, Fig. 3).
//   - 0-attribute: CGAL::Cell_attribute_with_point holding the vertex's Point_3 (the particle's
//     position lives in the LCC, "the position of the particle is given by the Point_3
//     associated to the corresponding vertex") and a Particle: index (for the implicit system),
//     mass, acceleration, velocity, force, per-axis fixed flags, redundancy (incident volumes)
//     and the list of pointers to its diagonal springs.
//   - 1-attribute: a Spring: rest length, stiffness, redundancy (incident volumes) and pointers
//     to its two extremities. The extremities point to the 0-attributes themselves, since they
//     hold both the Particle and the position the force needs. The viscosity coefficient
//     γ = 2√(k(mi+mj)/2) is stored at initialisation (the paper does not say whether it is
//     recomputed each step; storing it is the cheaper reading, and is what ours does).
//   - Diagonal springs (4 per hexahedron) have no 1-cell: they live in a 3-attribute of their
//     volume, and each end particle holds pointers to them (the paper's per-particle "array of
//     pointers to Spring"). Tetrahedra have no 3-attribute content.
//   - Geometry through CGAL's kernel types (Epick Point_3 / Vector_3), as the paper's code is
//     written against the kernel's FT, Point_3 and Vector_3 (§3).
//
// Initialisation (§4, "Initialization").
//   - The volumes are created from the indexed mesh with CGAL's incremental builder, which also
//     glues faces that share their vertices (the paper: "identify all the faces that share the
//     same geometry"); the builder is CGAL's fastest construction path (bench/cmap/cgal_lcc.hpp),
//     and construction is not timed here anyway.
//   - Masses: each particle iterates its incident volumes (one_dart_per_incident_cell<3,0>)
//     and adds ρV/8 (hexahedron) or ρV/4 (tetrahedron). Redundancies are the same counts.
//   - Edge springs: each 1-cell iterates its incident volumes and sums their contributions:
//     Baudet's box edge stiffness for a hexahedron (the box sizes are the volume's extents: the
//     meshes are axis-aligned boxes, the only shape the formula is defined for), van Gelder's
//     E·V/l² for a tetrahedron (sewn::physics stiffness functions, so both sides simulate the
//     same system; the setup check compares forces).
//   - Diagonals: each hexahedron pairs every corner with the farthest one (its opposite
//     corner, for a box) and creates 4 springs with Baudet's diagonal stiffness.
//
// Semi-implicit step (§4, "Forces computation" and "Numerical integration schemes"):
//   1) iterate the 0-attributes: force = m g (drag -c m v if any);
//   2) iterate the 1-attributes, then the diagonal springs of the 3-attributes: elastic
//      k(d - l)U plus viscous γ((Vj - Vi)·U)U, accumulated on both particles;
//   3) iterate the 0-attributes: a = F/m (fixed axes zeroed), V += h a, P += h V.
//   The library's degenerate-spring guard (no force below d = 1e-9 l) is kept so that both
//   sides compute the same forces in every state.
//
// Implicit step (§4, Baraff-Witkin):
//   (M - h ∂F/∂V - h² ∂F/∂P) ΔV = h (F + h ∂F/∂P V), then V += ΔV, P += h V.
//   - Damping model: the paper writes per-spring viscosity in the forces but a Rayleigh
//     ∂F/∂V, which is inconsistent (PHYSICS_NOTES §1.5). Both sides use the per-spring viscosity
//     in the forces and its own Jacobian ∂F^v/∂V = γUUᵀ in the matrix, and drop the non-symmetric
//     ∂F^v/∂P (as Baraff-Witkin do); ∂F^e/∂P uses max(0, 1 - l/d) so the matrix is SPD. So the two
//     solve the same linear system (the setup check compares A·p and b).
//   - Matrix: the paper stores "the global stiffness matrix" in the LCC+MSS object, resizes it
//     after a cut and "fills its nonzero entries" each step using the particle index. We read
//     that as a persistent Eigen::SparseMatrix whose pattern is built once (from the springs) and
//     whose values are zeroed and refilled each step with coeffRef (a binary search per entry in
//     its row). That is faster than assembling from triplets each step; row-major storage makes
//     Eigen's CG product row-wise. Both choices favour the peer.
//   - Fixed axes: their rows and columns are left out of the fill and get 1 on the diagonal and
//     0 in b, which is the Baraff-Witkin filter with a zero prescribed ΔV (PHYSICS_NOTES §1.5).
//   - Solver: Eigen::ConjugateGradient<SparseMatrix, Lower|Upper, DiagonalPreconditioner> at the
//     same relative tolerance as ours (1e-6 on ‖b - AΔV‖/‖b‖, the same measure), warm-started from
//     the previous ΔV as ours is. Ours preconditions with 3×3 blocks; iterations are reported
//     for both.

#include <CGAL/Linear_cell_complex_for_combinatorial_map.h>
#include <CGAL/Linear_cell_complex_incremental_builder.h>
#include <CGAL/version.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/Sparse>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "model.hpp"
#include "sewn/physics/springs.hpp"
#include "sewn/physics/stiffness.hpp"

namespace sewn::bench::mss {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Vector = Kernel::Vector_3;
using Point = Kernel::Point_3;

template <class Refs>
struct ParticleT;
template <class Refs>
using VertexAttr = CGAL::Cell_attribute_with_point<Refs, ParticleT<Refs>>;

template <class Refs>
struct SpringT {
  double rest_length = 0;
  double stiffness = 0;
  double viscosity = 0;
  int redundancy = 0;
  std::array<VertexAttr<Refs>*, 2> ends{};
};

template <class Refs>
struct ParticleT {
  std::size_t index = 0;
  double mass = 0;
  Vector acceleration = CGAL::NULL_VECTOR;
  Vector velocity = CGAL::NULL_VECTOR;
  Vector force = CGAL::NULL_VECTOR;
  std::array<bool, 3> fixed{};
  int redundancy = 0;
  std::vector<SpringT<Refs>*> diagonals;
};

// A volume's rest data and its internal diagonal springs (hexahedra only).
template <class Refs>
struct VolumeT {
  bool hexahedron = false;
  double measure = 0;
  std::array<double, 3> box{};  // extents along x, y, z (hexahedra)
  std::array<SpringT<Refs>, 4> diagonals{};
  int num_diagonals = 0;
};

struct MssItems {
  template <class Refs>
  struct Dart_wrapper {
    using Vertex_attribute = VertexAttr<Refs>;
    using Edge_attribute = CGAL::Cell_attribute<Refs, SpringT<Refs>>;
    using Volume_attribute = CGAL::Cell_attribute<Refs, VolumeT<Refs>>;
    using Attributes = std::tuple<Vertex_attribute, Edge_attribute, void, Volume_attribute>;
  };
};

using Lcc = CGAL::Linear_cell_complex_for_combinatorial_map<3, 3, CGAL::Linear_cell_complex_traits<3, Kernel>, MssItems>;
using Dart_handle = Lcc::Dart_handle;
using Vertex = Lcc::Attribute_type<0>::type;
using Particle = Vertex::Info;
using Spring = Lcc::Attribute_type<1>::type::Info;
using Volume = Lcc::Attribute_type<3>::type::Info;
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// The library's degenerate-spring guard (physics/src/springs.cpp).
constexpr double degenerate_ratio_sq = 1e-18;

class CgalMss final : public PeerModel {
 public:
  explicit CgalMss(const ModelSpec& spec) : spec_(spec) {
    build_map();
    init_volumes();
    init_particles();
    init_springs();
    init_matrix();
  }

  [[nodiscard]] Counts counts() const override {
    std::size_t springs = lcc_.number_of_attributes<1>();
    for (const auto& v : lcc_.attributes<3>()) springs += static_cast<std::size_t>(v.info().num_diagonals);
    return {lcc_.number_of_attributes<0>(), springs};
  }

  void step_semi_implicit(double h) override {
    compute_forces();
    for (auto& a : lcc_.attributes<0>()) {
      Particle& p = a.info();
      p.acceleration = p.force / p.mass;
      if (p.fixed[0] || p.fixed[1] || p.fixed[2])
        p.acceleration = Vector(p.fixed[0] ? 0.0 : p.acceleration.x(), p.fixed[1] ? 0.0 : p.acceleration.y(),
                                p.fixed[2] ? 0.0 : p.acceleration.z());
      p.velocity = p.velocity + h * p.acceleration;
      a.point() = a.point() + h * p.velocity;
    }
  }

  int step_implicit(double h) override {
    compute_forces();
    assemble(h);
    cg_.compute(A_);
    dv_ = cg_.solveWithGuess(b_, dv_);
    if (cg_.info() != Eigen::Success)
      throw std::runtime_error("CGAL peer: CG did not converge (" + std::to_string(cg_.iterations()) + " iterations)");
    for (auto& a : lcc_.attributes<0>()) {
      Particle& p = a.info();
      const std::size_t i = 3 * p.index;
      p.velocity = p.velocity + Vector(dv_[i], dv_[i + 1], dv_[i + 2]);
      a.point() = a.point() + h * p.velocity;
    }
    return static_cast<int>(cg_.iterations());
  }

  void set_state(const State& s) override {
    for (auto& a : lcc_.attributes<0>()) {
      Particle& p = a.info();
      const std::size_t i = 3 * p.index;
      a.point() = Point(s.x[i], s.x[i + 1], s.x[i + 2]);
      p.velocity = Vector(p.fixed[0] ? 0.0 : s.v[i], p.fixed[1] ? 0.0 : s.v[i + 1], p.fixed[2] ? 0.0 : s.v[i + 2]);
    }
    dv_.setZero();
  }

  [[nodiscard]] State state() const override {
    State s;
    s.x.assign(3 * by_point_.size(), 0.0);
    s.v.assign(s.x.size(), 0.0);
    for (const auto& a : lcc_.attributes<0>()) {
      const std::size_t i = 3 * a.info().index;
      for (int c = 0; c < 3; ++c) {
        s.x[i + static_cast<std::size_t>(c)] = a.point()[c];
        s.v[i + static_cast<std::size_t>(c)] = a.info().velocity[c];
      }
    }
    return s;
  }

  [[nodiscard]] std::vector<double> forces() override {
    compute_forces();
    std::vector<double> f(3 * by_point_.size(), 0.0);
    for (const auto& a : lcc_.attributes<0>())
      for (int c = 0; c < 3; ++c) f[3 * a.info().index + static_cast<std::size_t>(c)] = a.info().force[c];
    return f;
  }

  [[nodiscard]] std::vector<double> masses() const override {
    std::vector<double> m(by_point_.size(), 0.0);
    for (const auto& a : lcc_.attributes<0>()) m[a.info().index] = a.info().mass;
    return m;
  }

  [[nodiscard]] LinearSystemSample linear_system(double h, std::span<const double> p) override {
    compute_forces();
    assemble(h);
    const Eigen::Map<const Eigen::VectorXd> pv(p.data(), static_cast<Eigen::Index>(p.size()));
    const Eigen::VectorXd ap = A_ * pv;
    LinearSystemSample out;
    out.product.assign(p.size(), 0.0);
    out.rhs.assign(p.size(), 0.0);
    for (std::size_t k = 0; k < p.size(); ++k) {
      if (fixed_dof_[k]) continue;
      out.product[k] = ap[static_cast<Eigen::Index>(k)];
      out.rhs[k] = b_[static_cast<Eigen::Index>(k)];
    }
    return out;
  }

  [[nodiscard]] double max_abs_position() const override {
    double m = 0;
    for (const auto& a : lcc_.attributes<0>())
      for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(a.point()[c]));
    return std::isfinite(m) ? m : std::numeric_limits<double>::infinity();
  }

 private:
  // ---------------------------------------------------------------- initialisation

  void build_map() {
    const IndexedMesh& mesh = spec_.mesh;
    CGAL::Linear_cell_complex_incremental_builder_3<Lcc> builder(lcc_);
    for (const Point3& p : mesh.points) by_point_.push_back(&*builder.add_vertex(Point(p[0], p[1], p[2])));
    for (std::uint32_t c = 0; c < mesh.num_cells(); ++c) {
      if (mesh.types[c] != CellType::hexahedron && mesh.types[c] != CellType::tetrahedron)
        throw std::runtime_error("CGAL peer: only hexahedra and tetrahedra are supported");
      const auto v = mesh.cell(c);
      builder.begin_surface();
      for (auto face : cell_faces(mesh.types[c])) {
        builder.begin_facet();
        for (std::uint32_t l : face) builder.add_vertex_to_facet(v[l]);
        builder.end_facet();
      }
      builder.end_surface();
    }
    if (!lcc_.is_valid()) throw std::runtime_error("CGAL peer: the LCC built from " + spec_.name + " is not valid");
    for (std::size_t p = 0; p < by_point_.size(); ++p) by_point_[p]->info().index = p;
  }

  // The vertex attributes of the volume of d.
  std::vector<Vertex*> volume_vertices(Dart_handle d) {
    std::vector<Vertex*> out;
    for (auto& x : lcc_.one_dart_per_incident_cell<0, 3>(d)) out.push_back(&*lcc_.attribute<0>(lcc_.darts().iterator_to(x)));
    return out;
  }

  void init_volumes() {
    const Material& mat = spec_.material;
    for (auto& x : lcc_.one_dart_per_cell<3>()) {
      const Dart_handle d = lcc_.darts().iterator_to(x);
      const auto attr = lcc_.create_attribute<3>();
      lcc_.set_attribute<3>(d, attr);
      Volume& vol = attr->info();
      const std::vector<Vertex*> vs = volume_vertices(d);
      if (vs.size() == 8) {
        vol.hexahedron = true;
        for (int a = 0; a < 3; ++a) {
          double lo = std::numeric_limits<double>::infinity(), hi = -lo;
          for (Vertex* v : vs) {
            lo = std::min(lo, v->point()[a]);
            hi = std::max(hi, v->point()[a]);
          }
          vol.box[static_cast<std::size_t>(a)] = hi - lo;
        }
        vol.measure = vol.box[0] * vol.box[1] * vol.box[2];
        const double kd = physics::baudet_box_diagonal(mat.young, mat.poisson, vol.box[0], vol.box[1], vol.box[2]);
        // pair each corner with its opposite (farthest) corner: 4 body diagonals of the box
        std::vector<bool> used(8, false);
        for (std::size_t q = 0; q < 8; ++q) {
          if (used[q]) continue;
          std::size_t far = q;
          double dmax = -1;
          for (std::size_t r = 0; r < 8; ++r) {
            const double d2 = CGAL::squared_distance(vs[q]->point(), vs[r]->point());
            if (d2 > dmax) {
              dmax = d2;
              far = r;
            }
          }
          used[q] = used[far] = true;
          Spring& s = vol.diagonals[static_cast<std::size_t>(vol.num_diagonals++)];
          s.rest_length = std::sqrt(dmax);
          s.stiffness = kd;
          s.redundancy = 1;
          s.ends = {vs[q], vs[far]};
        }
        if (vol.num_diagonals != 4) throw std::runtime_error("CGAL peer: a hexahedron without 4 body diagonals");
      } else if (vs.size() == 4) {
        const auto e = [&](std::size_t q) {
          const Point& p = vs[q]->point();
          return Eigen::Vector3d(p.x(), p.y(), p.z());
        };
        vol.measure = physics::tet_volume(e(0), e(1), e(2), e(3));
      } else {
        throw std::runtime_error("CGAL peer: a volume with " + std::to_string(vs.size()) + " vertices");
      }
    }
  }

  void init_particles() {
    const double rho = spec_.material.density;
    for (auto& x : lcc_.one_dart_per_cell<0>()) {
      const Dart_handle d = lcc_.darts().iterator_to(x);
      Particle& p = lcc_.attribute<0>(d)->info();
      for (auto& y : lcc_.one_dart_per_incident_cell<3, 0>(d)) {
        const Volume& vol = lcc_.attribute<3>(lcc_.darts().iterator_to(y))->info();
        p.mass += physics::lumped_corner_mass(rho, vol.measure, vol.hexahedron ? 8 : 4);
        ++p.redundancy;
      }
      const bool fixed = !spec_.fixed.empty() && spec_.fixed[p.index] != 0;
      p.fixed = {fixed, fixed, fixed};
    }
  }

  void init_springs() {
    const Material& mat = spec_.material;
    for (auto& x : lcc_.one_dart_per_cell<1>()) {
      const Dart_handle d = lcc_.darts().iterator_to(x);
      const auto attr = lcc_.create_attribute<1>();
      lcc_.set_attribute<1>(d, attr);
      Spring& s = attr->info();
      s.ends = {&*lcc_.attribute<0>(d), &*lcc_.attribute<0>(lcc_.other_extremity(d))};
      const Vector e = s.ends[1]->point() - s.ends[0]->point();
      s.rest_length = std::sqrt(e.squared_length());
      for (auto& y : lcc_.one_dart_per_incident_cell<3, 1>(d)) {
        const Volume& vol = lcc_.attribute<3>(lcc_.darts().iterator_to(y))->info();
        ++s.redundancy;
        if (vol.hexahedron) {
          int axis = 0;
          for (int a = 1; a < 3; ++a)
            if (std::abs(e[a]) > std::abs(e[axis])) axis = a;
          if (std::abs(std::abs(e[axis]) - s.rest_length) > 1e-9 * s.rest_length)
            throw std::runtime_error("CGAL peer: a hexahedron edge is not axis-aligned");
          s.stiffness +=
              physics::baudet_box(mat.young, mat.poisson, vol.box[0], vol.box[1], vol.box[2]).edge[static_cast<std::size_t>(axis)];
        } else {
          s.stiffness += physics::van_gelder_tet_edge(mat.young, vol.measure, s.rest_length);
        }
      }
    }
    auto set_viscosity = [](Spring& s) {
      s.viscosity = physics::paper_viscosity(s.stiffness, s.ends[0]->info().mass, s.ends[1]->info().mass);
    };
    for (auto& a : lcc_.attributes<1>()) set_viscosity(a.info());
    for (auto& v : lcc_.attributes<3>())
      for (int q = 0; q < v.info().num_diagonals; ++q) {
        Spring& s = v.info().diagonals[static_cast<std::size_t>(q)];
        set_viscosity(s);
        s.ends[0]->info().diagonals.push_back(&s);
        s.ends[1]->info().diagonals.push_back(&s);
      }
  }

  // The pattern of the global matrix: every 3×3 block of a spring's two particles.
  void init_matrix() {
    const auto n3 = static_cast<Eigen::Index>(3 * by_point_.size());
    fixed_dof_.assign(static_cast<std::size_t>(n3), false);
    for (const auto& a : lcc_.attributes<0>())
      for (std::size_t c = 0; c < 3; ++c) fixed_dof_[3 * a.info().index + c] = a.info().fixed[c];
    std::vector<Eigen::Triplet<double>> t;
    auto block = [&](std::size_t i, std::size_t j) {
      for (std::size_t r = 0; r < 3; ++r)
        for (std::size_t c = 0; c < 3; ++c)
          t.emplace_back(static_cast<int>(3 * i + r), static_cast<int>(3 * j + c), 0.0);
    };
    for (const auto& a : lcc_.attributes<0>()) block(a.info().index, a.info().index);
    for_each_spring([&](const Spring& s) {
      block(s.ends[0]->info().index, s.ends[1]->info().index);
      block(s.ends[1]->info().index, s.ends[0]->info().index);
    });
    A_.resize(n3, n3);
    A_.setFromTriplets(t.begin(), t.end());
    A_.makeCompressed();
    b_ = Eigen::VectorXd::Zero(n3);
    kv_ = Eigen::VectorXd::Zero(n3);
    dv_ = Eigen::VectorXd::Zero(n3);
    cg_.setTolerance(1e-6);
  }

  // ---------------------------------------------------------------- the paper's loops

  template <class F>
  void for_each_spring(F&& f) {
    for (auto& a : lcc_.attributes<1>()) f(a.info());
    for (auto& v : lcc_.attributes<3>())
      for (int q = 0; q < v.info().num_diagonals; ++q) f(v.info().diagonals[static_cast<std::size_t>(q)]);
  }

  void compute_forces() {
    const Vector g(spec_.gravity[0], spec_.gravity[1], spec_.gravity[2]);
    const double drag = spec_.environment;
    for (auto& a : lcc_.attributes<0>()) {
      Particle& p = a.info();
      p.force = p.mass * g;
      if (drag != 0) p.force = p.force - (drag * p.mass) * p.velocity;
    }
    for_each_spring([](Spring& s) {
      Vertex& a = *s.ends[0];
      Vertex& b = *s.ends[1];
      const Vector d = b.point() - a.point();
      const double d2 = d.squared_length();
      if (!(d2 > degenerate_ratio_sq * s.rest_length * s.rest_length)) return;
      const double len = std::sqrt(d2);
      const Vector u = d / len;
      const double w = (b.info().velocity - a.info().velocity) * u;
      const Vector f = (s.stiffness * (len - s.rest_length) + s.viscosity * w) * u;
      a.info().force = a.info().force + f;
      b.info().force = b.info().force - f;
    });
  }

  void add_block(std::size_t i, std::size_t j, const Eigen::Matrix3d& B) {
    for (std::size_t r = 0; r < 3; ++r) {
      if (fixed_dof_[3 * i + r]) continue;
      for (std::size_t c = 0; c < 3; ++c) {
        if (fixed_dof_[3 * j + c]) continue;
        A_.coeffRef(static_cast<Eigen::Index>(3 * i + r), static_cast<Eigen::Index>(3 * j + c)) +=
            B(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
      }
    }
  }

  // A = M - h ∂F/∂V - h² ∂F/∂P and b = h (F + h ∂F/∂P V) at the current state (forces computed).
  void assemble(double h) {
    std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0);
    kv_.setZero();
    const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
    for_each_spring([&](const Spring& s) {
      const Vertex& a = *s.ends[0];
      const Vertex& b = *s.ends[1];
      const Vector d = b.point() - a.point();
      const double d2 = d.squared_length();
      if (!(d2 > degenerate_ratio_sq * s.rest_length * s.rest_length)) return;
      const double len = std::sqrt(d2);
      const Eigen::Vector3d U(d.x() / len, d.y() / len, d.z() / len);
      const Eigen::Matrix3d UU = U * U.transpose();
      const Eigen::Matrix3d Jx = s.stiffness * (UU + std::max(0.0, 1.0 - s.rest_length / len) * (I - UU));
      const Eigen::Matrix3d B = (-h * h) * Jx - (h * s.viscosity) * UU;
      const std::size_t i = a.info().index, j = b.info().index;
      add_block(i, j, B);
      add_block(j, i, B);
      add_block(i, i, -B);
      add_block(j, j, -B);
      const Vector dvel = b.info().velocity - a.info().velocity;
      const Eigen::Vector3d q = Jx * Eigen::Vector3d(dvel.x(), dvel.y(), dvel.z());
      kv_.segment<3>(static_cast<Eigen::Index>(3 * i)) += q;
      kv_.segment<3>(static_cast<Eigen::Index>(3 * j)) -= q;
    });
    for (const auto& a : lcc_.attributes<0>()) {
      const Particle& p = a.info();
      for (std::size_t c = 0; c < 3; ++c) {
        const auto k = static_cast<Eigen::Index>(3 * p.index + c);
        if (fixed_dof_[3 * p.index + c]) {
          A_.coeffRef(k, k) = 1.0;
          b_[k] = 0.0;
          dv_[k] = 0.0;
        } else {
          A_.coeffRef(k, k) += p.mass;
          b_[k] = h * (p.force[static_cast<int>(c)] + h * kv_[k]);
        }
      }
    }
  }

  ModelSpec spec_;
  Lcc lcc_;
  std::vector<Vertex*> by_point_;  // mesh point -> its 0-attribute (set-up and checks only)
  SparseMatrix A_;
  Eigen::VectorXd b_, kv_, dv_;
  std::vector<bool> fixed_dof_;
  Eigen::ConjugateGradient<SparseMatrix, Eigen::Lower | Eigen::Upper, Eigen::DiagonalPreconditioner<double>> cg_;
};

}  // namespace

bool have_cgal_peer() { return true; }

std::string cgal_peer_name() { return "CGAL " CGAL_VERSION_STR " LCC+MSS"; }

std::unique_ptr<PeerModel> make_cgal_peer(const ModelSpec& spec) { return std::make_unique<CgalMss>(spec); }

}  // namespace sewn::bench::mss
