#include "run_checkpoint.hpp"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <iterator>
#include <span>
#include <type_traits>

#include "sewn/refine/cut.hpp"

namespace sewn::app::detail {

namespace {

// Feeds values to FNV-1a by their bytes.
struct Hasher {
  std::uint64_t h = fnv1a("");
  template <class T>
    requires std::is_arithmetic_v<T>
  void add(T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    h = fnv1a(std::string_view(b, sizeof(T)), h);
  }
  template <class T>
  void add(std::span<const T> values) {
    add(static_cast<std::uint64_t>(values.size()));
    h = fnv1a(std::string_view(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T)), h);
  }
};

}  // namespace

std::uint64_t model_hash(const physics::MssModel<3>& model) {
  Hasher h;
  h.add(model.map().num_darts());
  h.add(model.map().dart_capacity());
  const auto& nodes = model.nodes();
  h.add(nodes.size());
  h.add(nodes.num_alive());
  h.add(nodes.masses());
  h.add(nodes.fixed_masks());
  for (physics::Index i = 0; i < nodes.size(); ++i) {
    const Eigen::Vector3d r = model.rest_position(i);
    for (int k = 0; k < 3; ++k) h.add(r[k]);
    h.add(nodes.is_alive(i));
  }
  const auto& springs = model.springs();
  h.add(springs.size());
  for (physics::Index s = 0; s < springs.size(); ++s) {
    h.add(springs.is_alive(s));
    if (!springs.is_alive(s)) continue;
    h.add(springs.node_i(s));
    h.add(springs.node_j(s));
    h.add(springs.stiffness(s));
    h.add(springs.rest_length(s));
    h.add(springs.viscosity(s));
  }
  h.add(static_cast<std::uint64_t>(model.elements().size()));
  for (const auto& e : model.elements()) h.add(e.alive);
  return h.h;
}

std::uint64_t run_hash(const Scene& scene, const physics::MssModel<3>& model, std::uint64_t steps, std::uint32_t frames) {
  Hasher h;
  if (scene.file == "(default)") {
    h.h = fnv1a(default_scene_json(), h.h);
  } else {
    std::ifstream in(scene.file, std::ios::binary);
    const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    h.h = fnv1a(text, h.h);
  }
  h.add(model_hash(model));
  h.add(model.nodes().x());
  h.add(model.nodes().v());
  h.add(scene.step);
  h.add(steps);
  h.add(frames);
  return h.h;
}

void replay_cuts(physics::MssModel<3>& model, const RefinementRun* refinement, const Checkpoint& c, const std::string& file) {
  for (std::size_t k = 0; k < c.cuts.size(); ++k) {
    const AppliedCut& a = c.cuts[k];
    if (a.refinement != 0) {
      const std::string which = std::string("recorded ") + (a.refinement == 1 ? "refinement" : "coarsening") + " " + std::to_string(k + 1);
      if (!refinement) throw CheckpointError(file, which + " in a run of a scene that refines nothing");
      try {
        refinement->redo(model, a.refinement == 2, std::span<const physics::Index>(a.elements));
      } catch (const physics::InputError& e) {
        throw CheckpointError(file, which + " does not fit the scene's model: " + e.what());
      }
      continue;
    }
    const std::string which = "recorded cut " + std::to_string(k + 1) + " (cuts[" + std::to_string(a.spec) + "])";
    if (a.pierce) {
      for (std::uint32_t e : a.elements)
        if (e >= model.elements().size() || !model.elements()[e].alive)
          throw CheckpointError(file, which + " pierces element " + std::to_string(e) + ", which the model does not have");
      (void)refine::pierce(model, std::span<const physics::Index>(a.elements), a.remove);
      continue;
    }
    std::vector<refine::Facet> facets;
    for (std::size_t f = 0; f < a.darts.size(); ++f) {
      const Dart d(a.darts[f]);
      // a facet between volumes is unsewn along β3, one between 2D cells along β2
      const physics::Index e = model.map().is_alive(d) ? model.element_of(d) : physics::invalid_index;
      const bool volume = e != physics::invalid_index && (model.elements()[e].kind == physics::ElementKind::hexahedron ||
                                                          model.elements()[e].kind == physics::ElementKind::tetrahedron);
      if (e == physics::invalid_index || a.betas[f] != (volume ? 3 : 2))
        throw CheckpointError(file, which + " unsews dart " + std::to_string(a.darts[f]) + " along beta " + std::to_string(a.betas[f]) +
                                        ", which the model does not have");
      facets.push_back({d, a.betas[f]});
    }
    (void)refine::cut(model, facets);
  }
  if (model_hash(model) != c.model_hash)
    throw CheckpointError(file, "its cuts, applied to the scene's model, give a different model than the run had: "
                                "the scene or a mesh file changed since, or the checkpoint is corrupt");
}

