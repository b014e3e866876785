"""What the VTK read-back checks run by CTest share (tests/io/tools/vtk_check.py,
tests/apps/vtk_check_*.py): importing VTK's Python bindings, or skipping without them, and
collecting failed checks."""
import os
import sys


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
