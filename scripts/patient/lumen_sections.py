"""The true cross-sections of a lumen surface (lumen_surface.py) at the stations of the artery's loft:
the surface cut by the normal plane of the centerline at a station, as the polar radius rho(theta) of
the cut around the station point, sampled at ANGLES equally spaced angles from the frame's first normal
(the rotation-minimizing normal of artery_mesh.py, so successive sections start at corresponding
points and the loft does not twist). A wall-thickness field given on the surface's vertices (a point
data array), the distance to an outer-wall surface, and plaque labels are sampled on the same rays.
Units: mm.

Each wall interface is then the lumen section moved outward along the same rays (artery_mesh.py):
interfaces of a star-shaped section moved radially never cross each other, whatever the thickness,
which is what makes the layered wall robust on eccentric and elliptic lumens. The thickness so
measured is radial, not normal to the lumen; for an ellipse of aspect ratio 1.5 the two differ by at
most 8 % (the angle between radius and normal reaches atan((a^2 - b^2) / 2ab) = 22.6 deg). A
section that is not star-shaped around its station point (a ray leaving the lumen twice: a kink, a
fold, a bifurcation remnant) is refused."""
import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from .errors import PatientInputError

ANGLES = 48  # samples per section: 7.5 degrees apart, below the artery mesh's element size around
# The loft's splines go through fewer points: OpenCASCADE's work on the lofted spline surfaces grows
# with their poles. Measured on an elliptic tube, mesh size 0.8 mm, 4.3k tet10, beside a run, with
# gmsh's own second-order pass (projections onto the lofts, since replaced by second_order.py):
# 176 s with 48 points, 31 s with 16 (circles: 7 s); the fragment's share not measured apart.
SPLINE_POINTS = 16


