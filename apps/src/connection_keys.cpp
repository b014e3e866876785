#include "sewn/apps/connection_keys.hpp"

namespace sewn::app {

namespace {

Field twisting_field() {
  return field("twisting", Kind::number).unit("N·m/rad").at_least(0)
      .doc("Point connections: twisting stiffness k_t per joint (E = ½k_t(δ − δ̄)², δ the twist about the joint's axis). Left out: auto, from the materials.");
}
Field bending_field() {
  return field("bending", Kind::number).unit("N·m/rad").at_least(0)
      .doc("Point connections: bending stiffness k_b per joint (E = ½k_bω², ω the tilt of one side's axis against the other's). Left out: auto.");
}

}  // namespace

Field connections_schema() {
  Field one = field("connection", Kind::object);
  one.doc("A joint named by place: every detected connection of `kind` at the mesh point nearest `at` (a curve: the whole curve the two bodies share through that point). Refused if no two bodies meet there that way.")
      .members({field("kind", Kind::string).one_of({"point", "curve"}).required().doc("`point`: bodies meeting at one node; `curve`: along shared edges."),
                field("at", Kind::vec3).unit("m").required().doc("A position of the joint's node (the nearest mesh point is taken; it must be within 1e-6 of the scene's size)."),
                twisting_field(), bending_field(),
                field("stiffness", Kind::number).unit("N/rad").at_least(0).doc("Curve connections: stiffness per unit length k (E = Σ ½k l̄ (δ − δ̄)² over the curve's edges). Left out: auto."),
                field("rigid", Kind::boolean).doc("This joint's auto stiffnesses × 1000 (default: the connections' `rigid`).")});
  Field c = field("connections", Kind::object);
  c.doc("Rotational energies where bodies of a continuum model meet (docs/connect.md): a conforming mesh shares the nodes, so without them a shell on a solid's line is hinged and a rod on a node pinned. Auto stiffnesses make a joint as stiff as one cell of the softer side: a rod edge's GJ/l̄ and EI/l̄; a shell's plate stiffness D = Eh³/(12(1−ν²)) (bending) and Gh³/3 (twisting); a solid tetrahedron's EI/ℓ, GJ/ℓ of a square section of its mean edge ℓ. Per unit length of a curve: D/w for a shell (w its triangle's height across the edge), GJ/l̄² for a rod, E w²/(12(1−ν²)) for a solid. With a rod side, the rods' twist angles become degrees of freedom (integrator `newton` only).")
      .members({field("detect", Kind::boolean).fallback(true).doc("Every detected point and curve connection (`sewn check` lists them) gets its energy; false: only `explicit` ones. Surface connections need none (the shell's own energies act on the shared faces)."),
                twisting_field(), bending_field(),
                field("curve_stiffness", Kind::number).unit("N/rad").at_least(0).doc("Curve connections: stiffness per unit length k. Left out: auto."),
                field("rigid", Kind::boolean).fallback(false).doc("Stiff joints: the auto stiffnesses × 1000 (a penalty: the joint turns 1000 times less than one cell of the softer side would)."),
                field("update", Kind::string).one_of({"incremental_ii", "incremental_i"}).fallback("incremental_ii").doc("How the twist angle is followed from step to step (PHYSICS_NOTES §3.5); either needs each step's increment below π."),
                field("explicit", Kind::array).of(one).items(0, 100000).fallback(nlohmann::json::array()).doc("Joints named by place, with their own stiffnesses (they win over `detect`'s).")});
  return c;
}

ConnectionsSpec read_connections(const nlohmann::json& j, const Field& schema, const std::string& file) {
  ConnectionsSpec s;
  s.enabled = true;
  const Reader r(j, schema);
  s.detect = r.boolean("detect");
  if (r.has("twisting")) s.twisting = r.number("twisting");
  if (r.has("bending")) s.bending = r.number("bending");
  if (r.has("curve_stiffness")) s.curve_stiffness = r.number("curve_stiffness");
  s.rigid = r.boolean("rigid");
  s.update = r.string("update");
  const Field& one = *schema.member("explicit")->element_;
  for (std::size_t k = 0; k < r["explicit"].size(); ++k) {
    const Reader e(r["explicit"][k], one);
    const std::string path = "model.connections.explicit[" + std::to_string(k) + "]";
    ExplicitConnectionSpec x;
    x.kind = e.string("kind");
    x.at = e.vec3("at");
    if (e.has("twisting")) x.twisting = e.number("twisting");
    if (e.has("bending")) x.bending = e.number("bending");
    if (e.has("stiffness")) x.stiffness = e.number("stiffness");
    if (e.has("rigid")) x.rigid = e.boolean("rigid");
    if (x.kind == "point" && x.stiffness) throw SceneError(file, path + ".stiffness", "a point connection has `twisting` and `bending`, not a stiffness per length");
    if (x.kind == "curve" && (x.twisting || x.bending))
      throw SceneError(file, path + (x.twisting ? ".twisting" : ".bending"), "a curve connection has one `stiffness` per length, not twisting and bending");
    s.explicit_connections.push_back(x);
  }
  return s;
}

}  // namespace sewn::app
