"""Plaque regions read from a volume label mesh (`patient.plaque_mesh`): a mesh of the wall or of
the plaque alone (tetrahedra, hexahedra, wedges, pyramids, linear or quadratic; any format meshio
reads) with an integer cell-data array, 0 for none and k for the k-th name of `types`, as a
segmentation of IVUS, OCT or CT into tissue classes is exported. At every centerline station and
on each of the sections' rays (lumen_sections.py, angle 0 along the rotation-minimizing normal) the
labels are probed at DEPTHS points through the intima, where plaque lives (VTK's probe filter: the
label of the cell that contains the point); each label present on a ray has the depth range of the
samples carrying it, half a sample's spacing beyond the outermost ones. Each label's (station, ray)
patches become sectors as for labels on the lumen surface (plaque_labels.regions_from_labels), each
with the offset and thickness that bound its samples' depths, or reaching the intima's outer
surface when its samples do. Units: mm."""
import numpy as np

from .errors import PatientInputError
from .lumen_surface import UNITS
from .surface_file import read_mesh

DEPTHS = 16  # samples through the intima per ray
# meshio cell type -> VTK cell type id (vtkCellType.h)
VTK_TYPES = {"tetra": 10, "hexahedron": 12, "wedge": 13, "pyramid": 14, "tetra10": 24, "hexahedron20": 25}


