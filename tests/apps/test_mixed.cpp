// Mixed-dimensional meshes: which cells a scene simulates (solids, shells, rods) and which are
// boundary labels, the continuum terms built on shared nodes, and `sewn check` reporting the
// simulated complex of a tetgen-style mesh with a face list.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>

#include <Eigen/Geometry>

#include "sewn/apps/cell_models.hpp"
#include "sewn/apps/continuum.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/io/cleanup.hpp"
#include "sewn/io/read.hpp"
#include "sewn/physics/rods/rods_term.hpp"
#include "sewn/physics/shells/shell_terms.hpp"
#include "sewn/physics/solids/tets.hpp"
#include "sewn/physics/solve/linear_solver.hpp"

#include "force_check.hpp"
#include "scratch.hpp"

namespace test_mixed {

using namespace sewn;
using namespace sewn::app;

namespace mixed_test {

// A block of 12 tetrahedra (tag 1); a flap of 4 triangles hanging from its bottom front edge
// (tag 2), sharing that edge's 3 nodes; a rod of 3 segments hanging from the flap's bottom
// middle point (tag 3); and two labels: a face of a tetrahedron (tag 4) and an edge of one (tag 5).
IndexedMesh block_flap_rod() {
  GridSpec g;
  g.spacing = {0.1, 0.1, 0.1};
  IndexedMesh m = tet_grid(2, 1, 1, TetSplit::kuhn6, g);
  for (auto& t : m.tags) t = 1;
  // grid point (i, j, k) = i + 3(j + 2k); the bottom front edge is points 0, 1, 2 (y = 0, z = 0)
  const std::uint32_t f0 = m.num_points();
  for (int i = 0; i < 3; ++i) m.points.push_back({0.1 * i, 0.0, -0.1});
  m.add_cell(CellType::triangle, {0, 1, f0 + 1}, 2);
  m.add_cell(CellType::triangle, {0, f0 + 1, f0}, 2);
  m.add_cell(CellType::triangle, {1, 2, f0 + 2}, 2);
  m.add_cell(CellType::triangle, {1, f0 + 2, f0 + 1}, 2);
  const std::uint32_t r0 = m.num_points();
  for (int k = 1; k <= 3; ++k) m.points.push_back({0.1 + 0.01 * k, 0.0, -0.1 - 0.05 * k});  // a slightly slanted rod
  m.add_cell(CellType::segment, {f0 + 1, r0}, 3);
  m.add_cell(CellType::segment, {r0, r0 + 1}, 3);
  m.add_cell(CellType::segment, {r0 + 1, r0 + 2}, 3);
  const auto tet0 = m.cell(0);
  m.add_cell(CellType::triangle, {tet0[0], tet0[1], tet0[2]}, 4);
  m.add_cell(CellType::segment, {tet0[0], tet0[1]}, 5);
  return m;
}

Scene mixed_scene() {
  Scene s;
  s.file = "mixed.json";
  s.model = "mixed";
  s.damping = "none";
  return s;
}

std::array<int, 5> count_models(const std::vector<CellModel>& m) {
  std::array<int, 5> n{};
  for (CellModel c : m) ++n[static_cast<std::size_t>(c)];
  return n;
}

std::string reason_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

// The sewn binary's standard output for `args`, and its exit code.
int sewn_stdout(const std::string& args, std::string& out) {
  const auto log = sewn::test::scratch("mixed/stdout.txt");
  const int status = std::system((std::string(SEWN_BINARY) + " " + args + " > " + log.string() + " 2>&1").c_str());
  std::ifstream in(log);
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  std::filesystem::remove(log);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}



TEST_CASE("cell models: faces and edges of higher cells are labels unless a group names them") {
  const IndexedMesh m = block_flap_rod();
  const auto embedded = io::embedded_cells(m);
  Scene s = mixed_scene();
  // label, mass-spring, solid, shell, rod
  CHECK(count_models(cell_models(m, embedded, s, "meshes[0]")) == std::array<int, 5>{2, 0, 12, 4, 3});
  s.model_groups = {{4, "", "shell", {}}, {5, "", "rod", {}}};
  CHECK(count_models(cell_models(m, embedded, s, "meshes[0]")) == std::array<int, 5>{0, 0, 12, 5, 4});
  s.model_groups = {{2, "", "label", {}}};
  CHECK(count_models(cell_models(m, embedded, s, "meshes[0]")) == std::array<int, 5>{6, 0, 12, 0, 3});
  Scene ms;  // mass-spring: the same labels, every other cell springs
  CHECK(count_models(cell_models(m, embedded, ms, "meshes[0]")) == std::array<int, 5>{2, 19, 0, 0, 0});

  s.model_groups = {{1, "", "shell", {}}};
  const std::string wrong = reason_of([&] { (void)cell_models(m, embedded, s, "meshes[0]"); });
  CHECK(wrong.find("model.groups[0].as: \"shell\" takes triangles only, but meshes[0] cell 0, of tag 1, is a tetrahedron") == 0);
  s.model = "solid";
  s.model_groups = {};
  CHECK(reason_of([&] { (void)cell_models(m, embedded, s, "meshes[0]"); }).find("model.type: \"solid\" needs tetrahedra only") == 0);
  s.model_groups = {{2, "", "label", {}}, {3, "", "rod", {}}};  // the other kinds named: accepted
  CHECK(count_models(cell_models(m, embedded, s, "meshes[0]")) == std::array<int, 5>{6, 0, 12, 0, 3});
  s.model_groups.push_back({9, "", "rod", {}});
  const GroupMatch match = match_groups(m, MeshNames{}, s);
  CHECK(match.named_a_cell == std::vector<bool>{true, true, false});
  CHECK(reason_of([&] { check_groups_used(s, match.named_a_cell, {}); }) == "model.groups[2].tag: no cell of any mesh carries tag 9");
}

TEST_CASE("simulated complex: components are the pieces that share a node") {
  const IndexedMesh m = block_flap_rod();
  Scene s = mixed_scene();
  const auto models = cell_models(m, io::embedded_cells(m), s, "m");
  const SimulatedComplex all = simulated_complex(m, models);
  CHECK(all.cells == std::array<std::uint32_t, 4>{0, 3, 4, 12});
  CHECK(all.components == 1);
  CHECK(all.points == m.num_points());
  REQUIRE(all.labels.size() == 2);
  CHECK(all.labels[0].tag == 4);
  CHECK(all.labels[0].dimension == 2);
  CHECK(all.labels[1].tag == 5);
  // without the flap, the rod hangs from nothing: two components; its points no longer count
  s.model_groups = {{2, "", "label", {}}};
  const SimulatedComplex split = simulated_complex(m, cell_models(m, io::embedded_cells(m), s, "m"));
  CHECK(split.components == 2);
  CHECK(split.points == m.num_points() - 2);
}

TEST_CASE("continuum on a mixed map: one node set, forces are the energy's gradient, rigid motions cost nothing") {
  const IndexedMesh m = block_flap_rod();
  const Scene s = mixed_scene();
  const auto models = cell_models(m, io::embedded_cells(m), s, "m");
  IndexedMesh sim;
  sim.points = m.points;
  std::vector<CellModel> sim_models;
  for (std::uint32_t c = 0; c < m.num_cells(); ++c)
    if (models[c] != CellModel::label) {
      sim.add_cell(m.types[c], m.cell(c), m.tags[c]);
      sim_models.push_back(models[c]);
    }
  std::vector<physics::MaterialParams> materials{{1e6, 0.3, 1000, 0.002, 1e-5, physics::ElongatedPolicy::refuse}};
  std::vector<std::uint32_t> material_of_cell(sim.num_cells(), 0);
  physics::MssOptions mo;
  mo.gravity.setZero();
  mo.damping = physics::DampingModel::none;
  physics::MssModel<3> model(sim, materials, material_of_cell, mo);
  const ContinuumParts parts = build_continuum(s, materials, sim, sim_models, std::vector<int>(sim.num_cells(), -1), model);
  physics::System& sys = model.system();
  CHECK(model.springs().num_alive() == 0);
  CHECK(model.nodes().size() == m.num_points());  // the flap and the rod share the block's and the flap's nodes
  REQUIRE(parts.rods != nullptr);
  CHECK(parts.rods->num_rods() == 1);
  CHECK(parts.rods->rod(0).num_edges() == 3);
  int tets = 0, membranes = 0, hinges = 0;
  for (const auto& t : sys.terms()) {
    if (auto* p = dynamic_cast<physics::solids::Tets*>(t.get())) tets += static_cast<int>(p->size());
    if (auto* p = dynamic_cast<physics::shells::Membranes*>(t.get())) membranes += static_cast<int>(p->size());
    if (auto* p = dynamic_cast<physics::shells::Hinges*>(t.get())) hinges += static_cast<int>(p->size());
  }
  CHECK(tets == 12);
  CHECK(membranes == 4);
  CHECK(hinges == 0);  // the default bending is "patch"
  // each of the flap's 3 interior edges seen from both its triangles; its top edge on the block is free
  const auto& pt = parts.patches;
  CHECK((pt.one ? pt.one->size() : 0) + 2 * (pt.two ? pt.two->size() : 0) + 3 * (pt.three ? pt.three->size() : 0) == 6);

  // a rigid rotation and translation of the whole: no energy, no force
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  for (physics::Index i = 0; i < model.nodes().size(); ++i)
    model.nodes().set_position(i, R * model.rest_position(i) + Eigen::Vector3d(0.3, -0.2, 1.0));
  sys.compute_forces();
  CHECK(std::abs(sys.potential_energy()) < 1e-9 * sys.energy_scale());
  double fmax = 0;
  for (physics::Index i = 0; i < model.nodes().size(); ++i) fmax = std::max(fmax, model.nodes().force(i).norm());
  CHECK(fmax < 1e-6);

  // a deformed state: every force is −∂E/∂x by central differences, on shared nodes too
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.01, 0.01);
  for (physics::Index i = 0; i < model.nodes().size(); ++i)
    model.nodes().set_position(i, model.rest_position(i) + Eigen::Vector3d(u(rng), u(rng), u(rng)));
  sys.compute_forces();
  std::vector<Eigen::Vector3d> f(model.nodes().size());
  for (physics::Index i = 0; i < model.nodes().size(); ++i) f[i] = model.nodes().force(i);
  const double h = 1e-6;
  double worst = 0, scale = 0;
  for (physics::Index i = 0; i < model.nodes().size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      worst = std::max(worst, std::abs(sewn::app::test::energy_slope(model, i, a, h) - f[i][a]));
      scale = std::max(scale, std::abs(f[i][a]));
    }
  }
  CAPTURE(worst);
  CAPTURE(scale);
  CHECK(scale > 1.0);
  CHECK(worst < 1e-5 * scale);
}

