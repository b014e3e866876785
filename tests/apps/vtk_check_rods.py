#!/usr/bin/python3
"""Reads the series `sewn run tests/apps/data/tiny_rod.json` wrote with VTK's own readers (CTest).
Checks that every frame holds the rod as one VTK poly-line through its 11 points in order, with
point vectors `rod_m1` and `rod_m2` (the material frame at each node) forming with the node's
tangent a right-handed orthonormal frame, and that the rod sagged (its tip moved down) so the
check ran on bent frames too.
Prints SEWN-SKIP and succeeds when VTK's Python bindings are missing, unless SEWN_CI is set."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtk_checks import Checks, import_vtk, pvd_frames, read_vtu  # noqa: E402

vtk = import_vtk("vtk_check_rods")

out = sys.argv[1]
checks = Checks()
check = checks.check
failures = checks.failures

frames = pvd_frames(os.path.join(out, "tiny_rod.pvd"))
check(len(frames) == 5, "the .pvd lists %d frames, expected 5" % len(frames))
tip_z = []


def unit(a):
    n = math.sqrt(sum(x * x for x in a))
    return [x / n for x in a]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


for name in frames:
    grid = read_vtu(vtk, os.path.join(out, name), check)
    check(grid.GetNumberOfPoints() == 11, "%s: %d points, expected 11" % (name, grid.GetNumberOfPoints()))
    check(grid.GetNumberOfCells() == 1, "%s: %d cells, expected 1 (the rod)" % (name, grid.GetNumberOfCells()))
    m1s, m2s = (grid.GetPointData().GetArray(a) for a in ("rod_m1", "rod_m2"))
    check(m1s is not None and m2s is not None, "%s: no rod_m1 / rod_m2 point arrays" % name)
    if m1s is None or m2s is None or grid.GetNumberOfCells() != 1:
        continue
    check(grid.GetCellType(0) == vtk.VTK_POLY_LINE, "%s: the rod is of VTK type %d, not a poly-line" % (name, grid.GetCellType(0)))
    ids = grid.GetCell(0).GetPointIds()
    chain = [ids.GetId(k) for k in range(ids.GetNumberOfIds())]
    check(chain == list(range(11)), "%s: the poly-line runs through points %s, not 0..10 in order" % (name, chain))
    worst = 0.0
    for k, p in enumerate(chain):
        # the node's tangent: the mean of its edges' unit tangents (one at an end)
        t = [0.0, 0.0, 0.0]
        for a, b in ((k - 1, k), (k, k + 1)):
            if 0 <= a and b < len(chain):
                e = unit([grid.GetPoint(chain[b])[i] - grid.GetPoint(chain[a])[i] for i in range(3)])
                t = [t[i] + e[i] for i in range(3)]
        t = unit(t)
        m1, m2 = m1s.GetTuple3(p), m2s.GetTuple3(p)
        tm = cross(t, m1)
        worst = max(worst, abs(sum(m1[i] * t[i] for i in range(3))), abs(math.sqrt(sum(v * v for v in m1)) - 1.0),
                    max(abs(m2[i] - tm[i]) for i in range(3)))
    check(worst < 1e-9, "%s: (t, rod_m1, rod_m2) is not a right-handed orthonormal frame at some node (off by %g)" % (name, worst))
    tip_z.append(grid.GetPoint(10)[2])
check(len(tip_z) == len(frames) and tip_z[-1] < tip_z[0] - 1e-3, "the rod's tip did not sag: z %s" % tip_z)

if failures:
    print("vtk_check_rods: " + "\n  ".join(failures))
    sys.exit(1)
print("vtk_check_rods: %d frames, one poly-line of 11 points each, (t, m1, m2) orthonormal at every node; tip z %.4f -> %.4f m"
      % (len(frames), tip_z[0], tip_z[-1]))