def low_pass(samples, points=SPLINE_POINTS):
    """Periodic samples (..., ANGLES) reduced to `points` equally spaced ones (the first at angle 0)
    through their Fourier series truncated below points / 2 harmonics: no aliasing of the facets'
    jitter into the spline."""
    x = np.asarray(samples, dtype=float)
    n = x.shape[-1]
    if n % points:
        raise ValueError(f"{n} samples do not reduce to {points}")
    c = np.fft.rfft(x, axis=-1)
    c[..., (points - 1) // 2 + 1 :] = 0.0
    return np.fft.irfft(c, n=n, axis=-1)[..., :: n // points]


def level_cut(X, T, values, c):
    """Where the piecewise-linear `values` (per vertex of the triangles T over the points X) cross c:
    one segment per cut triangle, as (end points (m, 2, 3), the mesh edges they lie on (m, 2, 2 vertex
    ids), their positions along those edges (m, 2), the triangles (m,), the loop of each segment (m,):
    connected components through the mesh edges the segments share), or None where nothing crosses.
    The plane cuts of the sections and the level sets of lumen_centerline.py."""
    d = values - c
    above = d[T] > 0.0
    cut = np.flatnonzero(above.any(axis=1) & ~above.all(axis=1))
    if not len(cut):
        return None
    ends, keys, edges, us = [], [], [], []
    for k in range(3):
        a, b = T[cut, k], T[cut, (k + 1) % 3]
        cross = above[cut, k] != above[cut, (k + 1) % 3]
        u = np.where(cross, d[a] / np.where(cross, d[a] - d[b], 1.0), 0.0)
        ends.append(np.where(cross[:, None], X[a] + u[:, None] * (X[b] - X[a]), np.nan))
        keys.append(np.where(cross, np.minimum(a, b) * len(X) + np.maximum(a, b), -1))
        edges.append(np.stack([a, b], -1))
        us.append(u)
    ends, keys, edges, us = np.stack(ends, 1), np.stack(keys, 1), np.stack(edges, 1), np.stack(us, 1)
    # each cut triangle crosses the level on exactly two of its edges
    order = np.argsort(keys < 0, axis=1, kind="stable")[:, :2]
    rows = np.arange(len(cut))[:, None]
    seg, key, edge, eu = ends[rows, order], keys[rows, order], edges[rows, order], us[rows, order]
    uniq, inv = np.unique(key, return_inverse=True)
    inv = inv.reshape(-1, 2)
    graph = scipy.sparse.coo_matrix((np.ones(len(inv)), (inv[:, 0], inv[:, 1])), shape=(len(uniq),) * 2)
    _, label = scipy.sparse.csgraph.connected_components(graph, directed=False)
    return seg, edge, eu, cut, label[inv[:, 0]]


def _cross2(a, b):
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


class LumenSections:
    """Sections of one lumen surface, with the wall thickness on the rays from `field` (a per-vertex
    array of the surface), or from `outer` (the LumenSections of an outer-wall surface: the thickness
    is then the distance between the two surfaces along each ray), or neither; and optionally per-vertex
    `labels` sampled on the same rays."""

    def __init__(self, surface, field=None, outer=None, labels=None):
        self.surface = surface
        self.field = None if field is None else np.asarray(field, dtype=float)
        self.outer = outer
        self.labels = None if labels is None else np.asarray(labels)  # per vertex (plaque_labels.py)

    @property
    def wall_from(self):
        """Where the wall thickness comes from: 'surface' (a point array), 'outer surface', or None."""
        return "surface" if self.field is not None else "outer surface" if self.outer is not None else None

    def _cut(self, P, t):
        """level_cut of the surface by the plane through P normal to t."""
        return level_cut(self.surface.points, self.surface.triangles, (self.surface.points - P) @ t, 0.0)

    def _rays(self, P, t, n1, n2, where, angles):
        """Where `angles` rays from P in the plane through P normal to t (theta from n1 towards n2) meet
        the lumen: (rho (K,), the mesh edges of the hit segment's ends (K, 2, 2), their positions on
        them (K, 2), the position along the segment (K,)); PatientInputError (naming `where`) when the
        plane misses the lumen around P or a ray leaves it more than once."""
        got = self._cut(P, t)
        if got is None:
            raise PatientInputError(f"{self.surface.path}: the section at {where} does not cut the lumen surface")
        seg, edge, eu, _, loop = got
        a = np.stack([(seg[:, 0] - P) @ n1, (seg[:, 0] - P) @ n2], -1)
        b = np.stack([(seg[:, 1] - P) @ n1, (seg[:, 1] - P) @ n2], -1)
        theta = 2.0 * np.pi * np.arange(angles) / angles
        e = np.stack([np.cos(theta), np.sin(theta)], -1)[:, None, :]
        dab = (b - a)[None]
        den = _cross2(e, dab)
        ok_den = np.abs(den) > 1e-300
        rho = np.where(ok_den, _cross2(a[None], dab) / np.where(ok_den, den, 1.0), np.nan)
        u = np.where(ok_den, _cross2(a[None], e) / np.where(ok_den, den, 1.0), np.nan)
        hit = ok_den & (u >= -1e-9) & (u <= 1.0 + 1e-9) & (rho > 0.0)
        # the loop around P: the one the rays hit (a plane may cut the vessel again far away)
        own = np.bincount(loop[hit.any(axis=0)], minlength=loop.max() + 1)
        if not own.any():
            raise PatientInputError(f"{self.surface.path}: the section at {where} does not enclose the centerline")
        hit &= (loop == int(np.argmax(own)))[None]
        out_rho, out_seg, out_u = np.empty(angles), np.empty(angles, dtype=int), np.empty(angles)
        for k in range(angles):
            r = rho[k, hit[k]]
            if not len(r):
                raise PatientInputError(
                    f"{self.surface.path}: the section at {where} is not star-shaped around its centerline point: the "
                    f"ray at {np.degrees(theta[k]):.0f} degrees does not meet the lumen wall (the point lies outside a "
                    "crescent- or C-shaped lumen, or the section is open)"
                )
            # hits at a vertex shared by two segments count once
            distinct = np.unique(np.round(r / max(r.min(), 1e-12), 6))
            if len(distinct) > 1:
                raise PatientInputError(
                    f"{self.surface.path}: the section at {where} is not star-shaped around its centerline point: the "
                    f"ray at {np.degrees(theta[k]):.0f} degrees leaves the lumen {len(distinct)} times (a kink or a "
                    "fold of the surface; smooth it or cut the vessel shorter)"
                )
            j = int(np.argmin(r))
            out_seg[k] = np.flatnonzero(hit[k])[j]
            out_rho[k] = r[j]
            out_u[k] = min(max(u[k, out_seg[k]], 0.0), 1.0)
        return out_rho, edge[out_seg], eu[out_seg], out_u

    def polar(self, P, t, n1, n2, where, angles=ANGLES):
        """(rho, wall thickness or None) on `angles` rays from P (see _rays)."""
        return self.sample(P, t, n1, n2, where, angles)[:2]

    def sample(self, P, t, n1, n2, where, angles=ANGLES):
        """(rho, wall thickness or None, labels or None) on `angles` rays from P (see _rays): the
        labels are those of the surface vertex nearest each hit."""
        rho, edge, eu, u = self._rays(P, t, n1, n2, where, angles)
        label = None
        if self.labels is not None:
            end = np.where(u < 0.5, 0, 1)
            rows = np.arange(len(u))
            label = self.labels[edge[rows, end, np.where(eu[rows, end] < 0.5, 0, 1)]]
        if self.outer is not None:
            outer, _ = self.outer.polar(P, t, n1, n2, where, angles)
            k = int(np.argmin(outer - rho))
            if outer[k] <= rho[k]:
                raise PatientInputError(
                    f"{self.outer.surface.path}: the outer wall at {where} lies inside the lumen of "
                    f"{self.surface.path} towards {360.0 * k / angles:.0f} degrees ({outer[k]:.3f} mm against "
                    f"{rho[k]:.3f} mm from the centerline): expected an outer surface around the lumen"
                )
            return rho, outer - rho, label
        if self.field is None:
            return rho, None, label
        f = self.field[edge]  # (K, 2 segment ends, 2 edge vertices)
        ends = f[..., 0] + eu * (f[..., 1] - f[..., 0])
        return rho, ends[:, 0] + u * (ends[:, 1] - ends[:, 0]), label


def inscribed_radius(rho):
    """The distance from the rays' origin to the nearest point of the polygon through the polar
    samples rho (<= min rho): the radius of the largest circle around the centerline point inside the
    section, what a device centered there must clear."""
    theta = 2.0 * np.pi * np.arange(len(rho)) / len(rho)
    a = np.asarray(rho)[:, None] * np.stack([np.cos(theta), np.sin(theta)], -1)
    d = np.roll(a, -1, axis=0) - a
    u = np.clip(-np.einsum("ij,ij->i", a, d) / np.maximum(np.einsum("ij,ij->i", d, d), 1e-300), 0.0, 1.0)
    return float(np.min(np.linalg.norm(a + u[:, None] * d, axis=1)))


def point_array(surface_path, surface, name, what):
    """The point-data array `name` of the surface file (`what` it holds, for messages), on the merged
    vertices of `surface`: one finite value per vertex."""
    from .surface_file import read_mesh

    mesh = read_mesh(surface_path, f"a surface with the point data array '{name}'")
    if name not in mesh.point_data:
        have = ", ".join(sorted(mesh.point_data)) or "none"
        raise PatientInputError(
            f"{surface_path}: expected a point data array '{name}' ({what}), got arrays: {have} "
            "(STL carries none: write VTP, VTK, VTU or PLY)"
        )
    values = np.asarray(mesh.point_data[name], dtype=float)
    if values.ndim == 2 and values.shape[1] == 1:
        values = values[:, 0]
    if values.ndim != 1 or not np.all(np.isfinite(values)):
        raise PatientInputError(f"{surface_path}: point data '{name}': expected one finite value per vertex")
    # the surface's merged vertices came from these points: each keeps the value of its nearest original
    from scipy.spatial import cKDTree

    _, idx = cKDTree(np.asarray(mesh.points, dtype=float)[:, :3] * surface.scale).query(surface.points)
    return values[idx]


def read_wall_field(surface_path, surface, name):
    """The wall thickness array `name` of the surface file, on the merged vertices of `surface` (mm)."""
    values = point_array(surface_path, surface, name, "the wall thickness, mm")
    if values.min() <= 0.0:
        raise PatientInputError(f"{surface_path}: point data '{name}': expected positive thicknesses (mm)")
    return values * surface.scale
