#include "sewn/apps/scene.hpp"

#include "sewn/physics/errors.hpp"
#include "sewn/physics/threads.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "json_file.hpp"
#include "sewn/apps/refine_keys.hpp"
#include "sewn/io/render.hpp"

namespace sewn::app {

namespace {

// Point indices are 32-bit; the largest value is kept as the "no point" marker.
constexpr double max_point_index = 4294967294.0;
constexpr std::size_t max_name_length = 100;
constexpr double default_memory_limit = 8e9;  // bytes
constexpr double default_step_limit = 1e8;

}  // namespace

Field selector_schema(std::string key, std::string doc) {
  Field s = field(std::move(key), Kind::object);
  s.doc(std::move(doc)).select_by("type");
  s.members({field("type", Kind::string).required().doc("Kind of region.")});
  s.variant("all", "Everything.", {});
  s.variant("box", "An axis-aligned box (bounds included).",
            {field("min", Kind::vec3).unit("m").required().doc("Lower corner."),
             field("max", Kind::vec3).unit("m").required().doc("Upper corner.")});
  s.variant("sphere", "A ball.",
            {field("center", Kind::vec3).unit("m").required().doc("Centre."),
             field("radius", Kind::number).unit("m").required().above(0).doc("Radius.")});
  s.variant("tag", "Cells carrying a mesh tag (Gmsh physical group, MEDIT reference); for points: points of such cells.",
            {field("tag", Kind::integer).required().at_least(-2147483648.0).at_most(2147483647.0).doc("The tag (a 32-bit signed integer).")});
  s.variant("points", "Mesh points by index (cells: all of whose points are listed).",
            {field("indices", Kind::number_list).required().whole().at_least(0).at_most(max_point_index).items(1, 1u << 30).doc(std::string("Point indices, numbered ") + point_numbering + ".")});
  return s;
}

namespace {

Field build_schema() {
  Field material = field("material", Kind::object);
  material.doc("A linear elastic material. The mass-spring stiffnesses follow Baudet et al. (hexahedra, quads) and van Gelder (tetrahedra, triangles), see PHYSICS_NOTES §1.");
  material.members({
      field("young", Kind::number).unit("Pa").required().above(0).at_most(1e13)
          .doc("Young's modulus E (the bound is ten times diamond's: beyond it the stiffnesses overflow the solver)."),
      field("poisson", Kind::number).fallback(0.3).above(-1).below(0.5).doc("Poisson's ratio ν."),
      field("density", Kind::number).unit("kg/m³").required().above(0).at_most(1e5)
          .doc("Mass density ρ (per unit area for 2D cells of unit thickness; the bound is four times osmium's)."),
      field("thickness", Kind::number).unit("m").fallback(1.0).above(0).doc("Thickness of 2D cells (membranes): scales their mass and stiffness."),
      field("area", Kind::number).unit("m²").fallback(1e-4).above(0).doc("Cross-section of 1D cells (polylines): axial spring k = E·area/length."),
      field("volume_stiffness", Kind::number).unit("Pa").fallback(0.0).at_least(0).at_most(1e13)
          .doc("Bulk stiffness κ of a volume-preserving term (Teschner et al. 2004): each tetrahedron, and each corner of a hexahedron with an eighth of its volume, stores ½ κ V̄ (V/V̄ - 1)². Springs see lengths, not orientation: a region much softer than its load (a 1 kPa region under a 1 GPa block) turns inside out, and κ well above the pressure it carries (e.g. 100× E for a soft, nearly incompressible solid) keeps it from inverting. 0: no term. Follows cuts (each element keeps its own particles after one) and `refinement` (each child gets its own stencils, a refined parent's are retired)."),
      field("elongated", Kind::string).one_of({"refuse", "clamp", "split"}).fallback("refuse")
          .doc("Baudet's edge stiffness turns negative for boxes longer than ~1.5× their width. `refuse`: such an element is refused, naming it. `split`: each such hexahedron is cut into near-cubes (pieces of aspect at most √2) before the model is built, and so are the hexahedra sharing its split edges, so that the mesh stays conforming; on the 1 m cantilever at E = 100 MPa (4 cells through its thickness) the static tip is the cube-meshed beam's at 10:1 and 5:1 boxes (the pieces are its cubes) and 3.1 % softer at 2.5:1 (pieces of 0.83:1), at the cost of the cube mesh's particles. Cells of other types on a split edge are refused. Messages name the file's cells, a piece of a split cell as such (\"piece 2 of cell 7 ...\"); the split's new points come after the mesh's, whose numbers stay. `clamp`: the negative edge stiffnesses are set to 0 and the diagonals carry the load along the long axis, which makes the body far too stiff in bending (on that cantilever: 4.8× at 2.5:1, 66× at 5:1, 860× at 10:1). Both `split` and `clamp` print a warning with the number of cells they changed."),
  });

  Field mesh = field("mesh", Kind::object);
  mesh.doc("One body. Procedural meshes are generated; `file` meshes are read from Gmsh .msh (2.2, 4.1, ASCII or binary), MEDIT .mesh or legacy VTK .vtk files.")
      .select_by("type");
  Field region = field("region", Kind::object);
  region.doc("A material assignment for the cells whose centroid lies in `where` (later entries win); one that selects no simulated cell of its mesh is refused. A Gmsh cell carries the tag of the first physical group that holds it.")
      .members({selector_schema("where", "Cells to assign.").required(),
                field("material", Kind::string).required().doc("Name of a material in `materials`.")});
  mesh.members({
      field("type", Kind::string).required().doc("Kind of mesh."),
      field("name", Kind::string).fallback("").doc("A name for messages and output."),
      field("material", Kind::string).required().doc("Name of the material of every cell (see `regions` for exceptions)."),
      field("regions", Kind::array).of(region).fallback(nlohmann::json::array()).doc("Per-region materials."),
  });
  auto cells3 = field("cells", Kind::number_list).items(3, 3).whole().at_least(1).at_most(4096).required().doc("Cells along x, y, z (whole numbers).");
  auto size3 = field("size", Kind::vec3).unit("m").above(0).required().doc("Extent along x, y, z.");
  auto origin = field("origin", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("Position of the minimum corner (or centre, for discs and cylinders).");
  auto cells2 = field("cells", Kind::number_list).items(2, 2).whole().at_least(1).at_most(65536).required().doc("Cells along the two in-plane axes.");
  auto size2 = field("size", Kind::number_list).items(2, 2).unit("m").above(0).required().doc("Extent along the two in-plane axes.");
  auto plane = field("plane", Kind::string).one_of({"xy", "xz", "yz"}).fallback("xy").doc("The plane the membrane lies in.");
  mesh.variant("hex_grid", "A box of hexahedra.", {cells3, size3, origin});
  mesh.variant("tet_grid", "A box of hexahedral cells, each cut into tetrahedra.",
               {cells3, size3, origin,
                field("split", Kind::string).one_of({"kuhn6", "five"}).fallback("kuhn6")
                    .doc("6 tetrahedra per cell around one diagonal, or 5 with alternating parity.")});
  mesh.variant("quad_grid", "A rectangle of quadrilaterals (a membrane).", {cells2, size2, origin, plane});
  mesh.variant("tri_grid", "A rectangle of quadrilaterals cut into triangles (a membrane).", {cells2, size2, origin, plane});
  mesh.variant("disc", "A triangulated disc: a centre point and rings of sectors·k points (ring k).",
               {field("radius", Kind::number).unit("m").required().above(0).doc("Radius."),
                field("rings", Kind::integer).required().at_least(1).at_most(10000).doc("Number of rings."),
                field("sectors", Kind::integer).fallback(6).at_least(3).at_most(10000).doc("Points on the first ring."),
                origin, plane});
  mesh.variant("cylinder", "A tetrahedralised cylinder along z: disc layers joined by prisms, each cut into 3 tetrahedra.",
               {field("radius", Kind::number).unit("m").required().above(0).doc("Radius."),
                field("height", Kind::number).unit("m").required().above(0).doc("Height."),
                field("rings", Kind::integer).required().at_least(1).at_most(1000).doc("Rings of the cross-section."),
                field("sectors", Kind::integer).fallback(6).at_least(3).at_most(1000).doc("Points on the first ring."),
                field("layers", Kind::integer).required().at_least(1).at_most(10000).doc("Layers along z."),
                origin});
  Field box = field("box", Kind::object);
  box.doc("Lattice cells [min, max) along x, y, z (whole numbers, max exclusive).")
      .members({field("min", Kind::number_list).items(3, 3).whole().at_least(-1e6).at_most(1e6).required().doc("First cell."),
                field("max", Kind::number_list).items(3, 3).whole().at_least(-1e6).at_most(1e6).required().doc("One past the last cell.")});
  mesh.variant("boxes",
               "A union of boxes of hexahedra on one lattice (a voxel shape): boxes that touch share points, so they form one body.",
               {field("spacing", Kind::vec3).unit("m").above(0).required().doc("Size of a lattice cell."), origin,
                field("boxes", Kind::array).of(box).items(1, 1u << 20).required().doc("The boxes.")});
  mesh.variant("polyline", "A chain of segments (a rope of axial springs).",
               {field("points", Kind::array).of(field("point", Kind::vec3).unit("m")).items(2, 1u << 24).required()
                    .doc("The points, in order.")});
  mesh.variant("surface",
               "A closed surface mesh (OFF, OBJ or STL) voxelized into hexahedra: the cubes of a grid with `resolution` cells along the longest side of the surface's bounding box whose centres lie inside it (then scaled and moved).",
               {field("path", Kind::string).required().doc("Path of the surface file, relative to the scene file."),
                field("resolution", Kind::integer).required().at_least(1).at_most(1024).doc("Cells along the longest side of the bounding box."),
                field("scale", Kind::number).fallback(1.0).above(0).doc("Factor applied to coordinates."),
                field("translate", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("Offset added after scaling."),
                field("missing", Kind::string).one_of({"error", "skip"}).fallback("error")
                    .doc("A missing file is an error, or (`skip`) makes `sewn run` skip the whole scene with a message and exit 0: for scenes whose data is optional (the 2014 paper's rabbit, from Debian's libcgal-demo).")});
  mesh.variant("file", "A mesh file.",
               {field("path", Kind::string).required().doc("Path of the file, relative to the scene file."),
                field("scale", Kind::number).fallback(1.0).above(0).doc("Factor applied to coordinates."),
                field("translate", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("Offset added after scaling.")});

  Field fix = field("fix", Kind::object);
  fix.doc("Particles held in place along some axes.")
      .members({selector_schema("where", "Particles to fix.").required(),
                field("axes", Kind::string).one_of({"xyz", "x", "y", "z", "xy", "xz", "yz"}).fallback("xyz").doc("Axes held.")});

  Field velocity = field("velocity", Kind::object);
  velocity.doc("An initial velocity v = linear + angular × (x − center) for the particles in `where` (x: rest position): a uniform motion plus a rigid rotation about the axis through `center` along `angular`. Fixed axes keep their zero velocity; where entries overlap, later ones win.")
      .members({selector_schema("where", "Particles to set in motion.").required(),
                field("linear", Kind::vec3).unit("m/s").fallback({0.0, 0.0, 0.0}).doc("Uniform velocity."),
                field("angular", Kind::vec3).unit("rad/s").fallback({0.0, 0.0, 0.0}).doc("Angular velocity ω (axis direction times rate)."),
                field("center", Kind::vec3).unit("m").fallback({0.0, 0.0, 0.0}).doc("A point of the rotation axis.")});

  Field cut = field("cut", Kind::object);
  cut.doc("A topological cut applied between two steps (3-unsew of faces between volumes; 2-unsew of edges between 2D cells).")
      .select_by("type");
  cut.members({field("type", Kind::string).required().doc("Kind of cut."),
               field("time", Kind::number).unit("s").required().at_least(0).doc("When to cut (the first step starting at or after it).")});
  cut.variant("plane", "Every inner face (edge, in 2D) whose two cells have their centroids strictly on opposite sides of a plane: the mesh faces nearest the plane, which then separate the body along it.",
              {field("point", Kind::vec3).unit("m").required().doc("A point of the plane."),
               field("normal", Kind::vec3).required().doc("Its normal (any length but zero)."),
               selector_schema("within", "Only faces whose centroid lies in this region.")});
  cut.variant("faces", "Explicit faces, each given by its mesh point indices.",
              {field("faces", Kind::array).of(field("face", Kind::number_list).items(2, 4).whole().at_least(0).at_most(max_point_index)).items(1, 1u << 24).required()
                   .doc(std::string("Each face as 3 or 4 point indices (2 for an edge of a 2D mesh), numbered ") + point_numbering + ".")});
  cut.variant("particles", "Every inner face (edge) all of whose points are among the listed particles: a cut along a path.",
              {field("particles", Kind::number_list).whole().at_least(0).at_most(max_point_index).items(2, 1u << 30).required().doc(std::string("Mesh point indices, numbered ") + point_numbering + ".")});
  cut.variant("pierce", "Unsew every face of the volumes whose centroid lies in a region.",
              {selector_schema("where", "Volumes to free.").required(),
               field("remove", Kind::boolean).fallback(true).doc("Remove the freed volumes (true) or keep them as loose pieces.")});

  Field picture = field("picture", Kind::object);
  picture.doc("A PNG of the last frame.")
      .members({field("enabled", Kind::boolean).fallback(true).doc("Write it."),
                field("color_by", Kind::string).one_of({"displacement", "speed", "force", "fixed", "material", "level"})
                    .fallback("displacement").doc("Per-point quantity shown by colour (`level`: the finest refinement level index of the elements around the point)."),
                field("style", Kind::string).one_of({"shaded", "wireframe"}).fallback("shaded").doc("Drawing style."),
                field("width", Kind::integer).fallback(1280).at_least(io::min_render_width).at_most(8192).unit("px").doc("Width."),
                field("height", Kind::integer).fallback(800).at_least(io::min_render_height).at_most(8192).unit("px").doc("Height.")});
  Field output = field("output", Kind::object);
  output.doc("What is written to the output folder (`--out`, default `out/<name>/`).\n\n"
             "`frames.csv` has one row per frame. Its energies (J) add up: `total_energy` = `kinetic_energy` + "
             "`elastic_energy` + `gravity_energy` (the springs' and gravity's potentials); `external_work` is the work "
             "gravity has done since the start (its potential then minus now) and `dissipated` the energy lost since "
             "the start (total then minus now: damping plus the integrator's numerical dissipation; negative when the "
             "scheme created energy), so that kinetic + elastic = their start value + `external_work` − `dissipated`. "
             "`energy_ratio_max` is the largest (kinetic + elastic) / (their start value + `external_work`) seen so far, "
             "at every step of the implicit schemes and at every frame of the semi-implicit one: at most 1 when the "
             "integrator created no energy, 1.43 if it once held 43 % more than it was given (0 until anything was given). "
             "`energy_rises` counts the implicit steps so far that created energy (see `integrator.energy_rise_tolerance`), "
             "`inverted` the hexahedra and tetrahedra inverted in the frame (see `integrator.stop_on_inversion`). "
             "`momentum_x` … `_z` (kg·m/s) and `angular_momentum_x` … `_z` (kg·m²/s, about the centre of mass) of all "
             "particles: constant on a free body (no fixed particle, no gravity) with an integrator that keeps them. "
             "Then: `particles`, `springs`, `elements` alive; `steps` in the frame, `ms_per_step` (stepping only), "
             "`cg_iterations_mean` and `_max` per step (implicit), `cuts` applied and `faces_cut` so far, elements `refined` (pre-refinement included) and families `coarsened` so far (`refinement`).")
      .fallback(nlohmann::json::object())
      .members({field("frames", Kind::integer).fallback(50).at_least(1).at_most(100000).doc("Output frames over the run (a ParaView .vtu each, plus frame 0)."),
                field("vtu", Kind::boolean).fallback(true).doc("Write the ParaView series (.vtu per frame + .pvd)."),
                field("csv", Kind::boolean).fallback(true).doc("Write frames.csv (energies, counts, timings per frame)."),
                picture});

  Field damping = field("damping", Kind::object);
  damping.doc("How motion is damped; the same model is used in the forces and in their Jacobians.")
      .fallback(nlohmann::json::object())
      .members({field("model", Kind::string).one_of({"viscous", "rayleigh", "none"}).fallback("viscous")
                    .doc("`viscous`: the 2013 paper's per-spring γ = 2√(k(mᵢ+mⱼ)/2); `rayleigh`: C = αM + βK."),
                field("alpha", Kind::number).unit("1/s").fallback(0.0).at_least(0).doc("Rayleigh mass coefficient α."),
                field("beta", Kind::number).unit("s").fallback(0.0).at_least(0).doc("Rayleigh stiffness coefficient β."),
                field("environment", Kind::number).unit("1/s").fallback(0.0).at_least(0).at_most(1e6).doc("Drag −c·m·v on every particle.")});

  Field group = field("group", Kind::object);
  group.doc("How the cells of one mesh tag (Gmsh physical group, MEDIT reference) are simulated; overrides `model.type` and the boundary-label rule for them.")
      .members({field("tag", Kind::integer).at_least(-2147483647).at_most(2147483647).doc("The mesh tag (every mesh of the scene). Give `tag` or `name`."),
                field("name", Kind::string).doc("A Gmsh physical name ($PhysicalNames of a `.msh` file), instead of `tag`: each mesh file resolves it to its own tag. MEDIT references and generated meshes have numbers only: select them with `tag`."),
                field("as", Kind::string).one_of({"solid", "shell", "rod", "label"}).required()
                    .doc("`solid`: tetrahedra; `shell`: triangles (membrane + hinges); `rod`: segments, chained into discrete elastic rods wherever exactly two meet; `label`: not simulated, only a name for `tag` selectors (fixed, velocities)."),
                field("radius", Kind::number).unit("m").above(0).doc("`rod`: a solid circular section of this radius (default: the circle of the material's `area`)."),
                field("semi_axes", Kind::number_list).unit("m").items(2, 2).above(0)
                    .doc("`rod`: a solid elliptic section, semi-axis a along the first material director and b along the second (instead of `radius`).")});

  Field model = field("model", Kind::object);
  model.doc("What the bodies' elasticity is made of (docs/elastic.md, docs/mixed.md). In every model, a triangle that is a face of a tetrahedron (a segment that is an edge of a triangle or tetrahedron) is a boundary label, not simulated, unless `groups` says otherwise: mesh generators list such faces (tetgen's face list, Gmsh's boundary groups) to name boundaries.")
      .fallback(nlohmann::json::object())
      .members({field("type", Kind::string).one_of({"mass-spring", "solid", "shell", "mixed"}).fallback("mass-spring")
                    .doc("`mass-spring`: the 2013 paper's springs on the map's edges; `solid`: finite-element tetrahedra (tetrahedral meshes only); `shell`: CST membranes with Green strain plus bending (`bending`), thickness from the material (triangle meshes only); `mixed`: each cell by its dimension (tetrahedra solid, triangles shell, segments rod), components touching at points or curves sharing their nodes. `solid` cells, and `shell` cells with `\"bending\": \"hinge\"`, follow plane, faces and particles cuts and `pierce` (a hinge on a cut edge, and every element pierced away, is removed); scenes with rod cells take no cuts yet. The damping of `solid`, `shell` and `mixed` comes from `rayleigh` α or `environment`, as spring damping does not apply."),
                field("law", Kind::string).one_of({"stvk", "stable_neo_hookean"}).fallback("stable_neo_hookean")
                    .doc("`solid` cells: St. Venant–Kirchhoff, or the inversion-safe stable neo-Hookean (Smith et al. 2018)."),
                field("bending", Kind::string).one_of({"morley", "patch", "hinge"}).fallback("patch")
                    .doc("Shell cells' bending: `patch` (the default), the plate energy of the quadratic fitted to each triangle and its neighbours (second order on structured meshes of either diagonal orientation, 4-20 % too soft on irregular ones; no cuts yet), `morley`, Morley's element (the deflection at the corners plus one mid-normal angle per edge, an angle DOF solved with the positions, so integrator `newton` only; second order on structured and irregular meshes alike; no cuts yet), or `hinge`, hinges on the interior edges with k_B = D/6 (up to 2x too soft on meshes whose diagonals run one way; follows cuts). With `patch` and `morley`, a triangle whose three nodes `fixed` holds on every axis is a clamp: a shell held by two rows of nodes is clamped exactly on the inner row. docs/elastic.md has the measured tables."),
                field("groups", Kind::array).of(group).items(0, 4096).fallback(nlohmann::json::array())
                    .doc("Per mesh tag, what its cells are (later entries win). With `mass-spring`, only `label` is accepted."),
                connections_schema()});

  Field integrator = field("integrator", Kind::object);
  integrator.doc("Time integration.")
      .fallback(nlohmann::json::object())
      .members({field("type", Kind::string).one_of({"implicit", "semi-implicit", "midpoint", "newton"}).fallback("implicit")
                    .doc("Linearly implicit Euler (Baraff–Witkin, CG: one solve per step, dissipative, loses angular momentum on fast rotations), semi-implicit (symplectic) Euler (explicit: below the stable step only), or the implicit midpoint rule with discrete-gradient springs solved by Newton and CG (keeps linear and angular momentum and the energy of free bodies to round-off at any step; a step where Newton misses, as at a radian of rotation per step, is taken as 2, 4, ... sub-steps and the summary says so; several solves per step), or backward Euler by Newton on the incremental potential (PSD-projected Hessians, CG solves, Armijo line search; docs/elastic.md). See docs/integrators.md."),
                field("step", Kind::number).unit("s").fallback(1e-3).above(0).at_most(10).doc("Time step h."),
                field("solver", Kind::string).one_of({"auto", "jacobi", "cholmod", "cholmod-pcg", "hypre-pcg", "petsc", "sa-pcg", "ldlt"}).fallback("auto")
                    .doc("Linear solver (implicit), docs/solvers.md: `jacobi` block-Jacobi CG, `cholmod` sparse Cholesky, `cholmod-pcg` CG preconditioned by a reused Cholesky factorization, `hypre-pcg` CG preconditioned by a reused BoomerAMG hierarchy, `petsc` PETSc's CG with GAMG on the program's MPI ranks, `sa-pcg` CG preconditioned by our aggregation multigrid (rigid-body modes); `auto` starts with `jacobi` and moves to `cholmod-pcg` (when built) once a solve takes more than 120 iterations on a model of at most 8000 nodes (stiff against its mass), afresh after a cut. The CHOLMOD ones need SuiteSparse at build time, `hypre-pcg` hypre, `petsc` PETSc. `newton` solves each Newton system by block-Jacobi CG to `tolerance` (`jacobi`), by a sparse direct factorization with `ldlt` or `cholmod` (CHOLMOD when built, else Eigen's LDLᵀ; exact solves, symbolic analysis once per pattern), or with `cholmod-pcg` by CG to `tolerance` preconditioned by a CHOLMOD factorization kept across Newton iterations and steps; it takes neither `hypre-pcg`, `petsc` nor `sa-pcg`. With `newton`, `auto` picks by the model's size: `ldlt` up to 2000 nodes, `cholmod-pcg` (when built) up to 8000, then block-Jacobi CG, or `ldlt` for a model with rods (elastic models leave CG hundreds of iterations a Newton system, rods thousands; docs/solvers.md, \"Newton's default\"). `ldlt` is for `newton` only."),
                field("tolerance", Kind::number).fallback(physics::solve::default_tolerance).above(0).below(1).doc("Relative residual of the iterative solvers (implicit)."),
                field("absolute_tolerance", Kind::number).unit("m/s").fallback(physics::solve::default_absolute_tolerance).at_least(0).at_most(1)
                    .doc("Floor of the residual as a velocity error on every free axis (implicit): a body at rest stops there instead of chasing round-off. 0: none."),
                field("absolute_acceleration", Kind::number).unit("m/s²").fallback(physics::solve::default_absolute_acceleration).at_least(0).at_most(1000)
                    .doc("Floor of the residual as a force error per mass on every free axis (implicit): a step of h stops at the smaller of `absolute_tolerance` and this times h, so the floor tightens with the step instead of stopping small steps early (docs/solvers.md). 0: no floor at all."),
                field("max_iterations", Kind::integer).fallback(physics::solve::default_max_iterations).at_least(1).at_most(1000000).doc("Iteration limit of the iterative solvers (implicit); reaching it is an error."),
                field("newton_tolerance", Kind::number).unit("m/s").fallback(1e-6).above(0).doc("Newton stops when the largest update divided by h is below it; a rod twist angle's update counts as the distance it turns the section, the section's radius of gyration times the angle (newton). The test reads the step, not the residual: far from the solution Newton can crawl in steps below it, so with steps long against the motion keep it tight (a rod pinned at one end and released horizontal fell 79 / 19 / 9 % of the way in 20 s at h = 2 / 5 / 10 s and 1e-3 m/s, with exit 0 (now with a warning: each stop came right after a line search had cut Newton's step below ¼); at the default 1e-6 the same steps end in Newton's iteration-limit error, and with `newton_iterations` 1000 it falls all the way; bench/results/hard.md)."),
                field("newton_forcing", Kind::number).fallback(0.0).at_least(0).below(1)
                    .doc("With `newton` and `cholmod-pcg`: inexact Newton. Each Newton system is solved to a relative residual between `tolerance` and this (Eisenstat-Walker forcing terms: this loose at a step's first iteration, tightening as the gradient falls), and a step that passes `newton_tolerance` from a looser solve is solved on to `tolerance` first, so the stopping test means the same. 0: every system to `tolerance`."),
                field("newton_iterations", Kind::integer).fallback(50).at_least(1).at_most(10000).doc("Newton iteration limit per step (newton); reaching it is an error."),
                field("allow_unstable", Kind::boolean).fallback(false)
                    .doc("Run a semi-implicit step larger than the estimated stable bound (otherwise refused with the bound)."),
                field("energy_rise_tolerance", Kind::number).fallback(1e-4).above(0).below(1)
                    .doc("An implicit step whose total energy (kinetic + elastic + gravity) rises by more than this fraction of the energy in motion is reported: a warning at the first, a count in frames.csv (`energy_rises`)."),
                field("stop_on_inversion", Kind::boolean).fallback(false)
                    .doc("Check for inverted hexahedra and tetrahedra (a corner's signed volume opposite to its rest sign) after every step and stop the run (exit 1) at the first, naming it; otherwise they are counted at every frame (`inverted` in frames.csv) and the first seen is a warning.")});

  Field limits = field("limits", Kind::object);
  limits.doc("Bounds on what a scene may ask for, checked when it is read, before anything is built: a scene over them is refused with the estimate, and runs only if it raises the limit here.")
      .fallback(nlohmann::json::object())
      .members({field("memory", Kind::number).unit("bytes").fallback(default_memory_limit).above(0)
                    .doc("Largest memory the generated meshes may need, estimated from their cell counts (about 4.4 kB per hexahedron, 2.5 kB per quad, 1.3 kB per triangle, 1.2 kB per tetrahedron, 1 kB per segment, measured on this code; mesh files are not counted)."),
                field("steps", Kind::number).fallback(default_step_limit).above(0)
                    .doc("Most time steps the run may take (duration / integrator.step).")});

  Field root = field("scene", Kind::object);
  root.doc("A scene file is one JSON object. Lengths in metres, times in seconds, SI units throughout.");
  root.members({
      field("name", Kind::string).fallback("").doc("Name of the scene (default: the file name without extension); the output goes to `out/<name>/` and its files are named after it, so it must be a plain file name: no `/` or `\\`, not `.` or `..`, no control characters, at most " + std::to_string(max_name_length) + " bytes."),
      field("description", Kind::string).fallback("").doc("Free text."),
      field("materials", Kind::map).of(material).items(1, 1u << 20).required().doc("Named materials."),
      field("meshes", Kind::array).of(mesh).items(1, 1u << 16).required().doc("The bodies."),
      field("fixed", Kind::array).of(fix).fallback(nlohmann::json::array()).doc("Fixed particles."),
      field("velocities", Kind::array).of(velocity).fallback(nlohmann::json::array()).doc("Initial velocities (default: at rest)."),
      motion_schema(),
      field("gravity", Kind::vec3).unit("m/s²").fallback({0.0, 0.0, -9.81}).at_least(-1e6).at_most(1e6)
          .doc("Gravity (each component within ±10⁶ m/s², 10⁵ g: beyond, the forces overflow the solver)."),
      model,
      damping,
      integrator,
      field("duration", Kind::number).unit("s").fallback(1.0).above(0).at_most(1e6).doc("Simulated time."),
      field("cuts", Kind::array).of(cut).fallback(nlohmann::json::array()).doc("Scheduled cuts."),
      field("threads", Kind::integer).fallback(0).at_least(0).at_most(physics::max_threads)
          .doc("Threads of the force, Jacobian and solver kernels (docs/solvers.md): results are deterministic for a given count and differ between counts in round-off only. 0: the environment variable SEWN_THREADS, else 1."),
      obstacles_schema(),
      refinement_schema(),
      output,
      limits,
  });
  return root;
}

std::array<bool, 3> read_axes(const std::string& a) {
  return {a.find('x') != std::string::npos, a.find('y') != std::string::npos, a.find('z') != std::string::npos};
}


// Why `name` cannot be the name of files in the output folder, or "" if it can: outputs are
// `<out>/<name>.pvd` and `<out>/<name>.png`, which must stay inside `<out>`.
std::string name_problem(const std::string& n) {
  if (n.size() > max_name_length)
    return "is " + std::to_string(n.size()) + " bytes long; at most " + std::to_string(max_name_length) + " are allowed";
  if (n == "." || n == "..") return "must be a plain file name, not \"" + n + "\"";
  if (n.find_first_of("/\\") != std::string::npos) return "must be a plain file name, without '/' or '\\' (got \"" + n + "\")";
  for (const char c : n)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "0x%02x", static_cast<unsigned>(static_cast<unsigned char>(c)));
      return std::string("contains the control character ") + buf;
    }
  return {};
}

// Bytes of memory a run needs per cell, the points, springs, map darts and solver vectors it
// brings included: peak resident size over cell count on grids of 10^4 to 10^5 cells (one step,
// no output), rounded up.
constexpr double bytes_per_hexahedron = 4400, bytes_per_tetrahedron = 1200, bytes_per_quad = 2500,
                 bytes_per_triangle = 1300, bytes_per_segment = 1000;

struct MeshEstimate {
  double bytes = 0;
  std::string key;   // the key that sets the size
  std::string what;  // e.g. "4096 x 4096 x 4096 = 6.87e+10 hexahedra"
};

std::string short_number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, x < 1e6 && std::trunc(x) == x ? "%.0f" : "%.3g", x);
  return buf;
}

std::string bytes_text(double b) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB", "EB"};
  std::size_t u = 0;
  while (b >= 1000 && u + 1 < std::size(units)) b /= 1000, ++u;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%.3g %s", b, units[u]);
  return buf;
}

