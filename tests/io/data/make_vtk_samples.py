#!/usr/bin/python3
"""Writes the legacy VTK samples in this folder with VTK's own writer (python3-vtk9), so the
reader is tested against files VTK produces, not only against our reading of the spec.
Run from this folder: /usr/bin/python3 make_vtk_samples.py"""
import vtk

points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),    # 0-3  hex bottom
          (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1),    # 4-7  hex top
          (0, 0, 2), (1, 0, 2), (0, 1, 2),                # 8-10 wedge top
          (0.5, 0.5, -1),                                 # 11   pyramid apex
          (2, 0, 0), (2, 1, 0)]                           # 12-13
cells = [(12, [0, 1, 2, 3, 4, 5, 6, 7]),   # hexahedron
         (13, [4, 7, 5, 8, 10, 9]),        # wedge over the hex (VTK order: base turns away from the top)
         (14, [0, 3, 2, 1, 11]),           # pyramid under the hex, base turning towards the apex
         (10, [1, 12, 2, 5]),              # tetrahedron
         (9, [1, 12, 13, 2]),              # quad
         (5, [2, 13, 6]),                  # triangle
         (3, [12, 13]),                    # line
         (1, [11])]                        # vertex (skipped by the reader)
material = [7, 8, 9, 10, 11, 12, 13, 14]

grid = vtk.vtkUnstructuredGrid()
pts = vtk.vtkPoints()
pts.SetDataTypeToDouble()
for p in points:
    pts.InsertNextPoint(p)
grid.SetPoints(pts)
for t, ids in cells:
    grid.InsertNextCell(t, len(ids), ids)
mat = vtk.vtkIntArray()
mat.SetName("material")
for m in material:
    mat.InsertNextValue(m)
grid.GetCellData().AddArray(mat)
temp = vtk.vtkFloatArray()
temp.SetName("temperature")
for i in range(len(points)):
    temp.InsertNextValue(0.5 * i)
grid.GetPointData().SetScalars(temp)
# string arrays, as ParaView and VTK users attach notes: one with a space (percent-encoded in
# ASCII), an empty one, and one of 70 bytes (a 2-byte length in BINARY)
note = vtk.vtkStringArray()
note.SetName("note")
for text in ["made by make_vtk_samples.py", "", "x" * 70]:
    note.InsertNextValue(text)
grid.GetFieldData().AddArray(note)
part = vtk.vtkStringArray()
part.SetName("part")
for i in range(len(cells)):
    part.InsertNextValue("cell %d" % i)
grid.GetCellData().AddArray(part)

for name, version, binary in [("sample42_ascii.vtk", 42, False), ("sample51_ascii.vtk", 51, False),
                              ("sample42_binary.vtk", 42, True), ("sample51_binary.vtk", 51, True)]:
    w = vtk.vtkUnstructuredGridWriter()
    w.SetFileName(name)
    w.SetInputData(grid)
    w.SetFileVersion(version)
    if binary:
        w.SetFileTypeToBinary()
    w.Write()
