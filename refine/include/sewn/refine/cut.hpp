#pragma once
// Cutting and piercing a mass-spring body while it moves (the 2013 paper's §5): a cut unsews
// facets between elements (3-unsew of faces between volumes, 2-unsew of edges between 2D cells);
// piercing unsews every facet of chosen elements and removes them or keeps them as loose pieces.
// The map's split hooks duplicate particles and springs; MssModel::edit() then recomputes
// masses, stiffnesses and diagonal attachments. Call these between two steps.
//
// Selections are made in the body's rest configuration (rest positions and mesh point indices),
// so a scheduled cut lands where the scene placed it however the body has moved since.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "sewn/physics/mss_model.hpp"

namespace sewn::refine {

using physics::Index;
using physics::MssModel;

/// A facet between two elements: `dart` lies on it, `index` is the β that joins the two sides
/// (3 for a face between volumes, 2 for an edge between 2D cells).
struct Facet {
  Dart dart;
  int index = 0;
  friend bool operator==(const Facet&, const Facet&) = default;
};

/// What an operation changed, in live counts.
struct CutReport {
  std::uint32_t facets = 0;  ///< facets unsewn
  std::int64_t particles = 0, springs = 0, elements = 0;  ///< change in live particles, springs, elements
  std::uint32_t refined = 0;  ///< elements refined first, so that no facet cut lies on a level jump
};

/// A predicate on rest positions (points, or element / facet centroids).
using Region = std::function<bool(const Eigen::Vector3d&)>;

/// Every facet between two elements, one dart each. O(darts).
template <int D>
std::vector<Facet> inner_facets(const MssModel<D>& m);

/// The inner facets given by their mesh point indices (3 or 4 per face, in order around it; 2
/// per edge of a 2D mesh); a facet an earlier cut already separated is skipped. A facet that
/// refinement has split since gives its pieces: the inner facets whose particles all lie on it
/// at rest. Throws physics::InputError naming the first list that is no facet between two
/// elements (no such face, a boundary face, or a refined one whose pieces are all cut already).
/// O(darts + faces), plus O(darts) for each refined one.
template <int D>
std::vector<Facet> facets_with_points(const MssModel<D>& m, std::span<const std::vector<std::uint32_t>> faces);

/// Inner facets whose two elements have their rest centroids strictly on opposite sides of the
/// plane (point, normal): the mesh facets nearest the plane, which separate the body along it.
/// With `within`, only facets whose rest centroid lies in it. O(darts).
template <int D>
std::vector<Facet> facets_across_plane(const MssModel<D>& m, const Eigen::Vector3d& point, const Eigen::Vector3d& normal,
                                       const Region& within = {});

/// Inner facets all of whose points are among `points` (mesh point indices): a cut along a
/// path or zone of selected particles, as the paper's tool does. O(darts).
template <int D>
std::vector<Facet> facets_among_points(const MssModel<D>& m, std::span<const std::uint32_t> points);

/// Live elements whose rest centroid lies in the region. O(elements).
template <int D>
std::vector<Index> elements_in(const MssModel<D>& m, const Region& region);

/// Unsews the facets (those already free are skipped). A facet between elements of different
/// levels (a level jump, with T-junctions of the coarser element on it) is cut after its coarser
/// side has been refined to the finer side's level, as the finer facets it then became: every
/// particle keeps an element that weighs it, the T-junctions on the cut become corners (free
/// particles) and mass and linear momentum are conserved exactly (the refinement's). Throws
/// physics::InputError, before any change, for a dead dart or a level jump whose coarser element
/// is no quad (2-map) or hexahedron. O(facets + touched cells); with level jumps, plus
/// O(darts + inner facets · facets) per round of refinement.
template <int D>
CutReport cut(MssModel<D>& m, std::span<const Facet> facets);

/// Unsews every facet joining the elements to elements not listed, so that they come out as
/// one piece (or several, if they do not touch); with `remove`, erases the freed pieces with the
/// particles and springs no other element uses, and compacts the model's arrays.
/// O(elements' cells).
template <int D>
CutReport pierce(MssModel<D>& m, std::span<const Index> elements, bool remove);

}  // namespace sewn::refine