// The memory a procedural mesh will need, from its cell count (0 for mesh files: their readers
// check counts against the data they hold).
MeshEstimate estimate(const MeshSpec& m) {
  const double cx = m.cells[0], cy = m.cells[1], cz = m.cells[2];
  auto make = [](double cells, double per_cell, std::string key, std::string what) {
    return MeshEstimate{cells * per_cell, std::move(key), what + " = " + short_number(cells)};
  };
  const std::string grid3 = short_number(cx) + " x " + short_number(cy) + " x " + short_number(cz);
  const std::string grid2 = short_number(cx) + " x " + short_number(cy);
  if (m.type == "hex_grid") return make(cx * cy * cz, bytes_per_hexahedron, "cells", grid3);
  if (m.type == "tet_grid") {
    const double per = m.split == "five" ? 5 : 6;
    return make(per * cx * cy * cz, bytes_per_tetrahedron, "cells", short_number(per) + " x " + grid3);
  }
  if (m.type == "quad_grid") return make(cx * cy, bytes_per_quad, "cells", grid2);
  if (m.type == "tri_grid") return make(2 * cx * cy, bytes_per_triangle, "cells", "2 x " + grid2);
  const double rings = m.rings, sectors = m.sectors;
  if (m.type == "disc")  // ring k adds sectors·(2k − 1) triangles
    return make(sectors * rings * rings, bytes_per_triangle, "rings", short_number(sectors) + " sectors x " + short_number(rings) + "² rings");
  if (m.type == "cylinder")
    return make(3 * m.layers * sectors * rings * rings, bytes_per_tetrahedron, "layers",
                "3 x " + short_number(m.layers) + " layers x " + short_number(sectors) + " sectors x " + short_number(rings) + "² rings");
  if (m.type == "boxes") {
    double cells = 0;
    for (const auto& b : m.boxes)
      cells += static_cast<double>(b.hi[0] - b.lo[0]) * static_cast<double>(b.hi[1] - b.lo[1]) * static_cast<double>(b.hi[2] - b.lo[2]);
    return make(cells, bytes_per_hexahedron, "boxes", "the boxes' cells");
  }
  if (m.type == "surface")  // at most the whole grid of cells³ (a cube's surface fills it)
    return make(cx * cx * cx, bytes_per_hexahedron, "resolution", "up to " + short_number(cx) + "³");
  if (m.type == "polyline")
    return make(static_cast<double>(m.points.size()) - 1, bytes_per_segment, "points", "the segments");
  return {};
}

