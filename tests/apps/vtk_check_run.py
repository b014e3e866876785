#!/usr/bin/python3
"""Reads the series `sewn run tests/apps/data/tiny.json` wrote with VTK's own readers (CTest).
Checks the .pvd lists every frame, each .vtu has the model's point and cell counts (a 6x2x2 beam:
63 particles and 24 hexahedra, 9 more particles once the section is cut through at mid-span),
and that the displacement array equals position minus the first frame's position.
Prints SEWN-SKIP and succeeds when VTK's Python bindings are missing, unless SEWN_CI is set."""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtk_checks import Checks, import_vtk, pvd_frames, read_vtu  # noqa: E402

vtk = import_vtk("vtk_check_run")

out = sys.argv[1]
checks = Checks()
check = checks.check
failures = checks.failures

frames = pvd_frames(os.path.join(out, "tiny.pvd"))
check(len(frames) == 5, "the .pvd lists %d frames, expected 5 (frame 0 and 4 more)" % len(frames))
first = None
for i, name in enumerate(frames):
    g = read_vtu(vtk, os.path.join(out, name), check)
    cut = i >= 3  # the cut happens at t = 0.1 s, between frames 2 (0.1 s) and 3
    points = 63 + (9 if cut else 0)
    check(g.GetNumberOfPoints() == points, "%s: %d points, expected %d" % (name, g.GetNumberOfPoints(), points))
    check(g.GetNumberOfCells() == 24, "%s: %d cells, expected 24" % (name, g.GetNumberOfCells()))
    check(all(g.GetCellType(c) == vtk.VTK_HEXAHEDRON for c in range(g.GetNumberOfCells())), name + ": not all hexahedra")
    for array in ("velocity", "force", "displacement", "fixed"):
        check(g.GetPointData().GetArray(array) is not None, "%s: no point array %s" % (name, array))
    for array in ("material", "refinement_level"):
        check(g.GetCellData().GetArray(array) is not None, "%s: no cell array %s" % (name, array))
    x = [g.GetPoint(p) for p in range(g.GetNumberOfPoints())]
    disp = g.GetPointData().GetArray("displacement")
    u = [disp.GetTuple3(p) for p in range(g.GetNumberOfPoints())]
    if first is None:
        first = x
        check(max(abs(c) for t in u for c in t) == 0.0, name + ": frame 0 has non-zero displacement")
    else:
        n = min(len(first), len(x))  # particles added by the cut come after the original ones
        err = max(abs(x[p][k] - first[p][k] - u[p][k]) for p in range(n) for k in range(3))
        check(err <= 1e-12, "%s: displacement differs from position - rest by %g" % (name, err))

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("vtk_check_run: %d frames read back by VTK" % len(frames))