std::size_t check_cut_schedule(const Checkpoint& c, std::span<const std::pair<double, std::size_t>> cuts, const std::string& file) {
  std::size_t done = 0;
  for (const AppliedCut& a : c.cuts) {
    if (a.refinement != 0) continue;
    if (done == cuts.size()) throw CheckpointError(file, "records more cuts than the scene schedules");
    if (a.spec != cuts[done].second) throw CheckpointError(file, "its cuts are not the scene's, in the scene's order");
    ++done;
  }
  return done;
}

namespace {

// The angle DOFs (values and rates) and each connection term's history.
void restore_angles_and_joints(physics::AngleTable& angles, const ConnectionParts& joints, const Checkpoint& c, const std::string& file) {
  if (c.angles.size() != angles.size())
    throw CheckpointError(file, "holds " + std::to_string(c.angles.size()) + " angle DOFs for a model of " + std::to_string(angles.size()));
  std::copy(c.angles.begin(), c.angles.end(), angles.values().begin());
  std::copy(c.angle_rates.begin(), c.angle_rates.end(), angles.rates().begin());
  auto restore = [&](auto* term, const std::vector<double>& h, const char* what) {
    if (!term) {
      if (!h.empty()) throw CheckpointError(file, std::string("holds ") + what + " history, and the scene's model has none");
      return;
    }
    try {
      term->restore(h);
    } catch (const physics::InputError& e) {
      throw CheckpointError(file, std::string("its ") + what + " history does not fit the scene's: " + e.what());
    }
  };
  restore(joints.points, c.point_connections, "point connection");
  restore(joints.curves, c.curve_connections, "curve connection");
}

}  // namespace

void restore_model(physics::MssModel<3>& model, const ContinuumParts& continuum, const ConnectionParts& joints, RefinementRun* refinement,
                   const Checkpoint& c, const std::string& file) {
  replay_cuts(model, refinement, c, file);
  if (refinement) {
    if (c.refinement.calm.size() > model.elements().size())
      throw CheckpointError(file, "holds " + std::to_string(c.refinement.calm.size()) + " calm counters for a model of " +
                                      std::to_string(model.elements().size()) + " elements");
    refinement->restore(c.refinement);
  }
  // the run moved its tetrahedra and shells onto the duplicated particles after each cut; once
  // after all of them gives the same node lists, as each follows the model's elements as they
  // end up, and retires the same hinges (a cut never sews an edge back)
  follow_cut(continuum, model);
  physics::NodeTable& nodes = model.nodes();
  if (c.x.size() != nodes.x().size())
    throw CheckpointError(file, "holds " + std::to_string(c.x.size() / 3) + " particles for a model of " + std::to_string(nodes.size()));
  std::copy(c.x.begin(), c.x.end(), nodes.x().begin());
  std::copy(c.v.begin(), c.v.end(), nodes.v().begin());
  restore_angles_and_joints(model.system().angles(), joints, c, file);
  if (!continuum.rods) {
    if (!c.rods.empty()) throw CheckpointError(file, "holds " + std::to_string(c.rods.size()) + " rods, and the scene's model has none");
    return;
  }
  try {
    continuum.rods->restore(c.rods);
  } catch (const physics::InputError& e) {
    throw CheckpointError(file, std::string("its rods do not fit the scene's: ") + e.what());
  }
}

}  // namespace sewn::app::detail