// Refuses a scene whose meshes or step count exceed its limits, naming the estimate and the key
// that raises the limit.
void check_limits(const Scene& s, const nlohmann::json& limits_json, const Field& limits_schema) {
  Reader lim(limits_json, limits_schema);
  const double max_memory = lim.number("memory"), max_steps = lim.number("steps");
  double total = 0;
  std::size_t largest = 0;
  std::vector<MeshEstimate> est;
  // pre-refinement splits each hexahedron 1:8 per level: counted as if it applied to every cell
  double growth = 1;
  for (const PreRefineSpec& p : s.refinement.pre_refine) growth = std::max(growth, std::pow(8.0, p.levels));
  for (std::size_t i = 0; i < s.meshes.size(); ++i) {
    est.push_back(estimate(s.meshes[i]));
    est.back().bytes *= growth;
    if (growth > 1) est.back().what += " x " + short_number(growth) + " (refinement.pre_refine)";
    total += est.back().bytes;
    if (est.back().bytes > est[largest].bytes) largest = i;
  }
  if (total > max_memory) {
    const MeshEstimate& e = est[largest];
    throw SceneError(s.file, "meshes[" + std::to_string(largest) + "]." + e.key,
                     "the scene needs about " + bytes_text(total) + " of memory (this mesh: " + e.what + " cells, about " +
                         bytes_text(e.bytes) + "), more than limits.memory = " + bytes_text(max_memory) +
                         "; use fewer cells, or raise limits.memory if the machine has it");
  }
  const double steps = s.duration / s.step;
  if (!(steps <= max_steps))
    throw SceneError(s.file, "integrator.step",
                     "a step of " + short_number(s.step) + " s over duration " + short_number(s.duration) + " s makes " +
                         short_number(steps) + " steps, more than limits.steps = " + short_number(max_steps) +
                         "; use a longer step or a shorter duration, or raise limits.steps");
}

