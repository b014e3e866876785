// The scene key `refinement`: defaults, bad values refused with the key path, and runs where
// the beam of the 2014 paper's Table 1 is pre-refined and refined adaptively.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <span>
#include <fstream>
#include <string>

#include "sewn/apps/refine_keys.hpp"
#include "sewn/apps/runner.hpp"
#include "sewn/apps/scene.hpp"
#include "sewn/physics/integrators.hpp"
#include "sewn/physics/solids/volume_term.hpp"
#include "sewn/refine/cut.hpp"
#include "sewn/refine/hierarchy.hpp"
#include "scratch.hpp"

namespace test_refine_keys {

using namespace sewn::app;
using nlohmann::json;

namespace refine_keys_test {

json beam_scene() {
  return json::parse(R"({
    "materials": {"paper": {"young": 1e5, "poisson": 0.3, "density": 100}},
    "meshes": [{"type": "hex_grid", "material": "paper", "cells": [2, 1, 1], "size": [2, 1, 1]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.001, 2, 2]}}],
    "integrator": {"step": 0.001},
    "duration": 0.3,
    "output": {"vtu": false, "csv": true, "picture": {"enabled": false}}
  })");
}

std::string refused(const json& j) {
  try {
    (void)parse_scene(j, "bad.json");
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "accepted";
}

std::string run_refused(const json& j) {
  try {
    RunOptions o;
    o.quiet = true;
    o.out = sewn::test::scratch("refine_keys/refused");
    (void)run(parse_scene(j, "bad.json"), o);
  } catch (const SceneError& e) {
    return e.path() + ": " + e.reason();
  }
  return "ran";
}

// The value of column `name` in a frames.csv row.
double csv_value(const std::string& header, const std::string& row, const std::string& name) {
  std::size_t col = 0, at = 0;
  for (std::size_t p = 0; p < header.find(name); ++p) col += header[p] == ',';
  for (std::size_t c = 0; c < col; ++c) at = row.find(',', at) + 1;
  return std::stod(row.substr(at));
}



TEST_CASE("scene refinement: defaults, criteria and pre-refined regions") {
  CHECK_FALSE(parse_scene(beam_scene(), "s.json").refinement.enabled);
  json j = beam_scene();
  j["refinement"] = json::parse(R"({
    "criteria": [{"type": "diagonal_strain", "threshold": 1.2},
                 {"type": "region", "where": {"type": "sphere", "center": [0, 0, 0], "radius": 0.5}},
                 {"type": "point", "point": [1, 2, 3], "radius": 0.1},
                 {"type": "strain_energy", "threshold": 250}],
    "pre_refine": [{"where": {"type": "all"}}]
  })");
  const Scene s = parse_scene(j, "s.json");
  const RefinementSpec& r = s.refinement;
  CHECK(r.enabled);
  REQUIRE(r.criteria.size() == 4);
  CHECK(r.criteria[0].threshold == 1.2);
  CHECK(r.criteria[1].where.type == Selector::Type::sphere);
  CHECK(r.criteria[2].radius == 0.1);
  CHECK(r.criteria[3].type == "strain_energy");
  CHECK(r.criteria[3].threshold == 250);
  CHECK(r.max_level == 3);
  CHECK(r.pre_refine.at(0).levels == 1);
  CHECK_FALSE(r.coarsen);
  CHECK(r.calm_steps == 20);
  CHECK_FALSE(r.balance);
  CHECK(r.t_junctions == "reduction");
  CHECK(r.max_elements == doctest::Approx(8e9 / 4400));
}

