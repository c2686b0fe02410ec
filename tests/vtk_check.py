#!/usr/bin/env python3
"""Reads voussoir's VTU output back with VTK and checks it.

usage: vtk_check.py BLOCKS.vtu CONTACTS.vtu PVD SURFACES.vtu N_BLOCKS TOTAL_VOLUME N_SUBCONTACTS
    TOTAL_AREA N_FACES TOTAL_SURFACE
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


def measured(grid, quantity):
    """The sum over the cells of ``quantity`` ("Volume" or "Area") as VTK measures it."""
    q = vtk.vtkCellSizeFilter()
    q.SetInputData(grid)
    q.SetComputeVolume(quantity == "Volume")
    q.SetComputeArea(quantity == "Area")
    q.Update()
    values = q.GetOutput().GetCellData().GetArray(quantity)
    return sum(values.GetValue(i) for i in range(values.GetNumberOfTuples()))


def main():
    blocks, contacts, pvd, surfaces = sys.argv[1:5]
    n_blocks, volume, n_subs, area = int(sys.argv[5]), float(sys.argv[6]), int(sys.argv[7]), float(sys.argv[8])
    n_faces, surface = int(sys.argv[9]), float(sys.argv[10])
    g = read(blocks)
    assert g.GetNumberOfCells() == n_blocks, (g.GetNumberOfCells(), n_blocks)
    types = {g.GetCellType(i) for i in range(g.GetNumberOfCells())}
    assert types == {vtk.VTK_POLYHEDRON}, types
    # Total volume of the polyhedron cells, measured by VTK itself.
    total = measured(g, "Volume")
    assert abs(total - volume) < 1e-9 * volume, (total, volume)
    ids = g.GetCellData().GetArray("block_id")
    assert [int(ids.GetValue(i)) for i in range(n_blocks)] == list(range(n_blocks))
    for name in ("material", "displacement", "velocity", "rotation", "fixed"):
        assert g.GetCellData().GetArray(name) is not None, name

    s = read(surfaces)
    assert s.GetNumberOfCells() == n_faces, (s.GetNumberOfCells(), n_faces)
    types = {s.GetCellType(i) for i in range(s.GetNumberOfCells())}
    assert types <= {vtk.VTK_TRIANGLE, vtk.VTK_QUAD, vtk.VTK_POLYGON}, types
    total_surface = measured(s, "Area")
    assert abs(total_surface - surface) < 1e-9 * surface, (total_surface, surface)
    ids = s.GetCellData().GetArray("block_id")
    assert sorted({int(ids.GetValue(i)) for i in range(n_faces)}) == list(range(n_blocks))

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
          f"{n_faces} faces, area {total_surface:.12g} m2, "
          f"{n_subs} sub-contacts, area {total_area:.12g} m2")


if __name__ == "__main__":
    main()
