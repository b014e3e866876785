#include "sewn/physics/solids/volume_term.hpp"

#include <array>
#include <cmath>
#include <string>

#include <Eigen/Geometry>

#include "../format.hpp"
#include "hex_corners.hpp"
#include "sewn/physics/errors.hpp"
#include "sewn/physics/mss_model.hpp"

namespace sewn::physics::solids {

namespace {

// The stencil's edges from its corner: columns a-o, b-o, c-o.
Eigen::Matrix3d edges(const CornerPositions& x) { return x.rightCols<3>().colwise() - x.col(0); }

Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// The gradient of det over (o, a, b, c), o's being minus the sum of the others'.
elements::Vec<12> stencil_gradient(const Eigen::Matrix3d& g) {
  elements::Vec<12> out;
  out.segment<3>(0) = -g.rowwise().sum();
  for (int p = 0; p < 3; ++p) out.segment<3>(3 + 3 * p) = g.col(p);
  return out;
}

}  // namespace

double volume_energy(const CornerPositions& x, const VolumeStencil& r) {
  const double strain = (edges(x).determinant() - r.rest_det) / r.rest_det;  // J - 1
  return 0.5 * r.stiffness * strain * strain;
}

elements::Vec<12> volume_gradient(const CornerPositions& x, const VolumeStencil& r) {
  const Eigen::Matrix3d e = edges(x);
  const double strain = (e.determinant() - r.rest_det) / r.rest_det;
  return (r.stiffness * strain / r.rest_det) * stencil_gradient(elements::cofactor(e));
}

elements::Mat<12> volume_hessian(const CornerPositions& x, const VolumeStencil& r) {
  const Eigen::Matrix3d e = edges(x);
  const double strain = (e.determinant() - r.rest_det) / r.rest_det;
  const elements::Vec<12> dJ = stencil_gradient(elements::cofactor(e)) / r.rest_det;
  // ∇²det over the edges a', b', c': block (p, q) = ∂(∂det/∂p)/∂q, zero on the diagonal. Over
  // (o, a, b, c), o enters every edge with a minus sign: its rows and columns are minus sums.
  std::array<std::array<Eigen::Matrix3d, 3>, 3> h;
  for (int p = 0; p < 3; ++p) {
    const int q = (p + 1) % 3, s = (p + 2) % 3;  // ∂det/∂p = q' × s'
    h[p][p].setZero();
    h[p][q] = -cross_matrix(e.col(s));
    h[p][s] = cross_matrix(e.col(q));
  }
  elements::Mat<12> out = r.stiffness * (dJ * dJ.transpose());
  const double c = r.stiffness * strain / r.rest_det;
  Eigen::Matrix3d oo = Eigen::Matrix3d::Zero();
  for (int p = 0; p < 3; ++p) {
    Eigen::Matrix3d row = Eigen::Matrix3d::Zero();  // Σ_q h[p][q]
    for (int q = 0; q < 3; ++q) {
      out.block<3, 3>(3 + 3 * p, 3 + 3 * q) += c * h[p][q];
      row += h[p][q];
    }
    out.block<3, 3>(3 + 3 * p, 0) -= c * row;
    out.block<3, 3>(0, 3 + 3 * p) -= c * row.transpose();
    oo += row;
  }
  out.block<3, 3>(0, 0) += c * oo;
  return out;
}

Index VolumePreservation::add(const std::array<Index, 4>& nodes, const CornerPositions& X, double kappa, double weight) {
  const std::string what = std::string(name()) + " element " + std::to_string(size());
  if (!(kappa > 0) || !std::isfinite(kappa))
    throw InputError(what + ": the bulk stiffness must be finite and > 0 (got " + physics::detail::format_number(kappa) + " Pa)");
  if (!(weight > 0) || !std::isfinite(weight))
    throw InputError(what + ": the rest volume must be finite and > 0 (got " + physics::detail::format_number(weight) + " m³)");
  const Eigen::Matrix3d e = edges(X);
  const double det = e.determinant();
  const double longest = e.colwise().norm().maxCoeff();
  if (!std::isfinite(det) || std::abs(det) <= 1e-12 * longest * longest * longest)
    throw InputError(what + ": its rest corner is flat (det " + physics::detail::format_number(det) + " m³ for edges up to " +
                     physics::detail::format_number(longest) + " m)");
  const Index e_index = push_element(nodes);
  rest_.push_back({det, kappa * weight});
  source_.emplace_back();
  return e_index;
}

void VolumePreservation::follow(const MssModel<3>& model) {
  Index last = invalid_index;
  std::vector<Index> corners;
  std::vector<char> covered(model.elements().size(), 0);  // live elements that keep live stencils
  for (Index e = 0; e < size(); ++e) {
    const Source& src = source_[e];
    if (src.element == invalid_index || !is_alive(e)) continue;
    if (src.element >= model.elements().size())
      throw InputError(std::string(name()) + " element " + std::to_string(e) + ": its model element " + std::to_string(src.element) +
                       " does not exist (" + std::to_string(model.elements().size()) + " elements)");
    if (!model.elements()[src.element].alive) {
      retire_element(e);  // pierced away, or refined (its children carry the volume now)
      continue;
    }
    covered[src.element] = 1;
    if (src.element != last) {  // a hexahedron's 8 stencils are consecutive: one read for them
      corners = model.element_nodes(src.element);
      last = src.element;
    }
    set_element_nodes(e, {corners[src.corners[0]], corners[src.corners[1]], corners[src.corners[2]], corners[src.corners[3]]});
  }
  if (kappa_of_material_.empty()) return;
  for (Index el = 0; el < model.elements().size(); ++el) {
    const Element& m = model.elements()[el];
    if (m.alive && !covered[el] && m.material < kappa_of_material_.size() && kappa_of_material_[m.material] > 0)
      add_element(model, el, kappa_of_material_[m.material]);
  }
}

void VolumePreservation::add_element(const MssModel<3>& model, Index el, double kappa) {
  const Element& m = model.elements()[el];
  if (m.kind != ElementKind::tetrahedron && m.kind != ElementKind::hexahedron) return;
  const std::vector<Index> v = model.element_nodes(el);
  const auto corner = [&](std::uint8_t o, std::uint8_t a, std::uint8_t b, std::uint8_t c, double weight) {
    CornerPositions X;
    const std::array<Index, 4> nodes{v[o], v[a], v[b], v[c]};
    for (int k = 0; k < 4; ++k) X.col(k) = model.rest_position(nodes[k]);
    set_source(add(nodes, X, kappa, weight), {el, {o, a, b, c}});
  };
  if (m.kind == ElementKind::tetrahedron) {
    corner(0, 1, 2, 3, m.measure);
  } else {
    for (std::uint8_t c = 0; c < 8; ++c)
      corner(c, detail::hex_corners[c][0], detail::hex_corners[c][1], detail::hex_corners[c][2], m.measure / 8);
  }
}

VolumePreservation* add_volume_preservation(MssModel<3>& model, std::span<const double> kappa_of_material) {
  if (kappa_of_material.size() != model.materials().size())
    throw InputError("volume term: " + std::to_string(kappa_of_material.size()) + " stiffnesses for " +
                     std::to_string(model.materials().size()) + " materials");
  bool any = false;
  for (std::size_t m = 0; m < kappa_of_material.size(); ++m) {
    if (!(kappa_of_material[m] >= 0) || !std::isfinite(kappa_of_material[m]))
      throw InputError("volume term: material " + std::to_string(m) + ": the bulk stiffness must be finite and >= 0 (got " +
                       physics::detail::format_number(kappa_of_material[m]) + " Pa)");
    any = any || kappa_of_material[m] > 0;
  }
  if (!any) return nullptr;
  auto& term = model.system().add<VolumePreservation>();
  for (Index e = 0; e < model.elements().size(); ++e) {
    const Element& el = model.elements()[e];
    if (el.alive && kappa_of_material[el.material] > 0) term.add_element(model, e, kappa_of_material[el.material]);
  }
  term.set_materials({kappa_of_material.begin(), kappa_of_material.end()});
  // a cut duplicates particles: each stencil then takes its element's copies; refinement and
  // coarsening change which elements are alive: the live ones get stencils
  model.after_edits([&model, &term] { term.follow(model); });
  return &term;
}

}  // namespace sewn::physics::solids