TEST_CASE("rods: segments chain through nodes of two, split at junctions, close into loops") {
  IndexedMesh m;
  // a star of three arms from point 0, and a separate triangle loop
  m.points = {{0, 0, 0}, {1, 0, 0}, {2, 0.1, 0}, {0, 1, 0}, {0, 2, 0.1}, {0, 0, 1}, {5, 0, 0}, {6, 0, 0}, {5.5, 1, 0}};
  for (auto [a, b] : std::vector<std::pair<std::uint32_t, std::uint32_t>>{{0, 1}, {1, 2}, {0, 3}, {3, 4}, {0, 5}, {6, 7}, {7, 8}, {8, 6}})
    m.add_cell(CellType::segment, {a, b}, 3);
  const Scene s = mixed_scene();
  const auto models = cell_models(m, io::embedded_cells(m), s, "m");
  std::vector<physics::MaterialParams> materials{{1e9, 0.3, 1000, 1, 1e-6, physics::ElongatedPolicy::refuse}};
  physics::MssOptions mo;
  mo.damping = physics::DampingModel::none;
  physics::MssModel<3> model(m, materials, {}, mo);
  const ContinuumParts parts = build_continuum(s, materials, m, models, std::vector<int>(m.num_cells(), -1), model);
  REQUIRE(parts.rods != nullptr);
  REQUIRE(parts.rods->num_rods() == 4);
  int closed = 0, edges = 0;
  for (physics::Index r = 0; r < 4; ++r) {
    closed += parts.rods->rod(r).closed();
    edges += parts.rods->rod(r).num_edges();
  }
  CHECK(closed == 1);
  CHECK(edges == 8);
  // the rods written to .vtu: one chain per rod (a closed one back to its start), every node
  // of a rod with a unit frame (m1, m2) normal to the node's tangent
  model.system().compute_forces();
  const RodOutput out = rod_output(parts, model);
  REQUIRE(out.chains.size() == 4);
  std::size_t chain_edges = 0;
  for (physics::Index r = 0; r < 4; ++r) {
    const auto& chain = out.chains[r];
    chain_edges += chain.size() - 1;
    CHECK((chain.front() == chain.back()) == parts.rods->rod(r).closed());
    for (std::size_t k = 0; k < chain.size(); ++k) {
      const physics::Index v = chain[k];
      // the node's tangent: its neighbours along the chain (one of them at an open end)
      const std::size_t prev = k > 0 ? k - 1 : (chain.front() == chain.back() ? chain.size() - 2 : k);
      const std::size_t next = k + 1 < chain.size() ? k + 1 : (chain.front() == chain.back() ? 1 : k);
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      if (prev != k) t += (model.nodes().position(v) - model.nodes().position(chain[prev])).normalized();
      if (next != k) t += (model.nodes().position(chain[next]) - model.nodes().position(v)).normalized();
      t.normalize();
      const Eigen::Vector3d m1(out.m1[v][0], out.m1[v][1], out.m1[v][2]), m2(out.m2[v][0], out.m2[v][1], out.m2[v][2]);
      if (v == 0) continue;  // the junction: the frame of the first rod through it
      CAPTURE(v);
      CHECK(std::abs(m1.norm() - 1) < 1e-12);
      CHECK(std::abs(m1.dot(t)) < 1e-12);
      CHECK((m2 - t.cross(m1)).norm() < 1e-12);
    }
  }
  CHECK(chain_edges == 8);
}

