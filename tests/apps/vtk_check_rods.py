#!/usr/bin/python3
"""Reads the series `sewn run tests/apps/data/tiny_rod.json` wrote with VTK's own readers (CTest).
Checks that every frame holds the rod as 10 VTK line cells on 11 points with a cell vector
`rod_director` (the material director m1 of each segment) that is a unit vector normal to its
segment, and that the rod sagged (its tip moved down) so the check ran on bent frames too.
Prints SEWN-SKIP and succeeds when VTK's Python bindings are missing, unless SEWN_CI is set."""
import math
import os
import sys
import xml.etree.ElementTree as ET

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from vtk_checks import Checks, import_vtk  # noqa: E402

vtk = import_vtk("vtk_check_rods")

out = sys.argv[1]
checks = Checks()
check = checks.check
failures = checks.failures

frames = [ds.get("file") for ds in ET.parse(os.path.join(out, "tiny_rod.pvd")).getroot().iter("DataSet")]
check(len(frames) == 5, "the .pvd lists %d frames, expected 5" % len(frames))
tip_z = []
for name in frames:
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(os.path.join(out, name))
    reader.Update()
    grid = reader.GetOutput()
    check(grid.GetNumberOfPoints() == 11, "%s: %d points, expected 11" % (name, grid.GetNumberOfPoints()))
    check(grid.GetNumberOfCells() == 10, "%s: %d cells, expected 10" % (name, grid.GetNumberOfCells()))
    directors = grid.GetCellData().GetArray("rod_director")
    check(directors is not None, "%s: no rod_director cell array" % name)
    if directors is None:
        continue
    worst = 0.0
    for c in range(grid.GetNumberOfCells()):
        check(grid.GetCellType(c) == vtk.VTK_LINE, "%s: cell %d is of VTK type %d, not a line" % (name, c, grid.GetCellType(c)))
        ids = grid.GetCell(c).GetPointIds()
        a, b = grid.GetPoint(ids.GetId(0)), grid.GetPoint(ids.GetId(1))
        t = [b[k] - a[k] for k in range(3)]
        length = math.sqrt(sum(x * x for x in t))
        m1 = directors.GetTuple3(c)
        worst = max(worst, abs(sum(m1[k] * t[k] for k in range(3))) / length, abs(math.sqrt(sum(x * x for x in m1)) - 1.0))
    check(worst < 1e-9, "%s: a rod_director is not a unit vector normal to its segment (off by %g)" % (name, worst))
    tip_z.append(grid.GetPoint(10)[2])
check(len(tip_z) == len(frames) and tip_z[-1] < tip_z[0] - 1e-3, "the rod's tip did not sag: z %s" % tip_z)

if failures:
    print("vtk_check_rods: " + "\n  ".join(failures))
    sys.exit(1)
print("vtk_check_rods: %d frames, 10 line cells each, directors unit and normal to their segments; tip z %.4f -> %.4f m"
      % (len(frames), tip_z[0], tip_z[-1]))
