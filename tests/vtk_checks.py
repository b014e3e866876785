"""What the VTK read-back checks run by CTest share (tests/io/tools/vtk_check.py,
tests/apps/vtk_check_*.py): importing VTK's Python bindings, or skipping without them, reading
a .vtu with VTK's reader and a series' frame list, and collecting failed checks."""
import os
import sys
import xml.etree.ElementTree as ET


def import_vtk(script):
    """VTK's module; without it prints SEWN-SKIP and exits 0, unless SEWN_CI is set: CI installs
    the bindings, so there a missing VTK is a failure (exit 1), not a skip."""
    try:
        import vtk
    except ImportError:
        if os.environ.get("SEWN_CI"):
            print(script + ": VTK's Python bindings (python3-vtk9) are missing but SEWN_CI is set")
            sys.exit(1)
        print("SEWN-SKIP: VTK's Python bindings (python3-vtk9) are not installed for " + sys.executable)
        sys.exit(0)
    return vtk


class Checks:
    """Failed checks, each described, collected so one run reports all of them."""

    def __init__(self):
        self.failures = []

    def check(self, cond, what):
        if not cond:
            self.failures.append(what)


def read_vtu(vtk, path, check):
    """The unstructured grid VTK's own XML reader makes of path; a reader error is a failed check."""
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    check(r.GetErrorCode() == 0, path + ": VTK reports error code %d" % r.GetErrorCode())
    return r.GetOutput()


def pvd_frames(path):
    """The .vtu files a .pvd collection lists, in its order (VTK has no .pvd reader outside ParaView)."""
    return [ds.get("file") for ds in ET.parse(path).getroot().iter("DataSet")]