TEST_CASE("scene keys of model groups: sections for rods only, labels only with mass-spring") {
  auto scene = [](const std::string& model) {
    return nlohmann::json::parse(R"({"materials": {"m": {"young": 1e6, "density": 1000}},
      "meshes": [{"type": "polyline", "material": "m", "points": [[0,0,0],[1,0,0],[2,0,0]]}],
      "damping": {"model": "none"}, "model": )" + model + "}");
  };
  auto error = [](const nlohmann::json& j) { return reason_of([&] { (void)parse_scene(j, "g.json"); }); };
  CHECK(error(scene(R"({"type": "mixed", "groups": [{"tag": 0, "as": "rod", "semi_axes": [0.01, 0.005]}]})")) == "accepted");
  CHECK(error(scene(R"({"type": "mixed", "groups": [{"tag": 0, "as": "shell", "radius": 0.01}]})")) ==
        "model.groups[0].radius: a section applies to rods only, not to \"shell\"");
  CHECK(error(scene(R"({"type": "mixed", "groups": [{"tag": 0, "as": "rod", "radius": 0.01, "semi_axes": [1, 1]}]})")) ==
        "model.groups[0].semi_axes: give either radius or semi_axes, not both");
  CHECK(error(scene(R"({"groups": [{"tag": 0, "as": "rod"}]})")).find("model.groups[0].as: \"rod\" cannot be combined with model.type \"mass-spring\"") == 0);
  CHECK(error(scene(R"({"type": "mixed", "groups": [{"tag": 0, "as": "cable"}]})")).find("model.groups[0].as") == 0);
  const Scene s = parse_scene(scene(R"({"type": "mixed", "groups": [{"tag": 0, "as": "rod", "radius": 0.01}]})"), "g.json");
  REQUIRE(s.model_groups.size() == 1);
  CHECK(s.model_groups[0].semi_axes == std::array<double, 2>{0.01, 0.01});
}

