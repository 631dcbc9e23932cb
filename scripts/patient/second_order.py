"""Quadratic elements (tet10 / tri6 / line3) on the CAD geometry of the current gmsh model, fast.

gmsh's own `setOrder(2)` places each mid-edge node of a curved boundary by OpenCASCADE projections
(`OCCFace::closestPoint` → `GeomAPI_ProjectPointOnSurf`, which samples a grid of the B-spline surface
for every call): on the lofted walls of an artery from a segmented lumen surface that took 630 s of
705 at 0.8 mm (profiled with perf; docs/performance.md). Here the quadratic mesh is built from the
linear one through gmsh's API: a mid-edge node on a curve or surface starts at the parametric
midpoint of its edge's ends and is moved by a few Gauss–Newton steps to the geometry's closest point
to the chord's midpoint (a handful of B-spline evaluations per node); interior mid-edge nodes sit at
the chord's midpoint. Every node on a curve or surface keeps its parametric coordinates, so that
gmsh's high-order optimizer reads them instead of projecting again. Units: those of the model (mm).
"""

import gmsh
import numpy as np

# gmsh linear type -> (quadratic type, corners, (corner a, corner b) per mid node in gmsh's order)
_QUADRATIC = {
    1: (8, 2, ((0, 1),)),  # line -> line3
    2: (9, 3, ((0, 1), (1, 2), (2, 0))),  # triangle -> tri6
    4: (11, 4, ((0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1))),  # tet -> tet10
}


def _project(dim, tag, par, target, iterations=4):
    """Gauss-Newton from the parametric midpoints `par` (n x dim) toward the closest points of the
    curve or surface to `target` (n x 3, the chords' midpoints): J^T J dp = -J^T (x(p) - target), J the
    parametrization's derivative. A lofted B-spline's parameter is not proportional to arc length, so
    the parametric midpoint alone can sit well along the surface from the chord's middle.
    Returns (par, x(par))."""
    for _ in range(iterations):
        x = np.reshape(gmsh.model.getValue(dim, tag, np.ravel(par)), (-1, 3))
        J = np.reshape(gmsh.model.getDerivative(dim, tag, np.ravel(par)), (-1, dim, 3))  # rows: dx/dp_k
        JJ = np.einsum("nki,nli->nkl", J, J) + 1e-14 * np.eye(dim)
        g = np.einsum("nki,ni->nk", J, x - target)
        par = par - np.linalg.solve(JJ, g[..., None])[..., 0]
    return par, np.reshape(gmsh.model.getValue(dim, tag, np.ravel(par)), (-1, 3))


def _place(dim, tag, par_of, edges, chord):
    """Mid-edge nodes of `edges` on the curve or surface: (parametric coordinates n x dim, points n x 3),
    projected from the parametric midpoints of the edges. On a periodic parametrization an edge across
    the seam has ends a period apart; where one end moved by a period gives another midpoint, both are
    projected and the point nearer the chord's midpoint is kept (a non-periodic parameter spanned by
    one edge keeps its plain midpoint)."""
    pa = np.array([par_of[a] for a, _ in edges])
    pb = np.array([par_of[b] for _, b in edges])
    lo, hi = (np.asarray(v, dtype=float) for v in gmsh.model.getParametrizationBounds(dim, tag))
    period = hi - lo
    par, x = _project(dim, tag, 0.5 * (pa + pb), chord)
    across = 0.5 * (pa + np.where(np.abs(pa - pb) > 0.5 * period, pb + np.sign(pa - pb) * period, pb))
    moved = np.flatnonzero(np.any(across != 0.5 * (pa + pb), axis=1))
    if len(moved):
        par_m, x_m = _project(dim, tag, across[moved], chord[moved])
        better = np.linalg.norm(x_m - chord[moved], axis=1) < np.linalg.norm(x[moved] - chord[moved], axis=1)
        par[moved[better]], x[moved[better]] = par_m[better], x_m[better]
    return par, x


