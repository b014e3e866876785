#include "sewn/physics/nodes.hpp"

#include <atomic>
#include <cmath>
#include <sstream>

#include "sewn/physics/errors.hpp"

namespace sewn::physics {

namespace {

bool finite3(const Eigen::Vector3d& a) { return a.allFinite(); }

std::string vec_str(const Eigen::Vector3d& a) {
  std::ostringstream os;
  os << '(' << a.x() << ", " << a.y() << ", " << a.z() << ')';
  return os.str();
}

void check_mass(double m, const char* where, Index i) {
  if (!(std::isfinite(m) && m > 0))
    throw InputError(std::string(where) + ": mass of node " + std::to_string(i) + " must be finite and > 0, got " +
                     std::to_string(m));
}

// A version no table of the process has had: a cache keyed by a table's versions cannot take a
// table copied or assigned over it, whose own counters might have reached the same numbers,
// for the one it was made from.
std::uint64_t next_version() {
  static std::atomic<std::uint64_t> versions{0};
  return ++versions;
}

}  // namespace

void NodeTable::check_node(Index i, const char* where) const {
  if (i >= size())
    throw InputError(std::string(where) + ": node " + std::to_string(i) + " out of range (" + std::to_string(size()) +
                     " nodes)");
  if (alive_[i] == 0) throw InputError(std::string(where) + ": node " + std::to_string(i) + " was removed");
}

void NodeTable::refresh_inverse_mass(Index i) {
  for (int a = 0; a < 3; ++a) {
    const bool fixed = (fixed_[i] >> a) & 1u;
    inv_mass_[3 * i + a] = (alive_[i] != 0 && !fixed) ? 1.0 / mass_[i] : 0.0;
  }
}

Index NodeTable::add(const Vec3& x, const Vec3& v, double mass) {
  const Index i = size();
  if (!finite3(x)) throw InputError("NodeTable::add: position of new node " + std::to_string(i) + " is not finite: " + vec_str(x));
  if (!finite3(v)) throw InputError("NodeTable::add: velocity of new node " + std::to_string(i) + " is not finite: " + vec_str(v));
  check_mass(mass, "NodeTable::add", i);
  if (size() == invalid_index - 1) throw InputError("NodeTable::add: too many nodes");
  for (int a = 0; a < 3; ++a) {
    x_.push_back(x[a]);
    v_.push_back(v[a]);
    f_.push_back(0.0);
    inv_mass_.push_back(1.0 / mass);
  }
  mass_.push_back(mass);
  fixed_.push_back(no_axes);
  alive_.push_back(1);
  ++alive_count_;
  topology_version_ = next_version();
  return i;
}

Index NodeTable::duplicate(Index i) {
  check_node(i, "NodeTable::duplicate");
  const Index j = add(position(i), velocity(i), mass_[i]);
  fixed_[j] = fixed_[i];
  if (fixed_[j] != no_axes) ++fixed_count_;
  refresh_inverse_mass(j);
  return j;
}

void NodeTable::reserve(Index n) {
  const std::size_t n3 = 3 * std::size_t{n};
  x_.reserve(n3);
  v_.reserve(n3);
  f_.reserve(n3);
  inv_mass_.reserve(n3);
  mass_.reserve(n);
  fixed_.reserve(n);
  alive_.reserve(n);
}

void NodeTable::remove(Index i) {
  check_node(i, "NodeTable::remove");
  if (fixed_[i] != no_axes) --fixed_count_;
  alive_[i] = 0;
  --alive_count_;
  mass_[i] = 0.0;
  fixed_[i] = all_axes;
  for (int a = 0; a < 3; ++a) {
    v_[3 * i + a] = 0.0;
    f_[3 * i + a] = 0.0;
  }
  refresh_inverse_mass(i);
  topology_version_ = next_version();
  parameter_version_ = next_version();
}

Eigen::Vector3d NodeTable::position(Index i) const {
  check_node(i, "NodeTable::position");
  return {x_[3 * i], x_[3 * i + 1], x_[3 * i + 2]};
}
Eigen::Vector3d NodeTable::velocity(Index i) const {
  check_node(i, "NodeTable::velocity");
  return {v_[3 * i], v_[3 * i + 1], v_[3 * i + 2]};
}
Eigen::Vector3d NodeTable::force(Index i) const {
  check_node(i, "NodeTable::force");
  return {f_[3 * i], f_[3 * i + 1], f_[3 * i + 2]};
}
double NodeTable::mass(Index i) const {
  check_node(i, "NodeTable::mass");
  return mass_[i];
}
AxisMask NodeTable::fixed(Index i) const {
  check_node(i, "NodeTable::fixed");
  return fixed_[i];
}

void NodeTable::set_position(Index i, const Vec3& x) {
  check_node(i, "NodeTable::set_position");
  if (!finite3(x)) throw InputError("NodeTable::set_position: position of node " + std::to_string(i) + " is not finite: " + vec_str(x));
  for (int a = 0; a < 3; ++a) x_[3 * i + a] = x[a];
}

void NodeTable::set_velocity(Index i, const Vec3& v) {
  check_node(i, "NodeTable::set_velocity");
  if (!finite3(v)) throw InputError("NodeTable::set_velocity: velocity of node " + std::to_string(i) + " is not finite: " + vec_str(v));
  for (int a = 0; a < 3; ++a) v_[3 * i + a] = v[a];
}

void NodeTable::set_mass(Index i, double m) {
  check_node(i, "NodeTable::set_mass");
  check_mass(m, "NodeTable::set_mass", i);
  mass_[i] = m;
  refresh_inverse_mass(i);
  parameter_version_ = next_version();
}

void NodeTable::fix(Index i, AxisMask axes) {
  check_node(i, "NodeTable::fix");
  if ((axes & ~all_axes) != 0) throw InputError("NodeTable::fix: axis mask " + std::to_string(axes) + " has bits beyond x|y|z");
  if (fixed_[i] == no_axes && axes != no_axes) ++fixed_count_;
  fixed_[i] = static_cast<AxisMask>(fixed_[i] | axes);
  for (int a = 0; a < 3; ++a)
    if ((axes >> a) & 1u) v_[3 * i + a] = 0.0;
  refresh_inverse_mass(i);
  parameter_version_ = next_version();
}

void NodeTable::unfix(Index i, AxisMask axes) {
  check_node(i, "NodeTable::unfix");
  if ((axes & ~all_axes) != 0) throw InputError("NodeTable::unfix: axis mask " + std::to_string(axes) + " has bits beyond x|y|z");
  const bool was = fixed_[i] != no_axes;
  fixed_[i] = static_cast<AxisMask>(fixed_[i] & ~axes);
  if (was && fixed_[i] == no_axes) --fixed_count_;
  refresh_inverse_mass(i);
  parameter_version_ = next_version();
}

std::vector<Index> NodeTable::compact() {
  std::vector<Index> old_to_new(size(), invalid_index);
  Index n = 0;
  for (Index i = 0; i < size(); ++i) {
    if (alive_[i] == 0) continue;
    old_to_new[i] = n;
    if (n != i) {
      for (int a = 0; a < 3; ++a) {
        x_[3 * n + a] = x_[3 * i + a];
        v_[3 * n + a] = v_[3 * i + a];
        f_[3 * n + a] = f_[3 * i + a];
        inv_mass_[3 * n + a] = inv_mass_[3 * i + a];
      }
      mass_[n] = mass_[i];
      fixed_[n] = fixed_[i];
      alive_[n] = 1;
    }
    ++n;
  }
  x_.resize(3 * std::size_t{n});
  v_.resize(3 * std::size_t{n});
  f_.resize(3 * std::size_t{n});
  inv_mass_.resize(3 * std::size_t{n});
  mass_.resize(n);
  fixed_.resize(n);
  alive_.resize(n);
  topology_version_ = next_version();
  parameter_version_ = next_version();
  return old_to_new;
}

}  // namespace sewn::physics
