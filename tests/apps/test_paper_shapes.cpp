// The 2019 paper's scene meshes (apps/paper_shapes.hpp): the published counts where PHYSICS_NOTES
// §5 finds them consistent, the stated proxies elsewhere, a valid map of every part together,
// the joints where the parts meet, and the committed scenes/meshes/s04_*.msh equal to what the
// generator writes now.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>
#include <sstream>
#include <string>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/paper_shapes.hpp"
#include "sewn/physics/solve/linear_solver.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/cmap/build.hpp"
#include "sewn/cmap/cmap.hpp"
#include "sewn/io/geometry.hpp"
#include "sewn/io/write_gmsh.hpp"
#include "minimal_scene.hpp"
#include "scratch.hpp"

namespace test_paper_shapes {

namespace {

struct Counts {
  std::uint32_t points, segments, triangles, tets;
};

Counts counts(const sewn::IndexedMesh& m) {
  const auto d = m.count_by_dimension();
  return {m.num_points(), d[1], d[2], d[3]};
}

// Every cell simulated as its dimension says (the scenes' model.groups name each part so).
std::vector<sewn::app::CellModel> all_simulated(const sewn::IndexedMesh& m) {
  std::vector<sewn::app::CellModel> models;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c) {
    const int d = sewn::cell_dimension(m.types[c]);
    models.push_back(d == 1 ? sewn::app::CellModel::rod : d == 2 ? sewn::app::CellModel::shell : sewn::app::CellModel::solid);
  }
  return models;
}

std::uint32_t found(const sewn::app::MeshConnections& c, sewn::connect::ConnectionKind k, sewn::connect::Body a,
                    sewn::connect::Body b) {
  return c.found.counts[static_cast<std::size_t>(k)][static_cast<std::size_t>(sewn::connect::body_pair_index(a, b))];
}

// The last row of a frames.csv as column name -> value.
std::map<std::string, double> last_row(const std::filesystem::path& csv) {
  std::ifstream in(csv);
  std::string header, line, last;
  std::getline(in, header);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::map<std::string, double> row;
  std::stringstream h(header), v(last);
  std::string name, value;
  while (std::getline(h, name, ',') && std::getline(v, value, ',')) row[name] = std::stod(value);
  return row;
}

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST_CASE("paper shapes: the published counts, or the stated proxies") {
  struct Expect {
    const char* name;
    Counts c;
  };
  // vertices / rod edges / shell faces / tets (PHYSICS_NOTES §5); the toy ball's and the
  // sandwich's points are the proxies' own (61 platform + 86 ball + 202 spring; 11 × 3 × 6)
  const Expect expect[] = {{"frisbee", {289, 64, 512, 0}},        {"umbrella", {3168, 198, 6144, 0}},
                           {"sticky_hands", {200, 19, 292, 0}},   {"jellyfish", {1465, 1273, 0, 454}},
                           {"toy_ball", {61 + 86 + 202, 203, 96, 226}}, {"sandwich", {198, 0, 160, 600}},
                           // from the figures (no published counts): 20 x 31 points; 175 body +
                           // 26 fin + 11 light + 19 antenna points
                           {"toy_tunnel", {620, 60, 1200, 0}},    {"anglerfish", {175 + 26 + 11 + 19, 20, 41, 576 + 16}}};
  REQUIRE(sewn::app::paper_shape_names().size() == std::size(expect));
  for (const Expect& e : expect) {
    CAPTURE(e.name);
    const sewn::app::PaperShape s = sewn::app::make_paper_shape(e.name);
    const Counts c = counts(s.mesh);
    CHECK(c.points == e.c.points);
    CHECK(c.segments == e.c.segments);
    CHECK(c.triangles == e.c.triangles);
    CHECK(c.tets == e.c.tets);
    CHECK(s.mesh.num_cells() == c.segments + c.triangles + c.tets);
    // every cell carries a named part
    for (const std::int32_t t : s.mesh.tags)
      CHECK(std::any_of(s.names.begin(), s.names.end(), [&](const sewn::io::TagName& n) { return n.tag == t; }));
    // no degenerate or inverted cell, no duplicate, no point left unused
    CHECK(sewn::io::find_geometry_issues(s.mesh, e.name).empty());
    std::vector<bool> used(s.mesh.num_points(), false);
    for (const std::uint32_t p : s.mesh.conn) used[p] = true;
    CHECK(std::count(used.begin(), used.end(), false) == 0);
    // one map of all the parts, valid, in one piece
    sewn::CMap<3, std::uint32_t> map;
    const sewn::BuildResult built = sewn::build(map, s.mesh);
    map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
    const auto report = map.validate();
    CHECK_MESSAGE(report.ok(), report.str());
    CHECK(built.unorientable_edges == 0);
    const auto simulated = sewn::app::simulated_complex(s.mesh, all_simulated(s.mesh));
    CHECK(simulated.components == 1);
  }
}

TEST_CASE("paper shapes: the joints are where the paper puts them") {
  using sewn::connect::Body;
  using K = sewn::connect::ConnectionKind;
  auto joints = [](const char* name) {
    const auto s = sewn::app::make_paper_shape(name);
    auto c = sewn::app::mesh_connections(s.mesh, all_simulated(s.mesh));
    REQUIRE(c.skipped.empty());
    return c;
  };
  // the frisbee's rim lies along all 64 boundary edges of the cloth
  auto c = joints("frisbee");
  CHECK(found(c, K::curve, Body::rod, Body::shell) == 64);
  CHECK(c.found.total() == 64);
  // the umbrella's ribs along 6 × 32 canopy edges; each rib root a triple rod joint
  c = joints("umbrella");
  CHECK(found(c, K::curve, Body::rod, Body::shell) == 192);
  CHECK(found(c, K::point, Body::rod, Body::rod) == 6 * 3);
  // the sticky hand's string meets the hand at its wrist only
  c = joints("sticky_hands");
  CHECK(found(c, K::point, Body::rod, Body::shell) == 1);
  CHECK(c.found.total() == 1);
  // jellyfish: 12 tentacles, 3 arm loops (2 ends each) on the body; the stalk on body and eye
  c = joints("jellyfish");
  CHECK(found(c, K::point, Body::rod, Body::solid) == 12 + 3 * 2 + 2);
  CHECK(c.found.total() == 20);
  // toy ball: the spring on the platform's centre and the ball's lowest point
  c = joints("toy_ball");
  CHECK(found(c, K::point, Body::rod, Body::shell) == 1);
  CHECK(found(c, K::point, Body::rod, Body::solid) == 1);
  CHECK(c.found.total() == 2);
  // sandwich: every sheet triangle lies on tetrahedron faces: surfaces only
  c = joints("sandwich");
  CHECK(found(c, K::surface, Body::shell, Body::solid) > 0);
  CHECK(found(c, K::curve, Body::shell, Body::solid) == 0);
  CHECK(found(c, K::point, Body::shell, Body::solid) == 0);
  // toy tunnel: both helices lie along the cloth's diagonals, every edge a curve joint
  c = joints("toy_tunnel");
  CHECK(found(c, K::curve, Body::rod, Body::shell) == 60);
  CHECK(c.found.total() == 60);
  // anglerfish: the fins along 3 + 4 + 3 + 3 body edges, the antenna on the head and the light
  c = joints("anglerfish");
  CHECK(found(c, K::curve, Body::shell, Body::solid) == 13);
  CHECK(found(c, K::point, Body::rod, Body::solid) == 2);
  CHECK(c.found.total() == 15);
}

TEST_CASE("paper shapes: the sticky hand's triangles all face one way (no fold from its fingers)") {
  const auto s = sewn::app::make_paper_shape("sticky_hands");
  for (std::uint32_t c = 0; c < s.mesh.num_cells(); ++c) {
    if (s.mesh.types[c] != sewn::CellType::triangle) continue;
    const auto t = s.mesh.cell(c);
    const auto &a = s.mesh.points[t[0]], &b = s.mesh.points[t[1]], &d = s.mesh.points[t[2]];
    // counter-clockwise in the (x, z) coordinates of the hand's plane, as the disc was built
    const double area2 = (b[0] - a[0]) * (d[2] - a[2]) - (b[2] - a[2]) * (d[0] - a[0]);
    CHECK(area2 > 0);
  }
}

TEST_CASE("paper shapes: the committed meshes are the generator's output") {
  for (const auto& name : sewn::app::paper_shape_names()) {
    CAPTURE(name);
    const auto s = sewn::app::make_paper_shape(name);
    const auto path = std::filesystem::path(SEWN_SOURCE_DIR) / "scenes" / "meshes" / ("s04_" + name + ".msh");
    REQUIRE(std::filesystem::exists(path));
    CHECK(read_text(path) == sewn::io::gmsh_text(s.mesh, s.names));
  }
}

TEST_CASE("paper scenes: a few steps each, Newton converged, energy finite, the map of the scene valid") {
  // run() throws NewtonError when a step's Newton iteration does not converge within the
  // scene's limit, so a run that returns took every step to the scene's tolerance.
  for (const std::string name : {"frisbee", "sticky_hands", "toy_ball", "sandwich", "jellyfish", "toy_tunnel", "anglerfish"}) {
    CAPTURE(name);
    const auto file = std::filesystem::path(SEWN_SOURCE_DIR) / "scenes" / ("s04_" + name + ".json");
    const sewn::app::Scene scene = sewn::app::load_scene(file.string());
    CHECK(scene.integrator == "newton");
    const sewn::app::Assembly a = sewn::app::assemble(scene);
    sewn::CMap<3, std::uint32_t> map;
    const sewn::BuildResult built = sewn::build(map, a.mesh);
    map.create_attributes<0>([&](sewn::Dart d) { return built.vertex_of_dart[d.index()]; });
    const auto report = map.validate();
    CHECK_MESSAGE(report.ok(), report.str());
    sewn::app::RunOptions opt;
    opt.out = sewn::test::scratch("paper_shapes/" + name);
    opt.until = 3 * scene.step;
    opt.frames = 3;
    opt.quiet = true;
    sewn::app::Scene quick = scene;
    quick.write_picture = false;
    const sewn::app::RunSummary sum = sewn::app::run(quick, opt);
    CHECK(sum.steps == 3);
    CHECK(sum.newton_iterations >= 3);  // at least one iteration per step (every scene starts moving)
    const auto row = last_row(opt.out / "frames.csv");
    REQUIRE(row.count("total_energy") == 1);
    CHECK(std::isfinite(row.at("total_energy")));
    CHECK(std::isfinite(row.at("kinetic_energy")));
    CHECK(row.at("kinetic_energy") > 0);
    CHECK(row.at("inverted") == 0);
    std::filesystem::remove_all(opt.out);
  }
}

TEST_CASE("integrator.solver ldlt: Newton's direct solve, refused with the other integrators by key") {
  auto j = sewn::app::test::minimal();
  j["integrator"] = {{"type", "newton"}, {"solver", "ldlt"}};
  CHECK(sewn::app::parse_scene(j, "s.json").solver == "ldlt");
  j["integrator"]["type"] = "implicit";
  try {
    (void)sewn::app::parse_scene(j, "s.json");
    FAIL("accepted ldlt with the implicit integrator");
  } catch (const sewn::app::SceneError& e) {
    CHECK(e.path() == "integrator.solver");
    CHECK(e.reason() == "\"ldlt\" solves the Newton systems of integrator.type \"newton\" only (this scene's is \"implicit\")");
  }
}

TEST_CASE("integrator.solver with newton: hypre-pcg, petsc and sa-pcg are refused by key, not replaced by block-Jacobi CG") {
  auto j = sewn::app::test::minimal();
  for (const char* name : {"hypre-pcg", "petsc", "sa-pcg"}) {
    CAPTURE(name);
    j["integrator"] = {{"type", "newton"}, {"solver", name}};
    try {
      (void)sewn::app::parse_scene(j, "s.json");
      FAIL("accepted a solver that Newton does not use");
    } catch (const sewn::app::SceneError& e) {
      CHECK(e.path() == "integrator.solver");  // a build without the backend refuses it too, naming the build
    }
  }
  if (!sewn::physics::solve::available(sewn::physics::solve::Backend::cholmod)) return;  // both need CHOLMOD
  for (const char* name : {"cholmod", "cholmod-pcg"}) {
    j["integrator"] = {{"type", "newton"}, {"solver", name}};
    CHECK(sewn::app::parse_scene(j, "s.json").solver == name);
  }
}

TEST_CASE("paper shapes: an unknown name is refused with the known ones") {
  CHECK_THROWS_WITH_AS(sewn::app::make_paper_shape("kite"),
                       "no paper shape 'kite' (known: frisbee, umbrella, sticky_hands, jellyfish, toy_ball, sandwich, toy_tunnel, anglerfish)",
                       std::invalid_argument);
}

}  // namespace test_paper_shapes
