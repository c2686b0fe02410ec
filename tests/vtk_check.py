#!/usr/bin/env python3
"""Reads voussoir's VTU output back with VTK and checks it.

usage: vtk_check.py BLOCKS.vtu CONTACTS.vtu PVD N_BLOCKS TOTAL_VOLUME N_SUBCONTACTS TOTAL_AREA
Exit status 0 when everything matches; prints what it measured.
"""
import sys

import vtk


def read(path):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    if r.GetErrorCode() != 0:
        sys.exit(f"{path}: reader error {r.GetErrorCode()}")
    return r.GetOutput()


def main():
    blocks, contacts, pvd = sys.argv[1:4]
    n_blocks, volume, n_subs, area = int(sys.argv[4]), float(sys.argv[5]), int(sys.argv[6]), float(sys.argv[7])
    g = read(blocks)
    assert g.GetNumberOfCells() == n_blocks, (g.GetNumberOfCells(), n_blocks)
    types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}
    assert types == {vtk.VTK_POLYHEDRON}, types
    # Total volume of the polyhedron cells, measured by VTK itself.
    q = vtk.vtkCellSizeFilter()
    q.SetInputData(g)
    q.SetComputeVolume(True)
    q.Update()
    vols = q.GetOutput().GetCellData().GetArray("Volume")
    total = sum(vols.GetValue(i) for i in range(vols.GetNumberOfTuples()))
    assert abs(total - volume) < 1e-9 * volume, (total, volume)
    ids = g.GetCellData().GetArray("block_id")
    assert [int(ids.GetValue(i)) for i in range(n_blocks)] == list(range(n_blocks))
    for name in ("material", "displacement", "velocity", "rotation", "fixed"):
        assert g.GetCellData().GetArray(name) is not None, name

    c = read(contacts)
    assert c.GetNumberOfPoints() == n_subs, (c.GetNumberOfPoints(), n_subs)
    assert c.GetNumberOfCells() == n_subs
    a = c.GetPointData().GetArray("area")
    total_area = sum(a.GetValue(i) for i in range(a.GetNumberOfTuples()))
    assert abs(total_area - area) < 1e-9 * area, (total_area, area)
    for name in ("normal_force", "normal_stress", "shear_force", "state", "slip"):
        assert c.GetPointData().GetArray(name) is not None, name

    p = vtk.vtkPVDReader() if hasattr(vtk, "vtkPVDReader") else None
    if p is not None:
        p.SetFileName(pvd)
        p.UpdateInformation()
    print(f"VTK {vtk.vtkVersion.GetVTKVersion()}: {n_blocks} polyhedra, volume {total:.12g} m3, "
          f"{n_subs} sub-contacts, area {total_area:.12g} m2")


if __name__ == "__main__":
    main()