def set_order_two():
    """Replaces the current linear mesh (points, lines, triangles, tetrahedra) by the quadratic one,
    with the mid-edge nodes of curves and surfaces on them. Returns (on the geometry, left at the
    chord's midpoint because the closest point lay farther than a quarter of the edge from it: a
    parametrization that folds there)."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    X = dict(zip(tags.tolist(), np.reshape(coords, (-1, 3))))
    next_tag = int(tags.max()) + 1
    nodes = {}  # (dim, tag) -> [node tags], [params]
    for dim, tag in gmsh.model.getEntities():
        n, _, p = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=False, returnParametricCoord=dim in (1, 2))
        nodes[(dim, tag)] = (n.tolist(), list(np.reshape(p, (-1, dim))) if dim in (1, 2) and len(p) else [])
    elements = {}  # (dim, tag) -> [(linear type, element tags, connectivity rows)]
    for dim, tag in gmsh.model.getEntities():
        types, etags, enodes = gmsh.model.mesh.getElements(dim, tag)
        elements[(dim, tag)] = [
            (int(t), list(et), np.reshape(en, (len(et), -1)).astype(np.int64))
            for t, et, en in zip(types, etags, enodes)
        ]
    mid_of = {}  # sorted corner pair -> mid node tag
    placed = straight = 0
    # curves first, then surfaces, then volumes: an edge takes the lowest-dimensional entity it lies on
    for dim in (1, 2, 3):
        for _, tag in gmsh.model.getEntities(dim):
            new = []  # (corner a, corner b) of edges first met on this entity
            for etype, _, rows in elements[(dim, tag)]:
                if etype not in _QUADRATIC:
                    raise RuntimeError(f"second order: element type {etype} on entity ({dim}, {tag})")
                for row in rows:
                    for a, b in _QUADRATIC[etype][2]:
                        key = (min(row[a], row[b]), max(row[a], row[b]))
                        if key not in mid_of:
                            mid_of[key] = next_tag
                            next_tag += 1
                            new.append(key)
            if not new:
                continue
            chord = np.array([0.5 * (X[a] + X[b]) for a, b in new])
            mids = [mid_of[k] for k in new]
            par = []
            n, p = [], []
            if dim < 3:
                n, _, p = gmsh.model.mesh.getNodes(dim, tag, includeBoundary=True, returnParametricCoord=True)
            if dim < 3 and len(n) and len(p) == dim * len(n):  # a parametrized curve or surface
                par_of = dict(zip(n.tolist(), np.reshape(p, (-1, dim))))
                pm, x = _place(dim, tag, par_of, new, chord)
                length = np.array([np.linalg.norm(X[b] - X[a]) for a, b in new])
                near = np.linalg.norm(x - chord, axis=1) < 0.25 * length
                # a node left at the chord's midpoint keeps its parametric coordinates, which map to
                # the point found (none met in the meshes measured: docs/performance.md)
                x = np.where(near[:, None], x, chord)
                placed += int(near.sum())
                straight += int((~near).sum())
                par = list(pm)
            else:
                x = chord
            for t, xm in zip(mids, x):
                X[t] = xm
            old_n, old_p = nodes[(dim, tag)]
            if old_n and len(old_p) != len(old_n):  # corners without parametric coordinates: none for any
                par = []
            nodes[(dim, tag)] = (old_n + mids, old_p + par)
    gmsh.model.mesh.clear()
    for (dim, tag), (n, p) in sorted(nodes.items()):
        if n:
            gmsh.model.mesh.addNodes(dim, tag, n, np.ravel([X[t] for t in n]).tolist(), np.ravel(p).tolist())
    for (dim, tag), blocks in sorted(elements.items()):
        for etype, etags, rows in blocks:
            if etype not in _QUADRATIC:  # points: as they were
                gmsh.model.mesh.addElementsByType(tag, etype, etags, np.ravel(rows).tolist())
                continue
            qtype, nc, edges = _QUADRATIC[etype]
            conn = [
                list(row[:nc]) + [mid_of[(min(row[a], row[b]), max(row[a], row[b]))] for a, b in edges] for row in rows
            ]
            gmsh.model.mesh.addElementsByType(tag, qtype, etags, np.ravel(conn).tolist())
    return placed, straight