TEST_CASE("sewn check reports the simulated complex of a mesh with a face list, and its labels") {
  std::string out;
  const std::string data = std::string(SEWN_SOURCE_DIR) + "/tests/apps/data/box_faces.mesh";
  REQUIRE(sewn_stdout("check " + data, out) == 0);
  CAPTURE(out);
  CHECK(out.find("292 cells (144 volumes, 116 surface cells, 32 segments)") != std::string::npos);
  CHECK(out.find("simulated: 144 volumes, 0 surface cells, 0 segments on 62 points; 1 component") != std::string::npos);
  CHECK(out.find("1 component; 116 boundary faces") != std::string::npos);  // the map of the tetrahedra alone
  CHECK(out.find("  tag 3: 22 surface cells") != std::string::npos);
  CHECK(out.find("1 component, χ = 1") != std::string::npos);

  const std::string fin = std::string(SEWN_SOURCE_DIR) + "/scenes/meshes/fin.msh";
  REQUIRE(sewn_stdout("check " + fin, out) == 0);
  CAPTURE(out);
  CHECK(out.find("simulated: 411 volumes, 34 surface cells, 4 segments") != std::string::npos);
  CHECK(out.find("; 1 component (cells sharing a point)") != std::string::npos);
  CHECK(out.find("  tag 4 \"top\": ") != std::string::npos);
  // the fin along 4 edges of the block, the mast from one node of the fin
  CHECK(out.find("3 components):\n  point: 1 rod-shell\n  curve: 4 shell-solid\n") != std::string::npos);
  REQUIRE(sewn_stdout("check " + fin + " --json", out) == 0);
  const auto j = nlohmann::json::parse(out.substr(out.find("\n{") + 1));  // after the text (stderr, unbuffered)
  CHECK(j["connections"]["curve"]["shell-solid"] == 4);
  CHECK(j["connections"]["point"]["rod-shell"] == 1);
  CHECK(j["connections"]["surface"].empty());
}

