// bench_connect: what the connections cost (issue 16).
//
//   connect/point/<pair>/<what>/ours   one point connection's energy, gradient or Hessian
//                                       (chained AD); peer: the whole-stencil AD Hessian
//   connect/curve/<pair>/<what>/ours   one curve connection (edge) the same way
//   connect/detect/<mesh>/ours         detect_connections on a tet block with a fin of triangles
//                                       along one of its edges and a rod hanging from the fin
//
// Configurations are fixed, perturbed from rest by a seeded random draw, so every run evaluates
// the same states. Counters: DOFs of the stencil; for detection, cells and connections found.

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/connect/curve.hpp"
#include "sewn/connect/detect.hpp"
#include "sewn/connect/point.hpp"
#include "sewn/physics/rods/stencils.hpp"
#include "sewn_bench.hpp"

namespace sewn::bench::connect_suite {

namespace {

namespace cn = sewn::connect;
constexpr const char* suite = "connect";
using Eigen::VectorXd;

VectorXd perturbed(VectorXd q, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (double& v : q) v += u(rng);
  return q;
}

// Point pairs: a shell triangle (0, 1, 2) and a rod edge 0 → 3; two tets touching at node 0.
struct PointCase {
  std::string name;
  cn::Side m, n;
  VectorXd q;
};
std::vector<PointCase> point_cases() {
  std::vector<PointCase> c;
  VectorXd q(16);
  q << 0, 0, 0, -1, 0.5, 0, -1, -0.5, 0, 0, 0, 0, 1, 0, 0, 0.3;
  c.push_back({"rod-triangle", cn::TriangleSide{{0, 1, 2}, std::nullopt}, cn::RodEdgeSide{0, 3, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 0, 1)}, q});
  VectorXd t(24);
  t << 0, 0, 0, 0.5, 0.1, -0.6, -0.4, 0.4, -0.5, -0.1, -0.5, -0.7, 0, 0, 0, 0.4, 0.1, 0.7, -0.5, 0.3, 0.6, 0.0, -0.5, 0.8;
  c.push_back({"tet-tet", cn::TetSide{{0, 1, 2, 3}, Eigen::Vector3d(0, 0, 1)}, cn::TetSide{{0, 7, 8, 9}, Eigen::Vector3d(0, 0, -1)}, t});
  return c;
}

// Curve pairs along the edge (0, 1): a rod and a face; two hinges (the widest stencil, 18).
struct CurveCase {
  std::string name;
  cn::EdgeSide m, n;
  VectorXd q;
};
std::vector<CurveCase> curve_cases() {
  std::vector<CurveCase> c;
  VectorXd q(10);
  q << 0, 0, 0, 0.4, 0, 0, 0.3, 0.15, 0, -0.3;
  c.push_back({"rod-face", cn::RodEdgeSide{0, 1, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, 1, 0)}, cn::FaceSide{2}, q});
  VectorXd h(18);
  h << 0, 0, 0, 0.4, 0, 0, 0.1, 0.3, 0.1, 0.25, -0.3, 0.1, 0.1, 0.1, 0.3, 0.3, 0.1, -0.3;
  c.push_back({"hinge-hinge", cn::HingeSide{2, 3}, cn::HingeSide{4, 5}, h});
  return c;
}

// A block of n×n×n cubes (6 tets each), a fin of triangles hanging from its bottom front edge
// (n wide, n/2 deep), a rod of n segments from the fin's bottom middle.
cn::CellList fin_block(std::uint32_t n) {
  GridSpec g;
  g.spacing = {1.0 / n, 1.0 / n, 1.0 / n};
  const IndexedMesh block = tet_grid(n, n, n, TetSplit::kuhn6, g);
  cn::CellList cells;
  for (std::uint32_t c = 0; c < block.num_cells(); ++c) cells.add(cn::Body::solid, block.cell(c));
  // grid point (i, 0, 0) = i along the bottom front edge; the fin's rows below it
  std::uint32_t next = block.num_points();
  std::vector<std::uint32_t> row(n + 1);
  for (std::uint32_t i = 0; i <= n; ++i) row[i] = i;
  for (std::uint32_t k = 0; k < n / 2 + 1; ++k) {
    std::vector<std::uint32_t> below(n + 1);
    for (auto& b : below) b = next++;
    for (std::uint32_t i = 0; i < n; ++i) {
      cells.add(cn::Body::shell, {row[i], row[i + 1], below[i + 1]});
      cells.add(cn::Body::shell, {row[i], below[i + 1], below[i]});
    }
    row = below;
  }
  std::uint32_t top = row[n / 2];
  for (std::uint32_t s = 0; s < n; ++s, top = next++) cells.add(cn::Body::rod, {top, next});
  return cells;
}

void register_all() {
  const Scale sc = scale();
  for (const PointCase& pc : point_cases()) {
    const cn::PointConnection c(pc.name, pc.m, pc.n, {2.0, 3.0}, pc.q);
    const VectorXd q = perturbed(pc.q, 5);
    const std::string base = "point/" + pc.name + "/";
    ours(suite, base + "energy", [c, q](benchmark::State& st) {
      for (auto _ : st) benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, false).energy);
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
    ours(suite, base + "gradient", [c, q](benchmark::State& st) {
      for (auto _ : st) benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, true).gradient.data());
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
    ours(suite, base + "hessian", [c, q](benchmark::State& st) {
      Eigen::MatrixXd H;
      for (auto _ : st) benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, true, &H).energy);
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
    peer(suite, base + "hessian", "whole-stencil AD", [c, q](benchmark::State& st) {
      Eigen::MatrixXd H;
      for (auto _ : st)
        benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, true, &H, cn::HessianMethod::nested_ad).energy);
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
  }
  for (const CurveCase& cc : curve_cases()) {
    const cn::EdgeConnection c(cc.name, 0, 1, cc.m, cc.n, 2.5, cc.q);
    const VectorXd q = perturbed(cc.q, 6);
    const std::string base = "curve/" + cc.name + "/";
    ours(suite, base + "gradient", [c, q](benchmark::State& st) {
      for (auto _ : st) benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, true).gradient.data());
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
    ours(suite, base + "hessian", [c, q](benchmark::State& st) {
      Eigen::MatrixXd H;
      for (auto _ : st) benchmark::DoNotOptimize(c.evaluate(q, cn::TwistUpdate::incremental_ii, true, &H).energy);
      st.counters["dofs"] = c.num_dofs();
    })->Unit(benchmark::kMicrosecond);
  }
  const std::uint32_t n = sc == Scale::smoke ? 2 : sc == Scale::small ? 8 : 24;
  const cn::CellList cells = fin_block(n);
  ours(suite, "detect/fin-block-" + std::to_string(n), [cells](benchmark::State& st) {
    std::uint32_t found = 0;
    for (auto _ : st) found = cn::detect_connections(cells).total();
    st.counters["cells"] = cells.size();
    st.counters["connections"] = found;
  });
}

const Registration reg(&register_all);

}  // namespace

}  // namespace sewn::bench::connect_suite