TEST_CASE("scene refinement: bad values name their key") {
  auto with = [](const char* refinement) {
    json j = beam_scene();
    j["refinement"] = json::parse(refinement);
    return refused(j);
  };
  CHECK(with(R"({"criteria": [{"type": "diagonal_strain", "threshold": 0}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "diagonal_strain"}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "strain_energy", "threshold": -1}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "strain_energy"}]})").find("refinement.criteria[0].threshold") == 0);
  CHECK(with(R"({"criteria": [{"type": "curvature"}]})").find("refinement.criteria[0].type") == 0);
  CHECK(with(R"({"max_level": 9})").find("refinement.max_level") == 0);
  CHECK(with(R"({"criteria": [{"type": "region", "where": {"type": "tag", "tag": 3}}]})") ==
        "refinement.criteria[0].where.type: refinement regions are geometric (all, box or sphere): refined elements carry no mesh tag or point list");
  CHECK(with(R"({"max_level": 2, "pre_refine": [{"where": {"type": "all"}, "levels": 2}]})") ==
        "refinement.pre_refine[0].levels: 2 refinements of the mesh's elements reach level 3, above refinement.max_level = 2");
  // pre-refinement counts against limits.memory: 2 hexahedra x 8^4
  json big = beam_scene();
  big["refinement"] = json::parse(R"({"max_level": 5, "pre_refine": [{"where": {"type": "all"}, "levels": 4}]})");
  big["limits"] = json::parse(R"({"memory": 1e7})");
  CHECK(refused(big).find("meshes[0].cells: the scene needs about 36 MB of memory") == 0);
}

TEST_CASE("scene refinement: what the model cannot take stops the run before it starts") {
  json j = beam_scene();
  j["refinement"] = json::parse(R"({"criteria": [{"type": "contact"}]})");
  CHECK(run_refused(j) == "refinement.criteria[0]: \"contact\" needs obstacles, and the scene has none");
  j["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "box", "min": [5, 5, 5], "max": [6, 6, 6]}}]})");
  CHECK(run_refused(j) == "refinement.pre_refine[0].where: holds the rest centroid of no hexahedron or quad");
  json tets = beam_scene();
  tets["meshes"][0]["type"] = "tet_grid";
  tets["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "all"}}]})");
  CHECK(run_refused(tets).find("refinement: refines hexahedra (1:8) and quads (1:4), and the meshes have none") == 0);
  tets["model"] = json::parse(R"({"type": "solid"})");
  tets["damping"] = json::parse(R"({"model": "none"})");
  CHECK(run_refused(tets) == "refinement: refines the mass-spring model only (model.type is \"solid\")");
  // adaptive refinement past limits.memory stops the run, naming the key to change
  json grow = beam_scene();
  grow["refinement"] = json::parse(R"({"criteria": [{"type": "region", "where": {"type": "all"}}], "max_level": 4})");
  grow["limits"] = json::parse(R"({"memory": 1e6})");  // 227 hexahedra: the second pass (16 -> 128) fits, the third not
  CHECK(run_refused(grow).find("refinement.max_level: adaptive refinement: refining the 128 elements") == 0);
}

TEST_CASE("scene refinement: the Table 1 beam refined adaptively by the run") {
  json j = beam_scene();
  j["refinement"] = json::parse(R"({"criteria": [{"type": "diagonal_strain", "threshold": 1.2}], "max_level": 3,
                                    "pre_refine": [{"where": {"type": "all"}}]})");
  RunOptions o;
  o.quiet = true;
  o.out = sewn::test::scratch("refine_keys/beam");
  const RunSummary s = run(parse_scene(j, "beam.json"), o);
  // the 2 roots pre-refined, then some of their 16 children as the beam sags: never past level 3
  CHECK(s.refined > 2);
  CHECK(s.refined <= 2 + 16);
  std::ifstream csv(s.csv);
  std::string header, row, last;
  std::getline(csv, header);
  while (std::getline(csv, row)) last = row;
  CHECK(header.find(",refined,coarsened") != std::string::npos);
  // the last frame's element count is 16 + 7 per refined child
  CHECK(csv_value(header, last, "elements") == 16 + 7 * static_cast<double>(s.refined - 2));

  // with 2:1 balance: the same run, balanced refinements counted with the criterion's
  json balanced = j;
  balanced["refinement"]["balance"] = true;
  const Scene bs = parse_scene(balanced, "beam.json");
  CHECK(bs.refinement.balance);
  const RunSummary b = run(bs, o);
  CHECK(b.refined >= s.refined);
  CHECK(b.refined <= 2 + 16);

  // by the strain energy density: the sagging beam's (about E·ε²/2 = 5 J/m³ at 1 % strain)
  // refines above 1 J/m³ and never above 1e9 J/m³
  for (const double threshold : {1.0, 1e9}) {
    json energy = j;
    energy["refinement"]["criteria"] = json::array({{{"type", "strain_energy"}, {"threshold", threshold}}});
    const RunSummary e = run(parse_scene(energy, "beam.json"), o);
    CHECK((e.refined > 2) == (threshold == 1.0));
    CHECK(e.refined >= 2);
  }

  // without refinement, the same scene keeps its two elements
  json plain = beam_scene();
  CHECK(run(parse_scene(plain, "beam.json"), o).refined == 0);
}

