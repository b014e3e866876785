#!/usr/bin/python3
"""Reads what write_samples wrote with VTK's own readers and checks it (run by CTest).
Prints SEWN-SKIP and succeeds when VTK's Python bindings are missing, unless SEWN_CI is set:
CI installs them, so there a missing VTK is a failure, not a skip."""
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "../.."))
from vtk_checks import Checks, import_vtk, read_vtu as read_with_vtk  # noqa: E402

vtk = import_vtk("vtk_check")

checks = Checks()
check = checks.check
failures = checks.failures

def read_vtu(path):
    return read_with_vtk(vtk, path, check)


def close(a, b):
    return abs(a - b) <= 1e-12 * max(1.0, abs(a), abs(b))


def check_beam(path, k):
    g = read_vtu(path)
    check(g.GetNumberOfPoints() == 7 * 3 * 3, "%s: %d points, expected 63" % (path, g.GetNumberOfPoints()))
    check(g.GetNumberOfCells() == 6 * 2 * 2, "%s: %d cells, expected 24" % (path, g.GetNumberOfCells()))
    ids = vtk.vtkIdList()
    g.GetCellPoints(0, ids)
    check([ids.GetId(i) for i in range(ids.GetNumberOfIds())] == [0, 1, 8, 7, 21, 22, 29, 28], path + ": cell 0 points")
    check(all(g.GetCellType(c) == 12 for c in range(g.GetNumberOfCells())), path + ": cell types")
    pd, cd = g.GetPointData(), g.GetCellData()
    f, vel, fixed, pid = (pd.GetArray(n) for n in ("f", "velocity", "fixed", "id"))
    check(None not in (f, vel, fixed, pid), path + ": point arrays missing")
    if None in (f, vel, fixed, pid):
        return
    check(vel.GetNumberOfComponents() == 3, path + ": velocity is not a 3-vector")
    for i in range(g.GetNumberOfPoints()):
        x, y, z = g.GetPoint(i)
        check(close(f.GetValue(i), x + 2 * y + 3 * z), "%s: f at point %d" % (path, i))
        check(vel.GetTuple3(i) == (y, -x, float(k)), "%s: velocity at point %d" % (path, i))
        check(fixed.GetValue(i) == (1 if x == 0.0 else 0), "%s: fixed at point %d" % (path, i))
        check(pid.GetValue(i) == i, "%s: id at point %d" % (path, i))
        x0 = (i % 7) * 0.5
        check(close(z, ((i // 21) * 0.5) + 0.1 * k * x0 * x0), "%s: z of point %d" % (path, i))
    mat, lev = cd.GetArray("material"), cd.GetArray("level")
    check(mat is not None and lev is not None, path + ": cell arrays missing")
    if mat is not None and lev is not None:
        for c in range(g.GetNumberOfCells()):
            check(mat.GetValue(c) == c % 3, "%s: material of cell %d" % (path, c))
            check(lev.GetValue(c) == 0.25 * c, "%s: level of cell %d" % (path, c))


def check_mixed(path):
    g = read_vtu(path)
    check(g.GetNumberOfPoints() == 14 and g.GetNumberOfCells() == 7, path + ": counts")
    check([g.GetCellType(c) for c in range(g.GetNumberOfCells())] == [12, 13, 14, 10, 9, 5, 3], path + ": types")
    v = vtk.vtkCellValidator()
    v.SetInputData(g)
    v.Update()
    state = v.GetOutput().GetCellData().GetArray("ValidityState")
    check([state.GetValue(c) for c in range(g.GetNumberOfCells())] == [0] * 7,
          path + ": vtkCellValidator finds invalid (e.g. wrongly oriented) cells")


def check_pvd(path):
    # VTK has no .pvd reader outside ParaView; its XML parser reads the collection, and each
    # data set goes through the VTU reader.
    p = vtk.vtkXMLDataParser()
    p.SetFileName(path)
    check(p.Parse() == 1, path + ": not well-formed XML")
    root = p.GetRootElement()
    check(root is not None and root.GetAttribute("type") == "Collection", path + ": not a VTK Collection")
    if root is None:
        return
    coll = root.FindNestedElementWithName("Collection")
    sets = [coll.GetNestedElement(i) for i in range(coll.GetNumberOfNestedElements())]
    check([float(s.GetAttribute("timestep")) for s in sets] == [0.0, 0.5, 1.0], path + ": timesteps")
    for k, s in enumerate(sets):
        check_beam(os.path.join(os.path.dirname(path), s.GetAttribute("file")), k)


out = sys.argv[1]
check_pvd(os.path.join(out, "beam.pvd"))
check_mixed(os.path.join(out, "mixed.vtu"))
check_mixed(os.path.join(out, "mixed_ascii.vtu"))
for f in failures[:20]:
    print("FAIL:", f)
print("vtk_check: %d failures" % len(failures))
sys.exit(1 if failures else 0)
