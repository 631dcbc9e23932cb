"""Reading a segmented lumen surface (STL, VTP, OBJ, PLY, VTK, VTU, ...: surface_file.read_mesh), in
mm, open at both ends, as a checked triangle mesh: duplicate vertices merged (STL stores every facet's corners),
every edge shared by at most two triangles, consistently oriented, exactly two boundary loops (the
vessel's cut ends). A surface in metres (SimVascular's and some VMTK exports) is recognised by its
size and refused unless `units: m` converts it. Every refusal is a PatientInputError naming the file
and what was expected. Units: mm."""
import collections
import os
from dataclasses import dataclass

import numpy as np

from .errors import PatientInputError
from .surface_file import read_mesh

MAX_BYTES = 512 * 2**20  # a segmented coronary lumen is a few MB; refuse anything that cannot be one
UNITS = {"mm": 1.0, "m": 1000.0, "cm": 10.0}
# A coronary lumen surface in mm spans tens of mm; below this extent it is taken for metres.
MIN_EXTENT_MM = 2.0
MAX_EXTENT_MM = 1000.0


@dataclass
class LumenSurface:
    path: str
    points: np.ndarray  # (n, 3) mm
    triangles: np.ndarray  # (m, 3) vertex ids, consistently oriented
    loops: list  # two arrays of vertex ids, each a boundary loop in order
    scale: float = 1.0  # mm per unit of the file


def read_lumen_surface(path, units="mm"):
    """The checked surface, or PatientInputError naming the file and the problem."""
    if units not in UNITS:
        raise PatientInputError(f"{path}: units: expected one of {', '.join(UNITS)}, got {units!r}")
    if os.path.isfile(path) and os.path.getsize(path) > MAX_BYTES:
        raise PatientInputError(f"{path}: {os.path.getsize(path)} bytes, expected a lumen surface below {MAX_BYTES}")
    mesh = read_mesh(path, "a lumen surface: STL, VTP, OBJ, PLY, VTK, VTU")
    tris = [c.data for c in mesh.cells if c.type == "triangle"]
    if not tris:
        kinds = ", ".join(sorted({c.type for c in mesh.cells})) or "none"
        raise PatientInputError(f"{path}: expected a triangulated surface, got cells of type {kinds}")
    points = np.asarray(mesh.points, dtype=float)[:, :3] * UNITS[units]
    if not np.all(np.isfinite(points)):
        raise PatientInputError(f"{path}: expected finite coordinates, got NaN or Inf")
    points, triangles = merge_vertices(points, np.concatenate(tris).astype(np.int64))
    extent = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
    if extent < MIN_EXTENT_MM:
        raise PatientInputError(
            f"{path}: the surface spans {extent:.4g} mm, expected a lumen of a few to tens of mm: is it in metres? "
            "(give units: m to convert)"
        )
    if extent > MAX_EXTENT_MM:
        raise PatientInputError(f"{path}: the surface spans {extent:.4g} mm, expected a coronary lumen (mm)")
    triangles = orient(path, triangles)
    loops = boundary_loops(path, triangles)
    if len(loops) != 2:
        raise PatientInputError(
            f"{path}: expected a lumen open at both ends (2 boundary loops), got {len(loops)}"
            + (" (a closed surface: cut its ends open)" if not loops else "")
            + (" (side branches or holes: cut branches off and close holes)" if len(loops) > 2 else "")
        )
    return LumenSurface(path, points, triangles, loops, UNITS[units])


def merge_vertices(points, triangles, tol=1e-9):
    """Vertices closer than tol (relative to the extent) merged; degenerate triangles dropped."""
    scale = max(float(np.ptp(points, axis=0).max()), 1e-300)
    keys = np.round(points / (tol * scale)).astype(np.int64)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    tri = inverse.reshape(-1)[triangles]
    keep = (tri[:, 0] != tri[:, 1]) & (tri[:, 1] != tri[:, 2]) & (tri[:, 0] != tri[:, 2])
    return points[first], tri[keep]


def _edge_use(triangles):
    use = collections.defaultdict(list)
    for t, (a, b, c) in enumerate(triangles):
        for u, v in ((a, b), (b, c), (c, a)):
            use[(min(u, v), max(u, v))].append((t, u, v))
    return use


def orient(path, triangles):
    """Triangles flipped so that every shared edge is traversed in opposite directions (breadth first
    from triangle 0); refuses edges of more than two triangles and surfaces that cannot be oriented."""
    use = _edge_use(triangles)
    bad = [e for e, ts in use.items() if len(ts) > 2]
    if bad:
        raise PatientInputError(
            f"{path}: expected a manifold surface, got {len(bad)} edges shared by more than two triangles "
            f"(e.g. between vertices {bad[0][0]} and {bad[0][1]})"
        )
    tri = triangles.copy()
    neighbours = collections.defaultdict(list)
    for ts in use.values():
        if len(ts) == 2:
            neighbours[ts[0][0]].append(ts[1][0])
            neighbours[ts[1][0]].append(ts[0][0])
    seen = np.zeros(len(tri), dtype=bool)
    components = 0
    for start in range(len(tri)):
        if seen[start]:
            continue
        components += 1
        seen[start] = True
        queue = collections.deque([start])
        while queue:
            t = queue.popleft()
            edges_t = {(tri[t][i], tri[t][(i + 1) % 3]) for i in range(3)}
            for n in neighbours[t]:
                edges_n = {(tri[n][i], tri[n][(i + 1) % 3]) for i in range(3)}
                same = bool(edges_t & edges_n)  # a shared edge in the same direction: opposite orientation
                if seen[n]:
                    if same:
                        raise PatientInputError(f"{path}: expected an orientable surface (a Moebius-like strip?)")
                    continue
                if same:
                    tri[n] = tri[n][::-1]
                seen[n] = True
                queue.append(n)
    if components > 1:
        raise PatientInputError(f"{path}: expected one connected surface, got {components} pieces")
    return tri


def boundary_loops(path, triangles):
    """The boundary edges (of one triangle) chained into closed loops of vertex ids."""
    nxt = {}
    for ts in _edge_use(triangles).values():
        if len(ts) == 1:
            _, u, v = ts[0]
            if u in nxt:
                raise PatientInputError(f"{path}: expected simple boundary loops, vertex {u} starts two boundary edges")
            nxt[u] = v
    loops = []
    while nxt:
        start = next(iter(nxt))
        loop, v = [start], nxt.pop(start)
        while v != start:
            if v not in nxt:
                raise PatientInputError(f"{path}: a boundary loop does not close (at vertex {v})")
            loop.append(v)
            v = nxt.pop(v)
        loops.append(np.array(loop))
    return loops