def read_label_mesh(path, array, units):
    """The volume mesh as a vtkUnstructuredGrid with the integer cell array `label`, or
    PatientInputError naming the file and what was expected."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray

    if units not in UNITS:
        raise PatientInputError(f"{path}: units: expected one of {', '.join(UNITS)}, got {units!r}")
    mesh = read_mesh(path, f"a volume mesh with the cell data array '{array}'")
    blocks = [(k, b) for k, b in enumerate(mesh.cells) if b.type in VTK_TYPES]
    if not blocks:
        kinds = ", ".join(sorted({b.type for b in mesh.cells})) or "none"
        raise PatientInputError(f"{path}: expected volume cells ({', '.join(VTK_TYPES)}), got cells of type {kinds}")
    if array not in mesh.cell_data:
        have = ", ".join(sorted(mesh.cell_data)) or "none"
        raise PatientInputError(f"{path}: expected a cell data array '{array}' (plaque labels), got arrays: {have}")
    labels = np.concatenate([np.asarray(mesh.cell_data[array][k]).reshape(-1) for k, _ in blocks])
    if not np.all(np.isfinite(labels)) or not np.all(labels == np.round(labels)) or labels.min() < 0:
        raise PatientInputError(f"{path}: cell data '{array}': expected integer labels >= 0")
    points = np.asarray(mesh.points, dtype=float)[:, :3] * UNITS[units]
    if not np.all(np.isfinite(points)):
        raise PatientInputError(f"{path}: expected finite coordinates, got NaN or Inf")
    grid = vtk.vtkUnstructuredGrid()
    p = vtk.vtkPoints()
    p.SetData(numpy_to_vtk(np.ascontiguousarray(points), deep=True))
    grid.SetPoints(p)
    types, conn, offsets, start = [], [], [np.zeros(1, dtype=np.int64)], 0
    for _, b in blocks:
        d = np.asarray(b.data, dtype=np.int64)
        types.append(np.full(len(d), VTK_TYPES[b.type], dtype=np.uint8))
        conn.append(d.ravel())
        offsets.append(start + d.shape[1] * np.arange(1, len(d) + 1))
        start += d.size
    cells = vtk.vtkCellArray()
    cells.SetData(
        numpy_to_vtkIdTypeArray(np.concatenate(offsets).astype(np.int64), deep=True),
        numpy_to_vtkIdTypeArray(np.concatenate(conn), deep=True),
    )
    cell_types = np.concatenate(types)
    grid.SetCells(numpy_to_vtk(cell_types, deep=True, array_type=vtk.VTK_UNSIGNED_CHAR), cells)
    lab = numpy_to_vtk(labels.astype(np.int32), deep=True, array_type=vtk.VTK_INT)
    lab.SetName("label")
    grid.GetCellData().AddArray(lab)
    return grid


def sample_labels(grid, P, n1, n2, rho, intima):
    """{label: (present (n, K) bool, depth (n, K, 2) mm below the lumen: [from, to] of the label's
    samples on the ray, NaN where absent)} of the label grid on K rays at 2 pi k / K of the sections
    around the stations P (n, 3) with frames n1, n2, from the lumen radius rho (n, K) through the
    intima (n, K). Labels stacked on one ray (a cap over a pool) each keep their own depth range."""
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, vtk_to_numpy

    n, K = rho.shape
    theta = 2.0 * np.pi * np.arange(K) / K
    e = np.cos(theta)[None, :, None] * n1[:, None, :] + np.sin(theta)[None, :, None] * n2[:, None, :]
    frac = (np.arange(DEPTHS) + 0.5) / DEPTHS
    depth = intima[..., None] * frac  # (n, K, J)
    X = P[:, None, None, :] + (rho[..., None] + depth)[..., None] * e[:, :, None, :]
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(X.reshape(-1, 3)), deep=True))
    probe_at = vtk.vtkPolyData()
    probe_at.SetPoints(pts)
    probe = vtk.vtkProbeFilter()
    probe.SetInputData(probe_at)
    probe.SetSourceData(grid)
    probe.Update()
    out = probe.GetOutput().GetPointData()
    valid = vtk_to_numpy(out.GetArray(probe.GetValidPointMaskArrayName())).astype(bool)
    got = np.where(valid, vtk_to_numpy(out.GetArray("label")), 0).reshape(n, K, DEPTHS)
    half = 0.5 * intima / DEPTHS
    out = {}
    for lab in np.unique(got[got > 0]):
        on = got == lab
        hit = on.any(axis=2)
        first = np.argmax(on, axis=2)
        last = DEPTHS - 1 - np.argmax(on[..., ::-1], axis=2)
        take = lambda j: np.take_along_axis(depth, j[..., None], axis=2)[..., 0]  # noqa: E731
        span = np.stack([np.maximum(take(first) - half, 0.0), take(last) + half], axis=-1)
        span[~hit] = np.nan
        out[int(lab)] = (hit, span)
    return out


def regions_from_mesh(spec, cl, r_lumen, intima, where):
    """patient.plaque entries of the checked patient.plaque_mesh `spec` (file resolved) around the
    centerline cl: the lumen radius r_lumen and the intima's thickness per station, (n,) or (n, K)."""
    from .artery_mesh import section_frames
    from .lumen_sections import ANGLES
    from .plaque_labels import check_types, regions_from_labels

    check_types(spec["types"], where)
    grid = read_label_mesh(spec["file"], spec["array"], spec["units"])

    def rays(a):
        a = np.asarray(a, dtype=float)
        return a if a.ndim == 2 else np.repeat(a[:, None], ANGLES, 1)

    rho, ti = rays(r_lumen), rays(intima)
    if rho.shape[1] != ANGLES:
        raise ValueError(f"{rho.shape[1]} rays, expected {ANGLES}")
    _, n1, n2 = section_frames(cl.points)
    found = sample_labels(grid, cl.points, n1, n2, rho, ti)
    regions = [
        e
        for lab, (hit, depth) in sorted(found.items())
        for e in regions_from_labels(hit * lab, cl.arc_length, spec["types"], None, where, depth=depth, intima=ti)
    ]
    return unstack(regions)


def unstack(regions):
    """Regions stacked over one another (a cap over a pool) share their boundary on every ray, but
    each region's depth range bounds all its rays, so the bounds of two stacked regions overlap by the
    sampling's jitter: such a pair is split at the middle of the overlap (the upper one ends, the
    lower one starts there). Regions whose ranges overlap by more than half the thinner are left for
    read_plaque to refuse as overlapping."""
    from .plaque import arcs_overlap

    def lo(e):
        return e.get("offset", 0.0)

    def hi(e):
        return lo(e) + e["thickness"] if "thickness" in e else np.inf

    for a in regions:
        for b in regions:
            if a is b or lo(a) > lo(b) or not (a["from_s"] < b["to_s"] and b["from_s"] < a["to_s"]):
                continue
            if not arcs_overlap(tuple(a["angle"]), tuple(b["angle"])) or hi(a) <= lo(b):
                continue
            overlap = hi(a) - lo(b)
            if overlap > 0.5 * min(hi(a) - lo(a), hi(b) - lo(b)):
                continue
            cut = lo(b) + 0.5 * overlap  # a: [lo(a), cut], b: [cut, hi(b)]
            a["thickness"] = cut - lo(a)
            if "thickness" in b:
                b["thickness"] = hi(b) - cut
            b["offset"] = cut
    return regions