TEST_CASE("scene surface meshes: voxelized, refined, and skipped when optional and absent") {
  const auto dir = sewn::test::scratch("refine_keys/surface");
  std::filesystem::create_directories(dir);
  {
    // a 2 m x 1 m x 1 m box, its faces as quads (outward)
    std::ofstream off(dir / "box.off");
    off << "OFF\n8 6 0\n0 0 0\n2 0 0\n2 1 0\n0 1 0\n0 0 1\n2 0 1\n2 1 1\n0 1 1\n"
           "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 1 2 6 5\n4 0 4 7 3\n";
  }
  json j = beam_scene();
  j["meshes"] = json::parse(R"([{"type": "surface", "material": "paper", "path": "box.off", "resolution": 4}])");
  j["refinement"] = json::parse(R"({"pre_refine": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.5, 2, 2]}}]})");
  j["duration"] = 0.002;
  const Scene s = parse_scene(j, (dir / "scene.json").string());
  CHECK(s.skip.empty());
  CHECK(s.meshes[0].path == (dir / "box.off").string());
  RunOptions o;
  o.quiet = true;
  o.out = dir / "out";
  const RunSummary r = run(s, o);
  CHECK(r.refined == 4);  // the 4 x 2 x 2 cubes of side 0.5 m: the 4 with x < 0.5 refined
  std::ifstream csv(r.csv);
  std::string header, row;
  std::getline(csv, header);
  std::getline(csv, row);
  // 5 x 3 x 3 particles, of which the refined block 0.5 x 1 x 1 had 2 x 3 x 3, now 3 x 5 x 5
  CHECK(csv_value(header, row, "particles") == 45 - 18 + 75);
  CHECK(csv_value(header, row, "elements") == 16 - 4 + 32);
  // a missing file: an error naming it, or a skipped scene when the scene says so
  j["meshes"][0]["path"] = "none.off";
  const Scene missing = parse_scene(j, (dir / "scene.json").string());
  CHECK(missing.skip.empty());
  CHECK_THROWS_WITH(run(missing, o), doctest::Contains("none.off: no such file"));
  j["meshes"][0]["missing"] = "skip";
  CHECK(parse_scene(j, (dir / "scene.json").string()).skip == "meshes[0].path: " + (dir / "none.off").string() + " is not present");
  // the memory estimate counts the whole grid of resolution³ cells
  j["meshes"][0]["resolution"] = 1024;
  CHECK(refused(j).find("meshes[0].resolution: the scene needs about") == 0);
  std::filesystem::remove_all(dir);
}

