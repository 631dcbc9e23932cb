"""Reading a lumen centerline from a VTK PolyData file (.vtp) as VMTK's vmtkcenterlines and
SimVascular write it: one polyline along the vessel, its points in order, with the lumen radius as
a point-data array. The radius is the first array present of RADIUS_ARRAYS (VMTK names it
MaximumInscribedSphereRadius); an optional array `wall` gives the total wall thickness. The checks
are those of the CSV (centerline_csv.checked_centerline). Units: mm."""
import os

import numpy as np

from .centerline_csv import checked_centerline, read_centerline_csv
from .errors import PatientInputError
from .surface_file import read_mesh

MAX_BYTES = 64 * 2**20
RADIUS_ARRAYS = ("MaximumInscribedSphereRadius", "radius", "r")


def read_centerline(path):
    """A centerline file, CSV or VTP by its extension (centerline_csv.read_centerline_csv, or below)."""
    if str(path).lower().endswith(".vtp"):
        return read_centerline_vtp(path)
    return read_centerline_csv(path)


def read_centerline_vtp(path):
    """The centerline, or PatientInputError naming the file and the problem."""
    path = str(path)
    if os.path.isfile(path) and os.path.getsize(path) > MAX_BYTES:
        raise PatientInputError(f"{path}: expected a centerline of at most {MAX_BYTES // 2**20} MiB")
    mesh = read_mesh(path, "a centerline: one polyline with a radius array")
    lines = [ids for ids in getattr(mesh, "polylines", []) if len(ids) > 1]
    if len(lines) != 1:
        raise PatientInputError(
            f"{path}: expected one centerline polyline (a vessel without branches, ends included), got "
            f"{len(lines)} (extract the branch to stent, e.g. vmtkbranchextractor, or merge its pieces)"
        )
    ids = lines[0]
    name = next((n for n in RADIUS_ARRAYS if n in mesh.point_data), None)
    if name is None:
        have = ", ".join(sorted(mesh.point_data)) or "none"
        raise PatientInputError(
            f"{path}: expected a point data array with the lumen radius (mm), one of {', '.join(RADIUS_ARRAYS)}; "
            f"got arrays: {have}"
        )

    def column(n):
        v = np.asarray(mesh.point_data[n], dtype=float)
        if v.ndim != 1 and not (v.ndim == 2 and v.shape[1] == 1):
            raise PatientInputError(f"{path}: point data '{n}': expected one value per point, got shape {v.shape}")
        v = v.reshape(-1)[ids]
        if not np.all(np.isfinite(v)):
            raise PatientInputError(f"{path}: point data '{n}': expected finite values, got NaN or Inf")
        return v

    pts = np.asarray(mesh.points, dtype=float)[ids, :3]
    if not np.all(np.isfinite(pts)):
        raise PatientInputError(f"{path}: expected finite coordinates, got NaN or Inf")
    wall = column("wall") if "wall" in mesh.point_data else None
    return checked_centerline(path, pts, column(name), wall, lambda k: f"{path}: point {ids[k]}: ")
