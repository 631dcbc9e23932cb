"""The centerline and lumen radius of a lumen surface (lumen_surface.py), without a centerline file.

A harmonic field u on the surface, u = 0 on one cut end and 1 on the other (cotangent Laplacian,
Pinkall & Polthier 1993, Experiment. Math. 2:15; the harmonic skeleton of tubular surfaces, e.g.
Antiga et al. 2003 for vessels), has level sets that are closed loops around the vessel, close to
its cross-sections. Each level set gives a station: the centroid of the loop (a point of the
centerline) and the area it encloses A (the norm of 1/2 sum p x q over its segments), i.e. the
equivalent lumen radius sqrt(A/pi) that the centerline CSV carries. The stations are resampled at a
uniform arc-length spacing. A level set of more than one loop (a handle, a surface that folds back)
is refused: the pipeline builds one vessel (side branches, which add boundary loops, are refused
when the surface is read). Units: mm."""
import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from .centerline_csv import arc_length
from .errors import PatientInputError
from .lumen_sections import level_cut


def cotangent_laplacian(points, triangles):
    """Symmetric positive semi-definite L with L_ij = -1/2 (cot alpha + cot beta) over the edge (i, j)."""
    n = len(points)
    rows, cols, vals = [], [], []
    for k in range(3):
        i, j, o = triangles[:, (k + 1) % 3], triangles[:, (k + 2) % 3], triangles[:, k]
        a, b = points[i] - points[o], points[j] - points[o]
        cot = np.einsum("ij,ij->i", a, b) / np.maximum(np.linalg.norm(np.cross(a, b), axis=1), 1e-300)
        w = 0.5 * cot
        rows += [i, j, i, j]
        cols += [j, i, i, j]
        vals += [-w, -w, w, w]
    return scipy.sparse.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    ).tocsr()


def harmonic_field(surface):
    """u on every vertex: 0 on the first boundary loop, 1 on the second, harmonic in between."""
    L = cotangent_laplacian(surface.points, surface.triangles)
    n = len(surface.points)
    u = np.full(n, np.nan)
    u[surface.loops[0]] = 0.0
    u[surface.loops[1]] = 1.0
    fixed = ~np.isnan(u)
    free = np.flatnonzero(~fixed)
    A = L[free][:, free]
    b = -L[free][:, np.flatnonzero(fixed)] @ u[fixed]
    u[free] = scipy.sparse.linalg.spsolve(A.tocsc(), b)
    if not np.all(np.isfinite(u)):
        raise PatientInputError(
            f"{surface.path}: the harmonic field of the surface is not finite (degenerate triangles?)"
        )
    return u


def iso_directions(surface, u):
    """Per triangle n x grad u: the direction in which a level-set segment runs with u growing to its left
    (n the triangle's outward normal; grad u of the linear interpolant, sum_a u_a n x e_a / (2 area))."""
    x = surface.points[surface.triangles]
    n = np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0])
    n2 = np.maximum(np.einsum("ij,ij->i", n, n), 1e-300)
    ut = u[surface.triangles]
    g = sum(ut[:, a, None] * np.cross(n, x[:, (a + 2) % 3] - x[:, (a + 1) % 3]) for a in range(3)) / n2[:, None]
    return np.cross(n, g)


def level_section(surface, u, c, iso):
    """(centroid, area vector, number of loops) of the level set u = c; iso from iso_directions."""
    got = level_cut(surface.points, surface.triangles, u, c)
    if got is None:
        return None, None, 0
    seg, _, _, tri, loop = got
    # orient each segment so that u grows to its left on the triangle's outward side: then all segments
    # of a loop run the same way round and 1/2 sum p x q is the area vector of the section
    flip = np.einsum("ij,ij->i", seg[:, 1] - seg[:, 0], iso[tri]) < 0
    p = np.where(flip[:, None], seg[:, 1], seg[:, 0])
    q = np.where(flip[:, None], seg[:, 0], seg[:, 1])
    area = 0.5 * np.cross(p, q).sum(axis=0)
    length = np.linalg.norm(q - p, axis=1)
    centroid = (0.5 * (p + q) * length[:, None]).sum(axis=0) / max(length.sum(), 1e-300)
    return centroid, area, len(np.unique(loop))


def lumen_centerline(surface, spacing=0.2, levels=400):
    """(points (n, 3), radius (n,)) at a uniform arc-length spacing (mm) from the first cut end to the second."""
    u = harmonic_field(surface)
    iso = iso_directions(surface, u)
    stations, radii = [], []
    for c in (np.arange(levels) + 0.5) / levels:
        centroid, area, loops = level_section(surface, u, c, iso)
        if loops != 1:
            raise PatientInputError(
                f"{surface.path}: the section at fraction {c:.3f} of the vessel has {loops} loops, expected one "
                "(a handle or a fold of the surface)"
            )
        stations.append(centroid)
        radii.append(np.sqrt(np.linalg.norm(area) / np.pi))
    stations, radii = np.array(stations), np.array(radii)
    s = arc_length(stations)
    if not np.all(np.diff(s) > 0):
        raise PatientInputError(f"{surface.path}: two sections share a centroid: a degenerate surface")
    n = max(int(np.ceil(s[-1] / spacing)), 2)
    t = np.linspace(0.0, s[-1], n + 1)
    pts = np.column_stack([np.interp(t, s, stations[:, k]) for k in range(3)])
    return pts, np.interp(t, s, radii)
