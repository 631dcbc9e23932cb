#!/usr/bin/env python3
"""Quadratic elements on the CAD geometry (scripts/patient/second_order.py).

Analytic: on a cylinder (a periodic surface whose seam the mesh crosses) every node of the lateral
surface and of the end circles lies on the geometry, and each mid-edge node is the closest point of
the cylinder to its chord's midpoint (on the radial line through it). Reference implementation: on a
lofted B-spline tube of unevenly spaced, elliptic sections (parameter not proportional to arc
length) the mid-edge nodes lie on the surface and agree with gmsh's own setOrder(2), which places
each between its edge's ends by OpenCASCADE projections, within 1 % of the edge's length: gmsh takes
the point of the surface equidistant from the two ends, this the surface's closest point to the
chord's midpoint; both are on the surface, and their difference along it (third order in the edge
length) is what the element's shape sees.
"""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "scripts"))

import gmsh  # noqa: E402

from patient import second_order  # noqa: E402


def mid_nodes(dim, tag):
    """(mid node tags, their coordinates, their chords' midpoints, their edges' lengths) of the tri6 /
    line3 on an entity."""
    etype, width, edges = (9, 6, ((0, 1, 3), (1, 2, 4), (2, 0, 5))) if dim == 2 else (8, 3, ((0, 1, 2),))
    tags, coords, _ = gmsh.model.mesh.getNodes()
    at = dict(zip(tags.tolist(), np.reshape(coords, (-1, 3))))
    _, nodes = gmsh.model.mesh.getElementsByType(etype, tag)
    rows = np.reshape(nodes, (-1, width)).astype(int)
    out = {}
    for a, b, m in edges:
        for r in rows:
            xa, xb = at[int(r[a])], at[int(r[b])]
            out[int(r[m])] = (at[int(r[m])], 0.5 * (xa + xb), np.linalg.norm(xb - xa))
    mids = sorted(out)
    return mids, *(np.array([out[n][k] for n in mids]) for k in range(3))


class Cylinder(unittest.TestCase):
    def setUp(self):
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addCylinder(0, 0, 0, 0, 0, 3, 1.0)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
        gmsh.model.mesh.generate(3)

    def tearDown(self):
        gmsh.finalize()

    def test_mid_nodes_are_the_closest_points_of_the_cylinder(self):
        tets = len(gmsh.model.mesh.getElementsByType(4)[0])
        moved, straight = second_order.set_order_two()
        self.assertGreater(moved, 100)
        self.assertEqual(straight, 0)  # the seam's edges too (periodic parametrization)
        self.assertEqual(len(gmsh.model.mesh.getElementsByType(11)[0]), tets)  # every tet now a tet10
        self.assertEqual(len(gmsh.model.mesh.getElementsByType(4)[0]), 0)
        # every node of a curve or surface carries its parametric coordinates (gmsh's optimizer reads them)
        for dim in (1, 2):
            for _, t in gmsh.model.getEntities(dim):
                n, _, p = gmsh.model.mesh.getNodes(dim, t, includeBoundary=False, returnParametricCoord=True)
                self.assertEqual(len(p), dim * len(n))
        lateral = [t for _, t in gmsh.model.getEntities(2) if gmsh.model.getType(2, t) == "Cylinder"]
        self.assertEqual(len(lateral), 1)
        _, x, chord, _ = mid_nodes(2, lateral[0])
        r = np.hypot(x[:, 0], x[:, 1])
        np.testing.assert_allclose(r, 1.0, atol=1e-12)
        # closest point of the cylinder to the chord's midpoint: same height, same direction from the axis
        np.testing.assert_allclose(x[:, 2], chord[:, 2], atol=1e-9)
        np.testing.assert_allclose(x[:, :2], chord[:, :2] / np.hypot(chord[:, 0], chord[:, 1])[:, None], atol=1e-9)
        for _, c in gmsh.model.getEntities(1):
            if gmsh.model.getType(1, c) == "Circle":
                _, x, _, _ = mid_nodes(1, c)
                np.testing.assert_allclose(np.hypot(x[:, 0], x[:, 1]), 1.0, atol=1e-12)


class LoftedTube(unittest.TestCase):
    """A tube lofted through elliptic sections spaced 0.3 to 2 mm apart: the B-spline's parameter
    runs unevenly along it."""

    def build(self):
        gmsh.initialize()
        gmsh.option.setNumber("General.Terminal", 0)
        occ = gmsh.model.occ
        wires = []
        for z, a in ((0.0, 1.0), (0.3, 1.05), (2.3, 0.8), (2.6, 0.85), (4.0, 1.0)):
            wires.append(occ.addCurveLoop([occ.addEllipse(0, 0, z, a, 0.7)]))
        occ.addThruSections(wires, makeSolid=True, makeRuled=False)
        occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
        gmsh.model.mesh.generate(3)

    def mids_of_surfaces(self):
        """{chord midpoint: (mid node coordinates, chord midpoint, edge length, distance to its surface's
        closest point by OpenCASCADE)}, keyed by the chord (node tags differ between the two routes)"""
        out = {}
        for _, s in gmsh.model.getEntities(2):
            if gmsh.model.getType(2, s) == "BSpline surface":
                _, x, chord, length = mid_nodes(2, s)
                on = np.reshape(gmsh.model.getClosestPoint(2, s, np.ravel(x))[0], (-1, 3))
                for xm, cm, ln, gap in zip(x, chord, length, np.linalg.norm(on - x, axis=1)):
                    out[tuple(np.round(cm, 9))] = (xm, cm, ln, gap)
        return out

    def test_agrees_with_gmsh_projection(self):
        self.build()
        gmsh.model.mesh.setOrder(2)
        reference = self.mids_of_surfaces()
        gmsh.finalize()
        self.build()
        moved, straight = second_order.set_order_two()
        ours = self.mids_of_surfaces()
        gmsh.finalize()
        self.assertEqual(straight, 0)
        self.assertEqual(len(ours), len(reference))
        # the same linear mesh, mid nodes placed by different projections
        # on the surface as far as OpenCASCADE's projection (getClosestPoint) resolves a point it did not place
        self.assertLess(max(v[3] for v in ours.values()), 1e-5)
        d = np.array([np.linalg.norm(ours[n][0] - reference[n][0]) for n in reference])
        edge = np.array([reference[n][2] for n in reference])
        curving = np.array([np.linalg.norm(ours[n][0] - ours[n][1]) for n in reference])
        self.assertGreater(curving.max(), 0.01)  # the surface is curved at this mesh size (mm)
        worst = int(np.argmax(d / edge))
        self.assertLess(d[worst], 0.01 * edge[worst], f"{d[worst]:.3g} mm apart on an edge of {edge[worst]:.3g} mm")


if __name__ == "__main__":
    unittest.main()