TEST_CASE("a tetgen -f style list of every face and edge, interior ones included, is all labels: one solid") {
  // tetgen -f -e writes every face and edge of the tetrahedralisation, not only the boundary's:
  // each must be a label, so the simulated complex is the tetrahedra alone, one component,
  // for the mass-spring, solid and mixed models alike (as `sewn check` reports and `sewn run`
  // builds). Checked by hand on a 49 736-tet Gmsh box with its 95 832 interior faces added.
  IndexedMesh m = io::read_mesh(std::string(SEWN_SOURCE_DIR) + "/tests/apps/data/box_faces.mesh");
  const std::uint32_t cells = m.num_cells();
  std::set<std::array<std::uint32_t, 3>> faces;
  std::set<std::array<std::uint32_t, 2>> edges;
  std::uint32_t tets = 0;
  for (std::uint32_t c = 0; c < cells; ++c) {
    if (m.types[c] != CellType::tetrahedron) continue;
    ++tets;
    const auto v = m.cell(c);
    for (int skip = 0; skip < 4; ++skip) {
      std::array<std::uint32_t, 3> f{};
      for (int k = 0, j = 0; k < 4; ++k)
        if (k != skip) f[static_cast<std::size_t>(j++)] = v[static_cast<std::size_t>(k)];
      std::sort(f.begin(), f.end());
      faces.insert(f);
    }
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b)
        edges.insert({std::min(v[static_cast<std::size_t>(a)], v[static_cast<std::size_t>(b)]),
                      std::max(v[static_cast<std::size_t>(a)], v[static_cast<std::size_t>(b)])});
  }
  for (const auto& f : faces) (void)m.add_cell(CellType::triangle, {f[0], f[1], f[2]}, 99);
  for (const auto& e : edges) (void)m.add_cell(CellType::segment, {e[0], e[1]}, 98);
  REQUIRE(faces.size() == (4 * tets + 116) / 2);  // interior faces twice, the 116 boundary ones once
  const auto embedded = io::embedded_cells(m);
  Scene solid = mixed_scene();
  solid.model = "solid";
  for (const Scene& s : {mixed_scene(), solid, Scene{}}) {
    CAPTURE(s.model);
    const auto models = cell_models(m, embedded, s, "meshes[0]");
    const SimulatedComplex sc = simulated_complex(m, models);
    CHECK(sc.cells == std::array<std::uint32_t, 4>{0, 0, 0, tets});
    CHECK(sc.components == 1);
    std::uint32_t labelled = 0;
    for (const auto& l : sc.labels) labelled += l.cells;
    CHECK(labelled == m.num_cells() - tets);
  }
}