// What `motion` cannot be combined with, said at the key.
void check_motion(const Scene& s) {
  for (std::size_t k = 0; k < s.motion.size(); ++k) {
    const std::string path = "motion[" + std::to_string(k) + "]";
    if (s.motion[k].from >= s.duration)
      throw SceneError(s.file, path + ".from", "is not before the end of the run (duration " + std::to_string(s.duration) + " s)");
    if (!s.cuts.empty()) throw SceneError(s.file, path, "prescribed motion cannot be combined with `cuts` yet (a cut duplicates driven particles)");
    if (s.refinement.enabled)
      throw SceneError(s.file, path, "prescribed motion cannot be combined with `refinement` yet (refinement renumbers particles)");
  }
}

}  // namespace

Selector read_selector(const nlohmann::json& j, const Field& schema) {
  const std::string type = j.at("type").get<std::string>();
  Reader r(j, schema, type);
  Selector s;
  if (type == "all") s.type = Selector::Type::all;
  if (type == "box") {
    s.type = Selector::Type::box;
    s.min = r.vec3("min");
    s.max = r.vec3("max");
  } else if (type == "sphere") {
    s.type = Selector::Type::sphere;
    s.center = r.vec3("center");
    s.radius = r.number("radius");
  } else if (type == "tag") {
    s.type = Selector::Type::tag;
    s.tag = static_cast<int>(r.integer("tag"));
  } else if (type == "points") {
    s.type = Selector::Type::points;
    for (const auto& x : r["indices"]) s.points.push_back(static_cast<std::uint32_t>(x.get<double>()));
  }
  return s;
}

