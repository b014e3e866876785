#include "run_checkpoint.hpp"

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

void require_checkpointable(const Scene& scene, const physics::MssModel<3>& model, bool simulates_rods,
                            const std::string& option) {
  if (scene.refinement.enabled)
    throw SceneError(scene.file, "refinement",
                     option + " is not available with adaptive refinement yet: the hierarchy and its T-junctions are not saved in checkpoints");
  if (simulates_rods)
    throw SceneError(scene.file, "model.type",
                     option + " is not available with rods yet: their reference frames and twist are not saved in checkpoints");
  if (scene.model != "mass-spring" && !scene.cuts.empty())
    throw SceneError(scene.file, "cuts",
                     option + " is not available when a \"" + scene.model +
                         "\" model cuts yet: a resumed run would not move its elements onto the duplicated particles");
  // Newton's backward Euler starts every step afresh (from x + h·v, with no watchdog), and the
  // midpoint integrator's history is in checkpoints; only the linear solver's is not.
  if (scene.integrator != "implicit") return;
  const auto asked = physics::solve::parse_backend(scene.solver);
  const auto b = asked == physics::solve::Backend::automatic ? physics::solve::default_backend(model.nodes().size()) : asked;
  if (b != physics::solve::Backend::jacobi)
    throw SceneError(scene.file, "integrator.solver",
                     option + " is not available with the \"" + std::string(physics::solve::to_string(b)) +
                         "\" solver yet: the factorization it keeps across steps is not saved in checkpoints (use \"jacobi\")");
}

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

void replay_cuts(physics::MssModel<3>& model, const Checkpoint& c, const std::string& file) {
  for (std::size_t k = 0; k < c.cuts.size(); ++k) {
    const AppliedCut& a = c.cuts[k];
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

}  // namespace sewn::app::detail