namespace {

// Signed volume of a hexahedron (VTK corner order) from its corners' positions, as six
// tetrahedra around the diagonal 0-6: exact for any trilinear box with planar faces, and the
// same measure at rest and deformed.
double hex_volume(const std::array<Eigen::Vector3d, 8>& x) {
  constexpr int tets[6][2] = {{1, 2}, {2, 3}, {3, 7}, {7, 4}, {4, 5}, {5, 1}};
  double v = 0;
  for (const auto& t : tets) v += (x[static_cast<std::size_t>(t[0])] - x[0]).cross(x[static_cast<std::size_t>(t[1])] - x[0]).dot(x[6] - x[0]) / 6;
  return v;
}

// The live hexahedra's volume, at rest or now.
double live_volume(const sewn::physics::MssModel<3>& m, bool rest) {
  double v = 0;
  for (sewn::physics::Index e = 0; e < m.elements().size(); ++e) {
    if (!m.elements()[e].alive) continue;
    const auto c = m.element_nodes(e);
    std::array<Eigen::Vector3d, 8> x;
    for (std::size_t k = 0; k < 8; ++k) x[k] = rest ? m.rest_position(c[k]) : m.nodes().position(c[k]);
    v += hex_volume(x);
  }
  return v;
}

// After a topology edit: the map valid, the refinement hierarchy sound, the mass kept exactly.
void require_sound(const sewn::physics::MssModel<3>& m, double mass0) {
  const auto report = m.map().validate();
  INFO(report.str());
  REQUIRE(report.ok());
  const auto h = sewn::refine::check_hierarchy(m);
  INFO(h.str());
  REQUIRE(h.ok());
  REQUIRE(std::abs(m.node_mass() - mass0) <= 1e-12 * mass0);
}

// The relative volume change of a soft 0.2 m cube on a clamped base under gravity after 0.4 s,
// built as `sewn run` builds it (the volume term, then the refinement with its pre-refinement),
// refined again after every step by a region criterion. Checks validate() and the hierarchy
// after every refinement.
double refined_cube_volume_change(double kappa) {
  json j = json::parse(R"({
    "materials": {"soft": {"young": 1e3, "poisson": 0.3, "density": 1000}},
    "meshes": [{"type": "hex_grid", "material": "soft", "cells": [2, 2, 2], "size": [0.2, 0.2, 0.2]}],
    "fixed": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.001]}}],
    "integrator": {"type": "implicit", "step": 0.002}, "duration": 0.4,
    "refinement": {"criteria": [{"type": "region", "where": {"type": "box", "min": [-1, -1, 0.1], "max": [1, 1, 1]}}],
                   "max_level": 3, "pre_refine": [{"where": {"type": "box", "min": [-1, -1, -1], "max": [0.1, 1, 1]}}]}
  })");
  j["materials"]["soft"]["volume_stiffness"] = kappa;
  const Scene scene = parse_scene(j, "cube.json");
  sewn::physics::MssOptions mo;
  mo.gravity = Eigen::Vector3d(0, 0, -9.81);
  sewn::physics::MssModel<3> m(sewn::hex_grid(2, 2, 2, {{0.1, 0.1, 0.1}, {}}), {{1e3, 0.3, 1000}}, {}, mo);
  for (sewn::physics::Index i = 0; i < m.nodes().size(); ++i)
    if (m.rest_position(i).z() < 1e-3) m.nodes().fix(i);
  const std::vector<double> k{kappa};
  (void)sewn::physics::solids::add_volume_preservation(m, k);
  RefinementRun refinement(scene, m);
  const double v0 = live_volume(m, true), mass0 = m.node_mass();
  sewn::physics::LinearlyImplicitEuler euler;
  for (int s = 0; s < 200; ++s) {
    (void)euler.step(m.system(), scene.step);
    if (refinement.after_step(m, scene.step * (s + 1))) {
      require_sound(m, mass0);
      REQUIRE(std::abs(live_volume(m, true) - v0) <= 1e-12 * v0);
    }
  }
  CHECK(refinement.refined() > 2);
  return (live_volume(m, false) - v0) / v0;
}

}  // namespace

TEST_CASE("scene refinement with a volume term: the children keep the volume within the load over the bulk stiffness") {
  // a 1 kPa cube 0.2 m high under its own weight: the pressure at its base is ρgH = 1962 Pa
  const double rho_g_h = 1000 * 9.81 * 0.2, kappa = 1e5;
  const double kept = refined_cube_volume_change(kappa), free = refined_cube_volume_change(0);
  MESSAGE("relative volume change with kappa = 1e5 Pa: " << kept << ", without the term: " << free);
  // a suddenly applied load at most doubles its static response (no pressure above ρgH anywhere)
  CHECK(std::abs(kept) <= 2 * rho_g_h / kappa);
  CHECK(std::abs(free) > 2 * rho_g_h / kappa);
}

