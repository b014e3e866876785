#include "sewn/apps/motion_keys.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include <Eigen/Geometry>

#include "sewn/apps/scene.hpp"

namespace sewn::app {

Field motion_schema() {
  Field rotate = field("rotate", Kind::object);
  rotate.doc("A rotation of the selection at a constant rate about an axis through `center` (the centre moves with `velocity`).")
      .members({field("axis", Kind::vec3).required().doc("Direction of the axis (any length but zero; right-hand rule)."),
                field("center", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("A point of the axis when the entry starts."),
                field("rate", Kind::number).unit("rad/s").required().at_least(-1e6).at_most(1e6).doc("Angular speed.")});
  Field m = field("move", Kind::object);
  m.doc("A prescribed rigid motion of the particles in `where` from `from` to `until`: with τ the time spent in the entry, "
        "x(τ) = center + velocity·τ + R(axis, rate·τ)(x₀ − center), x₀ where the particle was when the entry started. "
        "The particles are held on every axis for the whole run (before `from` where they start, after `until` in the "
        "entry's end pose) and reach x(t) exactly at every step, with every integrator (Dirichlet nodes: their velocity is "
        "set to the step's displacement over h); what they touch follows through the elastic forces. A rod's twist angles "
        "on them stay free. Entries may drive the same particles at disjoint times (they chain in time order), not at "
        "overlapping ones; a particle cannot be both driven and in `fixed`. Not available with `cuts` or `refinement` yet "
        "(both renumber or duplicate particles). The work a motion does is not counted in frames.csv's `external_work`: "
        "its energy balance, `energy_ratio_max` and `energy_rises` take it for energy the integrator created.")
      .members({selector_schema("where", "Particles to drive.").required(),
                field("velocity", Kind::vec3).unit("m/s").fallback({0.0, 0.0, 0.0}).at_least(-1e6).at_most(1e6).doc("Translation velocity."),
                rotate,
                field("from", Kind::number).unit("s").fallback(0.0).at_least(0).doc("When the motion starts."),
                field("until", Kind::number).unit("s").above(0)
                    .doc("When it stops (after `from`; default: the end of the run). The particles then stay where it left them.")});
  return field("motion", Kind::array).of(m).fallback(nlohmann::json::array()).doc("Prescribed rigid motions of selected particles (Dirichlet conditions that move): the 2019 paper's turned frisbee rim, driven jellyfish body, swimming anglerfish head.");
}

std::vector<MotionSpec> read_motion(const nlohmann::json& j, const Field& schema, const std::string& file,
                                    std::vector<Selector>& where) {
  const Field& element = *schema.element_;
  std::vector<MotionSpec> out;
  where.clear();
  for (std::size_t k = 0; k < j.size(); ++k) {
    const std::string path = "motion[" + std::to_string(k) + "]";
    Reader r(j[k], element);
    MotionSpec s;
    s.velocity = r.vec3("velocity");
    s.from = r.number("from");
    if (r.has("until")) {
      s.until = r.number("until");
      if (!(s.until > s.from))
        throw SceneError(file, path + ".until", "must be after `from` (" + std::to_string(s.from) + " s), got " + std::to_string(s.until) + " s");
    }
    if (r.has("rotate")) {
      Reader rr(r["rotate"], *element.member("rotate"));
      const auto a = rr.vec3("axis"), c = rr.vec3("center");
      const Eigen::Vector3d axis(a[0], a[1], a[2]);
      if (!(axis.norm() > 0)) throw SceneError(file, path + ".rotate.axis", "must not be zero");
      s.axis = axis.normalized();
      s.center = Eigen::Vector3d(c[0], c[1], c[2]);
      s.rate = rr.number("rate");
    }
    if (s.rate == 0 && s.velocity == std::array<double, 3>{0, 0, 0})
      throw SceneError(file, path, "moves nothing (zero velocity and no rotation): hold particles with `fixed` instead");
    where.push_back(read_selector(j[k].at("where"), *element.member("where")));
    out.push_back(s);
  }
  return out;
}

MotionDriver::MotionDriver(std::vector<MotionSpec> specs, const std::vector<std::vector<physics::Index>>& nodes,
                           physics::NodeTable& table, const std::string& file, const std::function<std::string(physics::Index)>& name)
    : specs_(std::move(specs)) {
  std::map<physics::Index, std::vector<std::uint32_t>> by_node;
  for (std::size_t k = 0; k < nodes.size(); ++k)
    for (physics::Index i : nodes[k]) by_node[i].push_back(static_cast<std::uint32_t>(k));
  for (auto& [node, ks] : by_node) {
    std::stable_sort(ks.begin(), ks.end(), [&](std::uint32_t a, std::uint32_t b) { return specs_[a].from < specs_[b].from; });
    for (std::size_t q = 1; q < ks.size(); ++q)
      if (specs_[ks[q]].from < specs_[ks[q - 1]].until)
        throw SceneError(file, "motion[" + std::to_string(std::max(ks[q], ks[q - 1])) + "].where",
                         "drives " + (name ? name(node) : "particle " + std::to_string(node)) + ", which motion[" + std::to_string(std::min(ks[q], ks[q - 1])) +
                             "] drives at overlapping times: one particle follows one motion at a time");
    table.fix(node, physics::all_axes);
    driven_.push_back({node, table.position(node), ks});
  }
}

Eigen::Vector3d MotionDriver::position(std::size_t i, double t) const {
  const Driven& d = driven_[i];
  Eigen::Vector3d x = d.x0;
  for (std::uint32_t k : d.specs) {
    const MotionSpec& s = specs_[k];
    if (t <= s.from) break;  // later entries start later still
    const double tau = std::min(t, s.until) - s.from;
    const Eigen::Vector3d v(s.velocity[0], s.velocity[1], s.velocity[2]);
    x = s.center + v * tau + Eigen::AngleAxisd(s.rate * tau, s.axis) * (x - s.center);
  }
  return x;
}

void MotionDriver::drive(physics::NodeTable& table, double t, double h) const {
  for (std::size_t i = 0; i < driven_.size(); ++i)
    table.set_velocity(driven_[i].node, (position(i, t + h) - table.position(driven_[i].node)) / h);
}

}  // namespace sewn::app
