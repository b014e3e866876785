#pragma once
// What every side of the mss suite simulates, described once (no CGAL, no map):
//   - ModelSpec: an indexed mesh (hexahedra and/or tetrahedra), the material, gravity, drag and
//     the fixed points. "Ours" (the library), the bare loop and the CGAL LCC+MSS peer are all
//     built from the same ModelSpec and checked against each other at setup.
//   - mass_spring(): masses and springs computed straight from the mesh with the library's
//     stiffness formulas (physics/stiffness.hpp): the bare loop's data. The library and the
//     CGAL peer compute theirs on their own maps; the setup checks compare the results.
//   - PeerModel: the interface of the CGAL peer, so that CGAL's headers stay in their own
//     translation unit (cgal_mss.cpp).
// Every per-point array here is indexed by mesh point, 3 doubles per point (x, y, z).

#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"

namespace sewn::bench::mss {

/// The 2013 paper's material: E = 100 MPa, ν = 0.3, ρ = 1000 kg/m³ (seed 002 §6).
struct Material {
  double young = 1e8;
  double poisson = 0.3;
  double density = 1000;
};

struct ModelSpec {
  std::string name;
  IndexedMesh mesh;
  Material material;
  std::array<double, 3> gravity{0.0, 0.0, -9.8};  ///< the paper's g = 9.8 (the cantilever uses 9.81)
  double environment = 0;                          ///< drag F = -c m v, c in 1/s (0: none)
  std::vector<std::uint8_t> fixed;                 ///< per mesh point: 1 = all three axes fixed
};

/// Fixes every point whose coordinate `axis` equals `value` (to 1e-9 of the mesh extent).
void clamp_plane(ModelSpec& spec, int axis, double value);

/// Masses and springs of the model, from the mesh alone: masses lumped ρV/8 per hexahedron
/// corner and ρV/4 per tetrahedron corner; one spring per distinct mesh edge whose stiffness is
/// the sum of its incident elements' contributions (Baudet box edges for hexahedra, van Gelder
/// E·V/l² for tetrahedra); 4 body diagonals per hexahedron (Baudet); the seed's viscosity
/// γ = 2√(k(mi+mj)/2) on every spring. Springs come edges first (sorted by end points), then
/// diagonals in cell order. Hexahedra must be axis-aligned boxes (the only shape the Baudet
/// formula covers), as in every mesh of this suite.
struct MassSpring {
  std::vector<double> mass;  ///< per mesh point
  std::vector<std::uint32_t> i, j;
  std::vector<double> k, l, gamma;
  std::size_t edges = 0, diagonals = 0;
  [[nodiscard]] std::size_t springs() const { return k.size(); }
};
MassSpring mass_spring(const ModelSpec& spec);

/// Particles and springs a model has, as the paper counts them (diagonals included).
struct Counts {
  std::size_t particles = 0, springs = 0;
  friend bool operator==(const Counts&, const Counts&) = default;
};
std::string to_string(const Counts& c);

/// A state for cross-checks: every free coordinate of the rest positions moved by up to
/// `amplitude` × the shortest mesh edge, velocities uniform in ±speed (m/s), fixed points at
/// rest. Deterministic for a seed.
struct State {
  std::vector<double> x, v;
};
State perturbed_state(const ModelSpec& spec, double amplitude, double speed, unsigned seed);
/// The rest state (mesh positions, zero velocities).
State rest_state(const ModelSpec& spec);

/// max_k |a_k - b_k| / max_k |a_k|: the relative disagreement of two force (or product) arrays.
double relative_difference(std::span<const double> a, std::span<const double> b);

/// The implicit step's linear system at the current state, for cross-checks: the product
/// A·p with A = M - h ∂F/∂V - h² ∂F/∂P (the solver's form: compression clamped, viscous
/// position terms dropped) and the right-hand side b = h (F + h ∂F/∂P V), both on free axes
/// only (p must be 0 on fixed axes; fixed entries of the results are set to 0).
struct LinearSystemSample {
  std::vector<double> product, rhs;
};

/// The seed's own approach, measured in the same binary: implemented in cgal_mss.cpp.
class PeerModel {
 public:
  PeerModel() = default;
  PeerModel(const PeerModel&) = delete;
  PeerModel& operator=(const PeerModel&) = delete;
  virtual ~PeerModel() = default;

  [[nodiscard]] virtual Counts counts() const = 0;
  /// One semi-implicit (symplectic Euler) step: forces, then v += h F/m, x += h v.
  virtual void step_semi_implicit(double h) = 0;
  /// One linearly implicit (Baraff-Witkin) Euler step; returns the CG iterations it took.
  virtual int step_implicit(double h) = 0;
  /// Sets positions and velocities (per mesh point); forgets the CG warm start.
  virtual void set_state(const State& s) = 0;
  [[nodiscard]] virtual State state() const = 0;
  /// The forces at the current state (per mesh point, fixed points included).
  [[nodiscard]] virtual std::vector<double> forces() = 0;
  /// Masses per mesh point.
  [[nodiscard]] virtual std::vector<double> masses() const = 0;
  [[nodiscard]] virtual LinearSystemSample linear_system(double h, std::span<const double> p) = 0;
  /// Largest |coordinate| of any position (to schedule restores of unstable runs).
  [[nodiscard]] virtual double max_abs_position() const = 0;
};

/// True when the binary was built with the CGAL peer.
bool have_cgal_peer();
/// "CGAL 5.5.1 LCC+MSS" (the LCC with Particle / Spring attributes, as the paper built it).
std::string cgal_peer_name();
/// Builds the peer; throws std::runtime_error when CGAL is absent or the mesh is not supported.
std::unique_ptr<PeerModel> make_cgal_peer(const ModelSpec& spec);

}  // namespace sewn::bench::mss