namespace {

// Distance from p to the polyline through `pts` (in the xz plane of the sheet).
double to_path(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& pts) {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k + 1 < pts.size(); ++k) {
    const Eigen::Vector3d u = pts[k + 1] - pts[k];
    const double t = std::clamp((p - pts[k]).dot(u) / u.squaredNorm(), 0.0, 1.0);
    best = std::min(best, (p - pts[k] - t * u).norm());
  }
  return best;
}

}  // namespace

TEST_CASE("scenes/refine_fig08_cut_path.json: membrane quads refined where the cut strains the sheet, and only there") {
  const Scene scene = load_scene(std::string(SEWN_SOURCE_DIR) + "/scenes/refine_fig08_cut_path.json");
  REQUIRE(scene.cuts.size() == 1);
  // `sewn run` itself, briefly: it cuts, refines and finishes
  RunOptions o;
  o.quiet = true;
  o.until = 0.4;
  o.out = sewn::test::scratch("refine_keys/fig08");
  const RunSummary run_summary = run(scene, o);
  CHECK(run_summary.cuts == 1);
  CHECK(run_summary.refined > 0);

  // the same model built as the runner builds it, to look inside after every change
  const Assembly a = assemble(scene);
  const MaterialSpec& ms = scene.materials.at("sheet");
  sewn::physics::MssOptions mo;
  mo.gravity = Eigen::Vector3d(scene.gravity[0], scene.gravity[1], scene.gravity[2]);
  sewn::physics::MssModel<3> m(a.mesh, {{ms.young, ms.poisson, ms.density, ms.thickness}}, {}, mo);
  for (sewn::physics::Index i = 0; i < m.nodes().size(); ++i) {
    const Eigen::Vector3d r = m.rest_position(i);
    if (r.x() < 1e-3 || r.x() > 1 - 1e-3 || r.z() < 1e-3 || r.z() > 1 - 1e-3) m.nodes().fix(i);  // the scene's 4 boxes
  }
  RefinementRun refinement(scene, m);
  std::vector<Eigen::Vector3d> path;  // the cut's rest polyline, from its edges' mesh points
  for (const auto& edge : scene.cuts[0].faces) {
    const auto& q = a.mesh.points[edge[0]];
    path.emplace_back(q[0], q[1], q[2]);
  }
  const auto& last = a.mesh.points[scene.cuts[0].faces.back()[1]];
  path.emplace_back(last[0], last[1], last[2]);
  const double mass0 = m.node_mass();
  auto check_model = [&] { require_sound(m, mass0); };
  sewn::physics::LinearlyImplicitEuler euler;
  const int cut_step = static_cast<int>(std::lround(scene.cuts[0].time / scene.step));
  for (int s = 0; s < 400; ++s) {
    if (s == cut_step) {
      CHECK(refinement.refined() == 0);  // the sag alone strains no diagonal past the threshold
      const auto facets = sewn::refine::facets_with_points(m, std::span(scene.cuts[0].faces));
      REQUIRE(facets.size() == scene.cuts[0].faces.size());
      CHECK(sewn::refine::cut(m, std::span(facets)).facets == facets.size());
      check_model();
    }
    (void)euler.step(m.system(), scene.step);
    if (refinement.after_step(m, scene.step * (s + 1))) check_model();
  }
  REQUIRE(refinement.refined() > 0);
  CHECK(refinement.refined() == run_summary.refined);  // the runner's own run did the same
  // every element refined lies by the cut: within two coarse cells (0.1 m) of the path at rest
  int finer = 0;
  for (sewn::physics::Index e = 0; e < m.elements().size(); ++e) {
    if (!m.elements()[e].alive || m.elements()[e].level == 1) continue;
    ++finer;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (sewn::physics::Index n : m.element_nodes(e)) c += m.rest_position(n) / 4;
    CHECK(to_path(c, path) < 0.1);
  }
  CHECK(finer >= 4);
}

}  // namespace refine_keys_test

}  // namespace test_refine_keys