TEST_CASE("sewn run simulates what sewn check reports on a mesh with a face list: its tetrahedra only") {
  // box_faces.mesh: 144 tetrahedra on 62 points with 116 boundary triangles and 32 edges as
  // cells of their own; `sewn check` reports 144 volumes (above). The run's frames.csv counts
  // the particles and elements it simulated, for the solid and the default mass-spring model.
  const auto dir = sewn::test::scratch("mixed/run");
  std::filesystem::create_directories(dir);
  const std::string mesh = std::string(SEWN_SOURCE_DIR) + "/tests/apps/data/box_faces.mesh";
  for (const std::string model : {R"({"type": "solid"})", R"({"type": "mass-spring"})"}) {
    CAPTURE(model);
    const auto scene = dir / "scene.json";
    std::ofstream(scene) << R"({"materials": {"rubber": {"young": 1e6, "poisson": 0.3, "density": 1000}},
      "meshes": [{"type": "file", "path": ")" << mesh << R"(", "material": "rubber"}],
      "gravity": [0, 0, -9.81], "damping": {"model": "rayleigh", "alpha": 1.0}, "model": )" << model << R"(,
      "integrator": {"type": "newton", "step": 1e-3}, "duration": 0.002,
      "output": {"frames": 2, "vtu": false, "picture": {"enabled": false}}})";
    std::string out;
    REQUIRE(sewn_stdout("run " + scene.string() + " --out " + (dir / "out").string() + " --quiet", out) == 0);
    std::ifstream csv(dir / "out" / "frames.csv");
    std::string header, row, last;
    std::getline(csv, header);
    while (std::getline(csv, row))
      if (!row.empty()) last = row;
    auto field = [](const std::string& line, std::size_t k) {
      std::stringstream ss(line);
      std::string f;
      for (std::size_t i = 0; i <= k; ++i) std::getline(ss, f, ',');
      return f;
    };
    auto column = [&](const std::string& name) {
      for (std::size_t k = 0;; ++k) {
        const std::string h = field(header, k);
        REQUIRE(!h.empty());
        if (h == name) return std::stod(field(last, k));
      }
    };
    CHECK(column("particles") == 62);
    CHECK(column("elements") == 144);
  }
  std::filesystem::remove_all(dir);
}

TEST_CASE("connections of a mixed mesh: the flap's edge line is curves, the rod's node a point, a face a surface") {
  const IndexedMesh m = block_flap_rod();
  Scene s = mixed_scene();
  auto found = [&] { return mesh_connections(m, cell_models(m, io::embedded_cells(m), s, "m")); };
  auto count = [](const MeshConnections& c, connect::ConnectionKind k, connect::Body a, connect::Body b) {
    return c.found.counts[static_cast<std::size_t>(k)][static_cast<std::size_t>(connect::body_pair_index(a, b))];
  };
  using connect::Body;
  using connect::ConnectionKind;
  MeshConnections c = found();
  REQUIRE(c.skipped.empty());
  CHECK(count(c, ConnectionKind::curve, Body::shell, Body::solid) == 2);  // the flap shares the edges (0, 1), (1, 2)
  CHECK(count(c, ConnectionKind::point, Body::rod, Body::shell) == 1);
  CHECK(c.found.total() == 3);
  // the labels simulated: the tet face as a shell lies on the block, the tet edge as a rod along it
  s.model_groups = {{4, "", "shell", {}}, {5, "", "rod", {}}};
  c = found();
  CHECK(count(c, ConnectionKind::surface, Body::shell, Body::solid) == 1);
  CHECK(count(c, ConnectionKind::curve, Body::rod, Body::solid) == 1);
  CHECK(count(c, ConnectionKind::curve, Body::rod, Body::shell) == 1);  // that edge is also the face-shell's
  // a mesh with other cells: said, not guessed
  IndexedMesh h = hex_grid(1, 1, 1);
  const auto hm = mesh_connections(h, std::vector<CellModel>(h.num_cells(), CellModel::mass_spring));
  CHECK(hm.skipped == "cell 0 is not a segment, triangle or tetrahedron");
  CHECK(connections_json(hm)["skipped"] == hm.skipped);
}

// Runs the scene `j` (named `name` in messages) writing nothing; returns its summary.
RunSummary run_quietly(const nlohmann::json& j, const std::string& name) {
  Scene scene = parse_scene(j, name + ".json");
  scene.write_picture = scene.write_vtu = scene.write_csv = false;
  RunOptions o;
  o.out = sewn::test::scratch("mixed/" + name);
  o.quiet = true;
  const RunSummary sum = run(scene, o);
  std::filesystem::remove_all(o.out);
  return sum;
}

