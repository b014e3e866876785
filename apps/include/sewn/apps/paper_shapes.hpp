#pragma once
// The meshes of the 2019 paper's Table 1 scenes (seed 004), rebuilt from their published
// counts (PHYSICS_NOTES §5): each one conforming mesh of tetrahedra (solids), triangles (shells)
// and segments (rods) sharing their nodes, with a Gmsh physical name per part. `sewn make-mesh`
// writes them; scenes/meshes/s04_*.msh are its output, and the scenes select the parts by name.
//
// Counts (vertices / rod edges / shell triangles / tetrahedra):
//   frisbee       289 / 64 / 512 / 0     exact: a polar disc (rings of 8k points), rim as rod
//   umbrella      3168 / 198 / 6144 / 0  exact: a spherical canopy 96 around × 32 radial quads
//                                        split, 6 ribs of 32 edges and a hexagonal hub of 6
//   sticky_hands  200 / 19 / 292 / 0     exact: a hand (a disc of 181 points, 68 on its outline)
//                                        and a 19-edge string from its wrist
//   jellyfish     1465 / 1273 / 0 / 454  exact: a thin disc body (432 tets), an eyeball (22) on
//                                        a stalk, 3 oral-arm loops, 12 tentacles
//   toy_ball      proxy (the published counts cannot all hold): a 96-triangle platform (61
//                 points), a 226-tet ball, a 203-edge helical spring (4 turns) between them
//   sandwich      proxy (1510 shell faces cannot lie in 600 tets): 600 tets (a 10 × 2 × 5 cube
//                 beam, 6 tets per cube) with its 4 interior horizontal face layers as shells
//   toy_tunnel    620 / 60 / 1200 / 0    from Fig. 14 (no published counts): a cloth cylinder
//                                        whose two diagonal helices are rods
//   anglerfish    231 / 20 / 41 / 592    from Fig. 17 (no published counts): a tet body with
//                                        four fins on rows of its edges, an antenna, a light ball
#include <string>
#include <vector>

#include "sewn/cmap/mesh.hpp"
#include "sewn/io/read.hpp"

namespace sewn::app {

/// A generated mesh, its physical names (one per part), and what the counts follow.
struct PaperShape {
  IndexedMesh mesh;
  std::vector<io::TagName> names;
  std::string note;
};

/// "frisbee", "umbrella", "sticky_hands", "jellyfish", "toy_ball", "sandwich", "toy_tunnel", "anglerfish".
const std::vector<std::string>& paper_shape_names();

/// Builds the named shape (deterministic: the same points and cells every call). Throws
/// std::invalid_argument naming the shape and listing the known ones.
PaperShape make_paper_shape(const std::string& name);

/// The paper's Fig. 18 slab on cubes of side `cell` from x = 0: `solid` × ny × nz cubes of 6
/// tetrahedra (tag 1, the points of tet_grid), then `shell` columns of ny × 2 triangles (tag 2)
/// on the mid-surface z = cell · nz / 2 (nz even), the first column on the solid's end-face
/// points there (a shared edge line: the curve joints).
IndexedMesh fig18_slab(std::uint32_t solid, std::uint32_t shell, std::uint32_t ny, std::uint32_t nz, double cell);

}  // namespace sewn::app
