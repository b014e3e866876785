#include "sewn/apps/obstacle_keys.hpp"

#include <cstdio>
#include <numbers>

#include <Eigen/Geometry>

#include "sewn/physics/errors.hpp"

namespace sewn::app {

Field obstacles_schema() {
  Field o = field("obstacle", Kind::object);
  o.doc("A rigid obstacle: every particle inside it is pushed out by the penalty E = ½ k d² (d: its depth inside; "
        "smooth, so both integrators use its Jacobian). A particle of mass m at rest sinks by m g / k; one arriving "
        "at speed v penetrates at most about v √(m/k). See physics/include/sewn/physics/obstacles/obstacles.hpp.")
      .select_by("type");
  o.members({field("type", Kind::string).required().doc("Kind of obstacle."),
             field("stiffness", Kind::number).unit("N/m").fallback(1e5).above(0).doc("Penalty stiffness k per particle.")});
  o.variant("plane", "The half-space behind a plane (the ground), optionally with smoothed Coulomb friction.",
            {field("point", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("A point of the plane."),
             field("normal", Kind::vec3).fallback({0.0, 0.0, 1.0}).doc("Normal pointing out of the obstacle, into free space (any length but zero)."),
             field("friction", Kind::number).fallback(0.0).at_least(0).doc("Coulomb coefficient μ (0: frictionless)."),
             field("friction_velocity", Kind::number).unit("m/s").fallback(1e-3).above(0)
                 .doc("Sliding speed below which friction is smoothed to a viscous law (IPC-style; sticking creeps at about this speed).")});
  o.variant("sphere", "A ball.",
            {field("center", Kind::vec3).unit("m").required().doc("Centre."),
             field("radius", Kind::number).unit("m").required().above(0).doc("Radius.")});
  o.variant("box", "An axis-aligned box.",
            {field("min", Kind::vec3).unit("m").required().doc("Lower corner."),
             field("max", Kind::vec3).unit("m").required().doc("Upper corner (each coordinate above min's).")});
  o.variant("cone", "A solid cone (the 2014 paper's spike): apex, axis into the solid, half angle, height.",
            {field("apex", Kind::vec3).unit("m").required().doc("Tip."),
             field("axis", Kind::vec3).fallback({0.0, 0.0, -1.0}).doc("From the apex into the cone (a spike pointing up: [0, 0, -1])."),
             field("half_angle", Kind::number).unit("rad").required().above(0).below(std::numbers::pi / 2).doc("Half opening angle."),
             field("height", Kind::number).unit("m").required().above(0).doc("Distance from the apex to the base.")});
  return field("obstacles", Kind::array).of(o).fallback(nlohmann::json::array()).doc("Rigid obstacles.");
}

std::vector<ObstacleSpec> read_obstacles(const nlohmann::json& j, const Field& schema, const std::string& file) {
  using namespace physics::obstacles;
  const Field& element = *schema.element_;
  std::vector<ObstacleSpec> out;
  for (std::size_t i = 0; i < j.size(); ++i) {
    const nlohmann::json& oj = j[i];
    const std::string path = "obstacles[" + std::to_string(i) + "]";
    const std::string type = oj.at("type").get<std::string>();
    Reader r(oj, element, type);
    auto v = [&](const char* key) {
      const auto a = r.vec3(key);
      return Vec3(a[0], a[1], a[2]);
    };
    auto nonzero = [&](const char* key) {
      const Vec3 a = v(key);
      if (a.norm() == 0) throw SceneError(file, path + "." + key, "must not be zero");
      return a;
    };
    ObstacleSpec spec;
    spec.stiffness = r.number("stiffness");
    spec.friction_velocity = 1e-3;
    if (type == "plane") {
      spec.shape = Plane{v("point"), nonzero("normal"), r.number("friction")};
      spec.friction_velocity = r.number("friction_velocity");
    } else if (type == "sphere") {
      spec.shape = Sphere{v("center"), r.number("radius")};
    } else if (type == "box") {
      const Vec3 lo = v("min"), hi = v("max");
      for (int a = 0; a < 3; ++a)
        if (!(hi[a] > lo[a])) throw SceneError(file, path + ".max", "must be above min on every axis");
      Box b;
      b.center = 0.5 * (lo + hi);
      b.half_extents = 0.5 * (hi - lo);
      spec.shape = b;
    } else {
      spec.shape = Cone{v("apex"), nonzero("axis"), r.number("half_angle"), r.number("height")};
    }
    // Anything the schema let through but the module refuses is still named by its path.
    try {
      physics::obstacles::Obstacles probe(spec.stiffness, spec.friction_velocity);
      (void)probe.add(spec.shape);
    } catch (const physics::InputError& e) {
      throw SceneError(file, path, e.what());
    }
    out.push_back(spec);
  }
  return out;
}

void add_obstacles(physics::System& sys, const std::vector<ObstacleSpec>& obstacles) {
  for (const ObstacleSpec& o : obstacles) {
    auto& term = sys.add<physics::obstacles::Obstacles>(o.stiffness, o.friction_velocity);
    (void)term.add(o.shape);
  }
}

std::vector<std::string> obstacle_start_warnings(std::span<const double> x, const std::vector<ObstacleSpec>& obstacles) {
  // A body meshed into an obstacle is shot out of it by the penalty in the first steps: a cube
  // half inside the ground plane was launched 1 m up in 0.5 s, with nothing said.
  const std::size_t n = x.size() / 3;
  const auto at = [&](std::size_t i) { return physics::obstacles::Vec3(x[3 * i], x[3 * i + 1], x[3 * i + 2]); };
  Eigen::AlignedBox3d box;
  for (std::size_t i = 0; i < n; ++i) box.extend(at(i));
  const double tol = n > 0 ? 1e-9 * box.diagonal().norm() : 0.0;
  std::vector<std::string> out;
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    std::size_t inside = 0, deepest = 0;
    double most = 0, energy = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double d = physics::obstacles::depth(obstacles[k].shape, at(i)).depth;
      if (!(d > tol)) continue;
      ++inside;
      energy += 0.5 * obstacles[k].stiffness * d * d;
      if (d > most) {
        most = d;
        deepest = i;
      }
    }
    if (inside == 0) continue;
    const auto p = at(deepest);
    char text[512];
    std::snprintf(text, sizeof text,
                  "obstacles[%zu] (%s): %zu particle(s) start inside it, the deepest %g m (particle %zu at (%g, %g, %g)); "
                  "its penalty holds %g J there, which the first steps turn into motion the scene did not supply: "
                  "start the bodies outside it",
                  k, std::string(physics::obstacles::type_name(obstacles[k].shape)).c_str(), inside, most, deepest, p.x(), p.y(),
                  p.z(), energy);
    out.emplace_back(text);
  }
  return out;
}

}  // namespace sewn::app