bool Selector::contains(const Vec3& p) const {
  switch (type) {
    case Type::all: return true;
    case Type::box:
      return p[0] >= min[0] && p[0] <= max[0] && p[1] >= min[1] && p[1] <= max[1] && p[2] >= min[2] && p[2] <= max[2];
    case Type::sphere: {
      const double dx = p[0] - center[0], dy = p[1] - center[1], dz = p[2] - center[2];
      return dx * dx + dy * dy + dz * dz <= radius * radius;
    }
    default: return false;  // tags and point lists are not geometric
  }
}

const Field& scene_schema() {
  static const Field schema = build_schema();
  return schema;
}

Scene parse_scene(const nlohmann::json& j, const std::string& file) {
  const Field& schema = scene_schema();
  validate(j, schema, file);
  Reader r(j, schema);
  Scene s;
  s.file = file;
  s.name = r.string("name");
  if (const std::string why = name_problem(s.name); !why.empty()) throw SceneError(file, "name", why);
  if (s.name.empty()) {
    s.name = file == "(default)" ? "default" : std::filesystem::path(file).stem().string();
    if (const std::string why = name_problem(s.name); !why.empty() || s.name.empty())
      throw SceneError(file, "name", "is not set, and the file name \"" + s.name + "\" cannot stand for it: " +
                                         (why.empty() ? std::string("it is empty") : why) + "; set `name`");
  }
  s.description = r.string("description");

  const Field& material_schema = *schema.member("materials")->element_;
  for (auto it = r["materials"].begin(); it != r["materials"].end(); ++it) {
    Reader m(it.value(), material_schema);
    MaterialSpec ms;
    ms.young = m.number("young");
    ms.poisson = m.number("poisson");
    ms.density = m.number("density");
    ms.thickness = m.number("thickness");
    ms.area = m.number("area");
    ms.elongated = m.string("elongated");
    ms.volume_stiffness = m.number("volume_stiffness");
    s.materials[it.key()] = ms;
  }
  auto check_material = [&](const std::string& name, const std::string& path) {
    if (!s.materials.count(name)) {
      std::vector<std::string> names;
      for (const auto& [n, _] : s.materials) names.push_back(n);
      const std::string near = closest_key(name, names);
      throw SceneError(file, path, "no material named \"" + name + "\"" + (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
    }
  };

  const Field& mesh_schema = *schema.member("meshes")->element_;
  const auto base = std::filesystem::path(file).parent_path();
  for (std::size_t i = 0; i < r["meshes"].size(); ++i) {
    const auto& mj = r["meshes"][i];
    const std::string path = "meshes[" + std::to_string(i) + "]";
    MeshSpec m;
    m.type = mj.at("type").get<std::string>();
    Reader mr(mj, mesh_schema, m.type);
    m.name = mr.string("name");
    if (m.name.empty()) m.name = m.type + std::to_string(i);
    m.material = mr.string("material");
    check_material(m.material, path + ".material");
    const Field& region_schema = *mesh_schema.member("regions")->element_;
    for (std::size_t k = 0; k < mr["regions"].size(); ++k) {
      const auto& rj = mr["regions"][k];
      Reader rr(rj, region_schema);
      check_material(rr.string("material"), path + ".regions[" + std::to_string(k) + "].material");
      m.regions.emplace_back(read_selector(rj.at("where"), *region_schema.member("where")), rr.string("material"));
    }
    if (mesh_schema.member("cells", m.type)) {
      const auto& c = mr["cells"];
      for (std::size_t k = 0; k < c.size(); ++k) m.cells[k] = static_cast<std::uint32_t>(c[k].get<double>());
      const auto& sz = mr["size"];
      for (std::size_t k = 0; k < sz.size(); ++k) m.size[k] = sz[k].get<double>();
    }
    if (mesh_schema.member("origin", m.type)) m.origin = mr.vec3("origin");
    if (m.type == "tet_grid") m.split = mr.string("split");
    if (mesh_schema.member("plane", m.type)) m.plane = mr.string("plane");
    if (m.type == "disc" || m.type == "cylinder") {
      m.radius = mr.number("radius");
      m.rings = static_cast<std::uint32_t>(mr.integer("rings"));
      m.sectors = static_cast<std::uint32_t>(mr.integer("sectors"));
    }
    if (m.type == "cylinder") {
      m.height = mr.number("height");
      m.layers = static_cast<std::uint32_t>(mr.integer("layers"));
    }
    if (m.type == "boxes") {
      m.size = mr.vec3("spacing");
      for (std::size_t k = 0; k < mr["boxes"].size(); ++k) {
        const auto& bj = mr["boxes"][k];
        const std::string bpath = path + ".boxes[" + std::to_string(k) + "]";
        LatticeBoxSpec b;
        for (std::size_t a = 0; a < 3; ++a) {
          b.lo[a] = static_cast<int>(bj.at("min")[a].get<double>());
          b.hi[a] = static_cast<int>(bj.at("max")[a].get<double>());
          if (b.hi[a] <= b.lo[a]) throw SceneError(file, bpath, "max must exceed min along every axis");
        }
        m.boxes.push_back(b);
      }
    }
    if (m.type == "polyline")
      for (const auto& p : mr["points"]) m.points.push_back({p[0].get<double>(), p[1].get<double>(), p[2].get<double>()});
    if (m.type == "surface") {
      const auto p = std::filesystem::path(mr.string("path"));
      m.path = (p.is_absolute() || file == "(default)") ? p.string() : (base / p).string();
      m.cells[0] = static_cast<std::uint32_t>(mr.integer("resolution"));
      m.scale = mr.number("scale");
      m.translate = mr.vec3("translate");
      std::error_code ec;
      if (mr.string("missing") == "skip" && !std::filesystem::exists(m.path, ec) && s.skip.empty())
        s.skip = path + ".path: " + m.path + " is not present";
    }
    if (m.type == "file") {
      const auto p = std::filesystem::path(mr.string("path"));
      m.path = (p.is_absolute() || file == "(default)") ? p.string() : (base / p).string();
      m.scale = mr.number("scale");
      m.translate = mr.vec3("translate");
    }
    s.meshes.push_back(std::move(m));
  }

  const Field& fix_schema = *schema.member("fixed")->element_;
  for (const auto& fj : r["fixed"]) {
    Reader fr(fj, fix_schema);
    s.fixed.push_back({read_selector(fj.at("where"), *fix_schema.member("where")), read_axes(fr.string("axes"))});
  }
  const Field& velocity_schema = *schema.member("velocities")->element_;
  for (const auto& vj : r["velocities"]) {
    Reader vr(vj, velocity_schema);
    s.velocities.push_back({read_selector(vj.at("where"), *velocity_schema.member("where")), vr.vec3("linear"),
                            vr.vec3("angular"), vr.vec3("center")});
  }
  s.motion = read_motion(r["motion"], *schema.member("motion"), file, s.motion_where);
  s.gravity = r.vec3("gravity");
  s.obstacles = read_obstacles(r["obstacles"], *schema.member("obstacles"), file);
  {
    Reader d(r["damping"], *schema.member("damping"));
    s.damping = d.string("model");
    s.rayleigh_alpha = d.number("alpha");
    s.rayleigh_beta = d.number("beta");
    s.environment_damping = d.number("environment");
  }
  {
    Reader m(r["model"], *schema.member("model"));
    s.model = m.string("type");
    s.law = m.string("law");
    s.bending = m.string("bending");
    const Field& group_schema = *schema.member("model")->member("groups")->element_;
    for (std::size_t k = 0; k < m["groups"].size(); ++k) {
      const auto& gj = m["groups"][k];
      const std::string gpath = "model.groups[" + std::to_string(k) + "]";
      Reader g(gj, group_schema);
      ModelGroup mg;
      if (g.has("tag") == g.has("name"))
        throw SceneError(file, gpath, g.has("tag") ? "give either tag or name, not both" : "give the cells' tag (a number) or name (a Gmsh physical name)");
      if (g.has("tag")) mg.tag = static_cast<int>(g.integer("tag"));
      if (g.has("name")) {
        mg.name = g.string("name");
        if (mg.name.empty()) throw SceneError(file, gpath + ".name", "the physical name is empty");
      }
      mg.as = g.string("as");
      if (g.has("radius")) mg.semi_axes = {g.number("radius"), g.number("radius")};
      if (g.has("semi_axes")) {
        if (g.has("radius")) throw SceneError(file, gpath + ".semi_axes", "give either radius or semi_axes, not both");
        mg.semi_axes = {g["semi_axes"][0].get<double>(), g["semi_axes"][1].get<double>()};
      }
      if (mg.as != "rod" && mg.semi_axes[0] > 0)
        throw SceneError(file, gpath + (g.has("radius") ? ".radius" : ".semi_axes"), "a section applies to rods only, not to \"" + mg.as + "\"");
      if (s.model == "mass-spring" && mg.as != "label")
        throw SceneError(file, gpath + ".as", "\"" + mg.as + "\" cannot be combined with model.type \"mass-spring\" (use \"mixed\", or \"label\")");
      s.model_groups.push_back(mg);
    }
    if (m.has("connections")) {
      if (s.model == "mass-spring") throw SceneError(file, "model.connections", "connections join continuum bodies (model.type solid, shell or mixed), not springs");
      s.connections = read_connections(m["connections"], *schema.member("model")->member("connections"), file);
    }
  }
  {
    Reader in(r["integrator"], *schema.member("integrator"));
    s.integrator = in.string("type");
    s.step = in.number("step");
    s.solver = in.string("solver");
    if (s.solver == "ldlt") {
      if (s.integrator != "newton")
        throw SceneError(file, "integrator.solver", "\"ldlt\" solves the Newton systems of integrator.type \"newton\" only (this scene's is \"" + s.integrator + "\")");
    } else {
      try {
        (void)physics::solve::parse_backend(s.solver);  // a name this build lacks
      } catch (const physics::InputError& e) {
        throw SceneError(file, "integrator.solver", e.what());
      }
      if (s.integrator == "newton" && (s.solver == "hypre-pcg" || s.solver == "petsc" || s.solver == "sa-pcg"))
        throw SceneError(file, "integrator.solver", "\"" + s.solver + "\" does not solve Newton systems: integrator.type \"newton\" takes \"jacobi\" (or \"auto\"), \"ldlt\", \"cholmod\" or \"cholmod-pcg\"");
    }
    s.tolerance = in.number("tolerance");
    s.absolute_tolerance = in.number("absolute_tolerance");
    s.absolute_acceleration = in.number("absolute_acceleration");
    s.max_iterations = static_cast<std::uint32_t>(in.integer("max_iterations"));
    s.newton_tolerance = in.number("newton_tolerance");
    s.newton_iterations = static_cast<std::uint32_t>(in.integer("newton_iterations"));
    s.newton_forcing = in.number("newton_forcing");
    if (s.newton_forcing > 0.0 && (s.integrator != "newton" || s.solver != "cholmod-pcg"))
      throw SceneError(file, "integrator.newton_forcing", "inexact Newton's forcing terms need integrator.type \"newton\" with solver \"cholmod-pcg\" (got \"" + s.integrator + "\" with \"" + s.solver + "\")");
    s.allow_unstable = in.boolean("allow_unstable");
    s.energy_rise_tolerance = in.number("energy_rise_tolerance");
    s.stop_on_inversion = in.boolean("stop_on_inversion");
  }
  s.duration = r.number("duration");
  s.threads = static_cast<std::uint32_t>(r.integer("threads"));
  if (s.step > s.duration) throw SceneError(file, "integrator.step", "is longer than the whole run (duration " + std::to_string(s.duration) + " s)");
  if (r.has("refinement")) s.refinement = read_refinement(r["refinement"], *schema.member("refinement"), file);
  check_limits(s, r["limits"], *schema.member("limits"));
  s.refinement.max_elements = Reader(r["limits"], *schema.member("limits")).number("memory") / bytes_per_hexahedron;

  const Field& cut_schema = *schema.member("cuts")->element_;
  for (std::size_t i = 0; i < r["cuts"].size(); ++i) {
    const auto& cj = r["cuts"][i];
    const std::string path = "cuts[" + std::to_string(i) + "]";
    CutSpec c;
    c.type = cj.at("type").get<std::string>();
    Reader cr(cj, cut_schema, c.type);
    c.time = cr.number("time");
    if (c.time > s.duration) throw SceneError(file, path + ".time", "is after the end of the run (duration " + std::to_string(s.duration) + " s)");
    if (c.type == "plane") {
      c.point = cr.vec3("point");
      c.normal = cr.vec3("normal");
      if (c.normal[0] == 0 && c.normal[1] == 0 && c.normal[2] == 0) throw SceneError(file, path + ".normal", "must not be zero");
      if (cr.has("within")) c.within = read_selector(cj.at("within"), *cut_schema.member("within", "plane"));
    } else if (c.type == "faces") {
      for (std::size_t k = 0; k < cr["faces"].size(); ++k) {
        std::vector<std::uint32_t> f;
        for (const auto& x : cr["faces"][k]) f.push_back(static_cast<std::uint32_t>(x.get<double>()));
        c.faces.push_back(std::move(f));
      }
    } else if (c.type == "particles") {
      for (const auto& x : cr["particles"]) c.particles.push_back(static_cast<std::uint32_t>(x.get<double>()));
    } else if (c.type == "pierce") {
      c.where = read_selector(cj.at("where"), *cut_schema.member("where", "pierce"));
      c.remove = cr.boolean("remove");
    }
    s.cuts.push_back(std::move(c));
  }
  check_motion(s);

  {
    Reader o(r["output"], *schema.member("output"));
    s.frames = static_cast<std::uint32_t>(o.integer("frames"));
    s.write_vtu = o.boolean("vtu");
    s.write_csv = o.boolean("csv");
    const Field& pic_schema = *schema.member("output")->member("picture");
    const nlohmann::json picture = o["picture"].is_null() ? nlohmann::json::object() : o["picture"];
    Reader p(picture, pic_schema);
    s.write_picture = p.boolean("enabled");
    s.color_by = p.string("color_by");
    s.style = p.string("style");
    s.width = static_cast<std::uint32_t>(p.integer("width"));
    s.height = static_cast<std::uint32_t>(p.integer("height"));
  }
  return s;
}

Scene load_scene(const std::string& path) {
  std::error_code ec;
  const auto status = std::filesystem::status(path, ec);
  if (ec && ec != std::errc::no_such_file_or_directory) throw SceneError(path, "", "cannot be read: " + ec.message());
  if (!std::filesystem::exists(status)) throw SceneError(path, "", "no such file");
  if (std::filesystem::is_directory(status)) throw SceneError(path, "", "is a folder, not a scene file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw SceneError(path, "", "cannot be read");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw SceneError(path, "", "cannot be read");
  return parse_scene(parse_json(text, path), path);
}

const char* default_scene_json() {
  return R"json({
  "name": "default",
  "description": "A 1 m cantilever of 40x4x4 hexahedra (2.5 cm cubes), clamped at x = 0, sagging under gravity; at t = 0.6 s, while it still swings, the upper three quarters of its section are cut through at mid-span and the cut opens. Air drag brings it to rest.",
  "materials": { "rubbery": { "young": 2e7, "poisson": 0.3, "density": 1000 } },
  "meshes": [ { "type": "hex_grid", "name": "beam", "material": "rubbery",
                "cells": [40, 4, 4], "size": [1.0, 0.1, 0.1], "origin": [0, -0.05, -0.05] } ],
  "fixed": [ { "where": { "type": "box", "min": [-1, -1, -1], "max": [0.001, 1, 1] } } ],
  "gravity": [0, 0, -9.81],
  "damping": { "model": "viscous", "environment": 4 },
  "integrator": { "type": "implicit", "step": 0.001 },
  "duration": 2.0,
  "cuts": [ { "type": "plane", "time": 0.6, "point": [0.5, 0, 0], "normal": [1, 0, 0],
              "within": { "type": "box", "min": [0.4, -1, -0.03], "max": [0.6, 1, 1] } } ],
  "output": { "frames": 80, "picture": { "color_by": "displacement" } }
})json";
}

Scene default_scene() { return parse_scene(nlohmann::json::parse(default_scene_json()), "(default)"); }

}  // namespace sewn::app