// A helix of 16 rod edges hanging from its first edge, stepped by Newton with the scene's
// `solver` (nothing else written).
RunSummary run_helix(const std::string& solver) {
  nlohmann::json pts = nlohmann::json::array();
  for (int k = 0; k <= 16; ++k) pts.push_back({0.05 * std::cos(0.5 * k), 0.05 * std::sin(0.5 * k), -0.01 * k});
  nlohmann::json j = {{"name", "helix"},
                      {"materials", {{"wire", {{"young", 1e8}, {"poisson", 0.3}, {"density", 1500}}}}},
                      {"meshes", {{{"type", "polyline"}, {"material", "wire"}, {"points", pts}}}},
                      {"model", {{"type", "mixed"}, {"groups", {{{"tag", 0}, {"as", "rod"}, {"semi_axes", {0.004, 0.002}}}}}}},
                      {"damping", {{"model", "rayleigh"}, {"alpha", 0.5}}},
                      {"fixed", {{{"where", {{"type", "points"}, {"indices", {0, 1}}}}}}},
                      {"integrator", {{"type", "newton"}, {"step", 0.01}, {"solver", solver}, {"newton_tolerance", 1e-3}}},
                      {"duration", 0.05}};
  return run_quietly(j, "helix");
}

// A beam of tetrahedra (cells x 2 x 2 to x 15 x 15, 6 Kuhn tets a cell) clamped at x = 0, one Newton step
// of h with the scene's `solver`.
RunSummary run_tet_beam(const std::string& solver, std::vector<int> cells, double h) {
  nlohmann::json j = {{"materials", {{"m", {{"young", 1e6}, {"density", 1000}}}}},
                      {"meshes", {{{"type", "tet_grid"}, {"material", "m"}, {"cells", cells}, {"size", {0.3, 0.1, 0.1}}}}},
                      {"model", {{"type", "solid"}}},
                      {"damping", {{"model", "rayleigh"}, {"alpha", 1.0}}},
                      {"fixed", {{{"where", {{"type", "box"}, {"min", {-1, -1, -1}}, {"max", {0.001, 1, 1}}}}}}},
                      {"integrator", {{"type", "newton"}, {"step", h}, {"solver", solver}}},
                      {"duration", h}};
  return run_quietly(j, "solid");
}

TEST_CASE("Newton's solver `auto` picks by size: ldlt, then cholmod-pcg, then block-Jacobi CG (ldlt with rods)") {
  // Block-Jacobi CG needs ~500 iterations a step here (hopeless on stiffer rods); `auto` must
  // take ldlt's path: no CG iteration, the same Newton iterations and state as `ldlt`.
  const RunSummary automatic = run_helix("auto"), direct = run_helix("ldlt"), jacobi = run_helix("jacobi");
  CHECK(automatic.linear_iterations == 0);
  CHECK(automatic.newton_iterations == direct.newton_iterations);
  CHECK(automatic.kinetic_end == direct.kinetic_end);
  CHECK(jacobi.linear_iterations > 100 * jacobi.steps);
  // Without rods, by the node count: 4 x 3 x 3 nodes, ldlt's run exactly
  const RunSummary small = run_tet_beam("auto", {3, 2, 2}, 0.01);
  CHECK(small.linear_iterations == 0);
  CHECK(small.kinetic_end == run_tet_beam("ldlt", {3, 2, 2}, 0.01).kinetic_end);
  CHECK(run_tet_beam("jacobi", {3, 2, 2}, 0.01).linear_iterations > 0);
  // 31 x 9 x 9 = 2511 nodes: the factor kept across Newton iterations, where CHOLMOD is built
  if (sewn::physics::solve::available(sewn::physics::solve::Backend::cholmod_pcg)) {
    const RunSummary mid = run_tet_beam("auto", {30, 8, 8}, 0.01);
    CHECK(mid.linear_iterations > 0);
    CHECK(mid.kinetic_end == run_tet_beam("cholmod-pcg", {30, 8, 8}, 0.01).kinetic_end);
  }
  // 41 x 16 x 16 = 10 496 nodes: block-Jacobi CG (a short step keeps its iterations few)
  const RunSummary large = run_tet_beam("auto", {40, 15, 15}, 1e-5);
  CHECK(large.linear_iterations > 0);
  CHECK(large.kinetic_end == run_tet_beam("jacobi", {40, 15, 15}, 1e-5).kinetic_end);
}

}  // namespace mixed_test

}  // namespace test_mixed
