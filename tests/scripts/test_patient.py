#!/usr/bin/python3
"""Patient pipeline (scripts/patient/): centerline CSV checks, device placement (paper §2.4, eq. 3)
and the three-layer tet10 artery mesh (paper §4.2.1). Consistency checks against the definitions:
eq. (3) evaluated on the fitted spline, clearances recomputed from the geometry, mesh groups and
Jacobians read back through gmsh."""
import math
import os
import sys
import tempfile
import unittest
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
from patient.artery_mesh import (  # noqa: E402
    SLIVER_QUALITY,
    TET10_EDGES,
    Refinement,
    WallSpec,
    _jacobian_samples,
    _optimize_high_order,
    _shape_quality,
    build_artery,
    layer_radii,
)
from patient.centerline_csv import arc_length, read_centerline_csv, write_centerline_csv  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.placement import (  # noqa: E402
    Device,
    devices_fit,
    narrowest_under,
    nearest_on_polyline,
    place_device,  # noqa: E402
    stenosis_site,
)
from patient.deformed_placement import place_on_deformed_lumen  # noqa: E402
from patient.prepare import add_insertion, refinement_of  # noqa: E402
from patient.reproducible_mesh import build_artery_reproducibly  # noqa: E402


def arc(n=60, length=12.0, bend=20.0, r0=0.9, stenosis=0.25, noise=0.0, seed=1, wiggle=0.0):
    s = np.linspace(0.0, length, n)
    pts = np.column_stack(
        [bend * np.sin(s / bend), bend * (1 - np.cos(s / bend)), 0.2 * np.sin(s) + wiggle * np.sin(2 * np.pi * s / 2.5)]
    )
    if noise:
        pts = pts + noise * np.random.default_rng(seed).standard_normal(pts.shape)
    r = r0 * (1 - stenosis * np.exp(-(((s - 0.5 * length) / 1.5) ** 2)))
    wall = 0.7 + 0.3 * np.exp(-(((s - 0.5 * length) / 1.5) ** 2))
    return pts, r, wall


class Csv(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory(prefix=f"patient-csv-{os.getpid()}-")
        self.path = Path(self.dir.name) / "c.csv"

    def tearDown(self):
        self.dir.cleanup()

    def write(self, text):
        self.path.write_text(text)
        return str(self.path)

    def refused(self, text, *parts):
        with self.assertRaises(PatientInputError) as cm:
            read_centerline_csv(self.write(text))
        msg = str(cm.exception)
        self.assertIn(str(self.path), msg)
        for p in parts:
            self.assertIn(p, msg)
        return msg

    def test_round_trip(self):
        pts, r, wall = arc()
        write_centerline_csv(self.path, pts, r, wall, comment="test")
        cl = read_centerline_csv(str(self.path))
        np.testing.assert_allclose(cl.points, pts, atol=1e-6)
        np.testing.assert_allclose(cl.radius, r, atol=1e-6)
        np.testing.assert_allclose(cl.wall, wall, atol=1e-6)

    def test_bad_files(self):
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,1\n0,0,2,1\n", "at least 4")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,1\n0,0,1,1\n0,0,2,1\n", "repeated", ":4")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,0\n0,0,2,1\n0,0,3,1\n", "positive lumen radius", ":3")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,-1\n0,0,2,1\n0,0,3,1\n", "positive lumen radius")
        self.refused("x,y,z\n0,0,0\n", "no column 'r'")
        self.refused("x,y,z,r,radius\n", "unknown column 'radius'")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,nan\n0,0,2,1\n0,0,3,1\n", "finite")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1,abc\n0,0,2,1\n0,0,3,1\n", "expected a number")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,1\n", "expected 4 values")
        self.refused("x,y,z,r\n0,0,0,1\n0,0,2,1\n0,0,1,1\n0,0,3,1\n", "reversals")
        self.refused("x,y,z,r,wall\n0,0,0,1,0.5\n0,0,1,1,0\n0,0,2,1,1\n0,0,3,1,1\n", "positive wall")
        self.refused("", "no data")
        self.path.write_bytes(b"\xff\xfe\x00binary")
        with self.assertRaises(PatientInputError):
            read_centerline_csv(str(self.path))


class Placement(unittest.TestCase):
    DEV = Device(balloon_length=8.0, balloon_radius=0.3, stent_length=6.0, stent_radius=0.4)

    def centerline(self, **kw):
        d = tempfile.mkdtemp(prefix=f"patient-pl-{os.getpid()}-")
        pts, r, wall = arc(**kw)
        p = Path(d) / "c.csv"
        write_centerline_csv(p, pts, r, wall)
        return read_centerline_csv(str(p))

    def test_eq3_holds_on_a_rough_centerline(self):
        # a 0.5 mm wiggle of 2.5 mm wavelength: the least-squares cubic leaves more than zeta, so
        # FITPACK adds knots until eq. (3) holds as an equality within eps_zeta = 1e-3
        cl = self.centerline(n=100, wiggle=0.5, stenosis=0.0, r0=1.6)
        s_site = stenosis_site(cl, 6.0)
        plc = place_device(cl, self.DEV, s_site, zeta=4.0)
        z = plc.spline[2]  # the wiggle is in z; x and y are fitted by the cubic
        self.assertTrue(z["eq3_equality"], z)
        self.assertLess(abs(z["residual"] - 4.0), 1e-3 * 4.0)
        self.assertGreater(z["interior_knots"], 0)

    def test_smooth_centerline_gives_the_least_squares_cubic(self):
        cl = self.centerline(noise=0.0)
        plc = place_device(cl, self.DEV, stenosis_site(cl))
        for sp in plc.spline:
            self.assertEqual(sp["interior_knots"], 0)
            self.assertLess(sp["residual"], 4.0)

    def test_site_and_clearance(self):
        cl = self.centerline(noise=0.01, seed=3)
        s_site = stenosis_site(cl)
        self.assertAlmostEqual(s_site, cl.arc_length[np.argmin(cl.radius)])
        plc = place_device(cl, self.DEV, s_site, margin=0.02)
        # recompute the clearance of the written device centerline against the lumen tube
        sig = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(plc.points, axis=0), axis=1))])
        inside = (sig >= plc.balloon_start) & (sig <= plc.balloon_start + self.DEV.balloon_length)
        d, r = nearest_on_polyline(cl.points, cl.radius, plc.points[inside])
        self.assertGreaterEqual((r - d - self.DEV.balloon_radius).min(), 0.02 - 1e-3)
        # and the stent over its own span (recomputed, not place_device's own figure)
        st = (sig >= plc.stent_start) & (sig <= plc.stent_start + self.DEV.stent_length)
        d, r = nearest_on_polyline(cl.points, cl.radius, plc.points[st])
        self.assertGreaterEqual((r - d - self.DEV.stent_radius).min(), 0.02 - 1e-3)
        # devices centred on the site: the device centerline passes the site's normal plane at sigma_site
        self.assertAlmostEqual(plc.stent_start + 0.5 * self.DEV.stent_length, plc.sigma_site)
        self.assertAlmostEqual(plc.balloon_start + 0.5 * self.DEV.balloon_length, plc.sigma_site)
        q = np.array([np.interp(plc.sigma_site, sig, plc.points[:, c]) for c in range(3)])
        self.assertLess(np.linalg.norm(q - plc.site_point), plc.site_radius)

    def test_weights_pull_the_spline_into_a_tight_lumen(self):
        # a tight stenosis in a bend: uniform weights put the stent into the wall, adapted ones do not
        cl = self.centerline(n=80, length=12.0, bend=6.0, r0=0.75, stenosis=0.35, noise=0.005)
        dev = Device(balloon_length=8.0, balloon_radius=0.3, stent_length=6.0, stent_radius=0.45)
        plc = place_device(cl, dev, stenosis_site(cl), zeta=4.0)
        self.assertGreater(plc.weight_rounds, 0)
        self.assertGreaterEqual(plc.clearance_stent, 0.0)

    def test_refusals(self):
        cl = self.centerline()
        with self.assertRaisesRegex(PatientInputError, "reaches beyond the centerline"):
            place_device(cl, Device(20.0, 0.3, 6.0, 0.4), stenosis_site(cl))
        with self.assertRaisesRegex(PatientInputError, "does not fit in the lumen"):
            place_device(cl, Device(8.0, 0.3, 6.0, 0.8), stenosis_site(cl))
        with self.assertRaisesRegex(PatientInputError, "longer than the balloon"):
            place_device(cl, Device(8.0, 0.3, 9.0, 0.4), stenosis_site(cl))
        with self.assertRaisesRegex(PatientInputError, "within the centerline"):
            stenosis_site(cl, 100.0)


class Insertion(unittest.TestCase):
    """A lesion narrower than the crimped devices: placed all the same with the
    axis kept inside the lumen, and the scene completed with the virtual insertion tool."""

    DEV = Device(balloon_length=8.0, balloon_radius=0.49, stent_length=6.0, stent_radius=0.635)

    def placement(self):
        cl = Placement.centerline(self, r0=0.8, stenosis=0.45, noise=0.005)  # lumen 0.88 mm at the site
        s_site = stenosis_site(cl)
        self.assertFalse(devices_fit(cl, self.DEV, s_site))
        return cl, place_device(cl, self.DEV, s_site, insertion=True)

    def test_axis_inside_the_lumen(self):
        cl, plc = self.placement()
        self.assertTrue(plc.insertion)
        self.assertLess(plc.clearance_stent, 0.0)  # the crimped stent overlaps the wall
        # the axis clearance recomputed from the written centerline over the balloon
        sig = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(plc.points, axis=0), axis=1))])
        on = (sig >= plc.balloon_start) & (sig <= plc.balloon_start + self.DEV.balloon_length)
        d, r = nearest_on_polyline(cl.points, cl.radius, plc.points[on])
        narrowest = narrowest_under(cl, self.DEV, stenosis_site(cl))["balloon"]
        self.assertGreaterEqual((r - d).min(), 0.5 * narrowest - 1e-3)
        self.assertAlmostEqual(plc.axis_clearance, (r - d).min(), delta=2e-3)
        with self.assertRaisesRegex(PatientInputError, "patient.insertion.mode: auto"):
            place_device(cl, self.DEV, stenosis_site(cl))

    def scene(self):
        return {
            "time": {"start": -0.2, "end": 2.0, "steps": 110},
            "load_curves": {"balloon": [[-0.2, 0.0], [0.0, 0.0], [1.0, 1.317], [2.0, 0.0]]},
            "balloon": {"pressure": {"value": 1.0, "curve": "balloon"}},
            "contact": {
                "stent_balloon": {"penalty": 10.0},
                "stent_artery": {"penalty": 10.0},
                "balloon_artery": {"penalty": 50.0},
            },
        }

    def test_tool_opens_before_the_inflation(self):
        _, plc = self.placement()
        done = self.scene()
        rep = add_insertion(done, plc, self.DEV, {"clearance": 0.065, "penalty": 300.0}, "s.yaml")
        curve = np.array(done["load_curves"]["insertion_tool"])
        self.assertEqual(done["contact"]["insertion"]["radius"]["curve"], "insertion_tool")
        self.assertEqual(done["contact"]["insertion"]["axis"], "balloon")
        self.assertLess(curve[0, 1], plc.axis_clearance)  # starts inside the lumen
        self.assertAlmostEqual(curve[:, 1].max(), 0.635 + 0.065)  # opens to the stent + clearance
        self.assertEqual(np.interp(0.0, curve[:, 0], curve[:, 1]), 0.0)  # gone when the inflation starts
        t_open = curve[np.argmax(curve[:, 1]), 0]
        t_close = curve[curve[:, 1] == curve[:, 1].max(), 0].max()
        for key in ("stent_artery", "balloon_artery"):  # the artery contacts switch on while it is open
            self.assertTrue(t_open <= done["contact"][key]["from"] <= t_close, (key, done["contact"][key]))
            self.assertEqual(rep["contacts_from"][key], done["contact"][key]["from"])
        self.assertNotIn("from", done["contact"]["stent_balloon"])

    def test_refused_without_a_phase_before_the_inflation(self):
        _, plc = self.placement()
        done = self.scene()
        done["time"]["start"] = 0.0
        with self.assertRaisesRegex(PatientInputError, "time.start"):
            add_insertion(done, plc, self.DEV, {"clearance": 0.065, "penalty": 300.0}, "s.yaml")
        done = self.scene()
        done["load_curves"]["balloon"] = [[-0.2, 0.0], [1.0, 1.317]]
        with self.assertRaisesRegex(PatientInputError, "no balloon pressure before"):
            add_insertion(done, plc, self.DEV, {"clearance": 0.065, "penalty": 300.0}, "s.yaml")


class DeformedPlacement(unittest.TestCase):
    """A later phase's devices on the lumen the phase before left (patient/deformed_placement.py),
    from the solid summary's station centroids and diameters. Consistency: a "deformed" lumen that
    is the reference one gives the reference placement; a rigid translation of it translates the
    device centerline and keeps its starts."""

    DEV = Placement.DEV

    def summary(self, cl, shift=(0.0, 0.0, 0.0)):
        stations = [float(v) for v in cl.arc_length]
        step = {
            "lumen_centroid": (cl.points + np.asarray(shift)).tolist(),
            "lumen_diameter": (2 * cl.radius).tolist(),
        }
        return {"lumen_stations": stations}, step

    def test_reference_lumen_gives_the_reference_placement(self):
        cl = Placement.centerline(self, noise=0.01, seed=3)
        s_site = stenosis_site(cl)
        ref = place_device(cl, self.DEV, s_site, insertion=True)
        with tempfile.TemporaryDirectory() as d:
            summary, step = self.summary(cl)
            plc, ext = place_on_deformed_lumen(summary, step, s_site, self.DEV, 4.0, 0.0, Path(d) / "c.txt", "s")
            np.testing.assert_allclose(plc.points, ref.points, atol=1e-9)
            self.assertAlmostEqual(plc.balloon_start, ref.balloon_start, places=9)
            self.assertAlmostEqual(plc.stent_start, ref.stent_start, places=9)
            # the balloon's extent in the reference stations: centred on the site, its length long
            self.assertAlmostEqual(0.5 * (ext[0] + ext[1]), s_site, places=9)
            self.assertAlmostEqual(ext[1] - ext[0], self.DEV.balloon_length, places=9)
            np.testing.assert_allclose(np.loadtxt(Path(d) / "c.txt"), ref.points, atol=1e-8)  # the file written

    def test_translated_lumen_translates_the_devices(self):
        cl = Placement.centerline(self, noise=0.01, seed=3)
        s_site = stenosis_site(cl)
        ref = place_device(cl, self.DEV, s_site, insertion=True)
        with tempfile.TemporaryDirectory() as d:
            summary, step = self.summary(cl, shift=(0.2, -0.1, 0.05))
            plc, _ = place_on_deformed_lumen(summary, step, s_site, self.DEV, 4.0, 0.0, Path(d) / "c.txt", "s")
        np.testing.assert_allclose(plc.points, ref.points + [0.2, -0.1, 0.05], atol=1e-9)
        self.assertAlmostEqual(plc.balloon_start, ref.balloon_start, places=9)

    def test_no_centroids_no_placement(self):
        cl = Placement.centerline(self)
        summary, step = self.summary(cl)
        del step["lumen_centroid"]  # a summary of a solver before the centroids
        self.assertIsNone(place_on_deformed_lumen(summary, step, 6.0, self.DEV, 4.0, 0.0, "/nonexistent", "s"))


class ArteryMesh(unittest.TestCase):
    def test_three_layers_tet10(self):
        import gmsh

        pts, r, wall = arc(n=30, length=6.0, r0=0.8, stenosis=0.2)
        spec = WallSpec(media_ratio=0.06, adventitia_ratio=0.065, min_intima=0.05)
        with tempfile.TemporaryDirectory(prefix=f"patient-mesh-{os.getpid()}-") as d:
            for binary in (False, True):
                out = Path(d) / f"a{int(binary)}.msh"
                info = build_artery(pts, r, wall, spec, 0.9, out, binary=binary, log=lambda m: None)
                self.assertGreater(info["elements"], 50)
                # shape quality per layer, the worst one where it is (no slivers in a plain tube)
                shape = info["min_shape_quality"]
                self.assertEqual(set(shape), {"intima", "media", "adventitia"})
                self.assertTrue(all(SLIVER_QUALITY < q <= 1.0 for q in shape.values()), shape)
                self.assertEqual(info["worst_shape"]["quality"], min(shape.values()))
                self.assertEqual(shape[info["worst_shape"]["layer"]], info["worst_shape"]["quality"])
                gmsh.initialize()
                try:
                    gmsh.option.setNumber("General.Terminal", 0)
                    gmsh.open(str(out))
                    names = {(dim, gmsh.model.getPhysicalName(dim, tag)) for dim, tag in gmsh.model.getPhysicalGroups()}
                    self.assertEqual(
                        names,
                        {
                            (3, "intima"),
                            (3, "media"),
                            (3, "adventitia"),
                            (2, "endothelium"),
                            (2, "outer"),
                            (2, "end0"),
                            (2, "end1"),
                        },
                    )
                    types = gmsh.model.mesh.getElementTypes(3)
                    self.assertEqual(list(types), [11])  # tet10 only
                    self.assertEqual(list(gmsh.model.mesh.getElementTypes(2)), [9])  # tri6 faces
                    pts_q, _ = gmsh.model.mesh.getIntegrationPoints(11, "Gauss4")
                    _, det, _ = gmsh.model.mesh.getJacobians(11, pts_q)
                    self.assertGreater(det.min(), 0.0)
                    # the endothelium lies on the lumen tube, the outer surface at r + wall
                    for name, target in (("endothelium", 0), ("outer", 3)):
                        tag = [
                            t for dim, t in gmsh.model.getPhysicalGroups(2) if gmsh.model.getPhysicalName(2, t) == name
                        ][0]
                        _, xyz = gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)
                        radii, *_ = layer_radii(r, wall, spec, "test")
                        dist, rr = nearest_on_polyline(pts, radii[:, target], xyz.reshape(-1, 3))
                        self.assertLess(np.abs(dist - rr).max(), 0.05 * rr.max(), name)
                finally:
                    gmsh.finalize()

    def test_refinement_is_local_and_keeps_the_geometry(self):
        """patient.mesh.refine: the fine size over its span, the coarse one away from it, the same
        layers (volumes within 1 % of the uniform mesh's: the geometry is the loft's, not the mesh's),
        and no node left from the size field's seed points."""
        import gmsh
        import meshio

        pts, r, wall = arc(n=60, length=12.0, r0=0.8, stenosis=0.2)
        spec = WallSpec(media_ratio=0.06, adventitia_ratio=0.065, min_intima=0.05)

        def layer_volumes(path):
            """Volume per layer of the quadratic (tet10) mesh: Gauss quadrature of det J."""
            gmsh.initialize()
            try:
                gmsh.option.setNumber("General.Terminal", 0)
                gmsh.open(str(path))
                q, w = gmsh.model.mesh.getIntegrationPoints(11, "Gauss4")
                out = {}
                for _, tag in gmsh.model.getPhysicalGroups(3):
                    v = 0.0
                    for e in gmsh.model.getEntitiesForPhysicalGroup(3, tag):
                        _, det, _ = gmsh.model.mesh.getJacobians(11, q, tag=e)
                        v += float(np.dot(det.reshape(-1, len(w)).sum(axis=0), w))
                    out[gmsh.model.getPhysicalName(3, tag)] = v
                return out
            finally:
                gmsh.finalize()

        def build(path, refine=None):
            return build_artery(pts, r, wall, spec, 0.9, path, log=lambda m: None, refine=refine)

        def mean_edge(X, t, lo, hi):
            """Mean edge length of the tets whose centroid lies over lumen arc lengths lo..hi."""
            c = X[t[:, :4]].mean(axis=1)
            s_of = arc_length(pts)[np.linalg.norm(c[:, None] - pts[None], axis=2).argmin(axis=1)]
            e = np.mean([np.linalg.norm(X[t[:, i]] - X[t[:, j]], axis=1) for i, j in TET10_EDGES], axis=0)
            return e[(s_of > lo) & (s_of < hi)].mean()

        with tempfile.TemporaryDirectory(prefix=f"patient-refine-{os.getpid()}-") as d:
            coarse, fine, intima_only = (Path(d) / f"{n}.msh" for n in ("coarse", "fine", "intima"))
            build(coarse)
            info = build(fine, Refinement(4.0, 8.0, 0.3, 1.0))
            vc, vf = layer_volumes(coarse), layer_volumes(fine)
            self.assertEqual(set(vc), set(vf))
            for name in vc:
                self.assertAlmostEqual(vf[name] / vc[name], 1.0, delta=0.01, msg=name)
            m = meshio.read(fine)
            t = np.vstack([b.data for b in m.cells if b.type.startswith("tetra")])
            self.assertEqual(len(np.unique(t)), len(m.points))  # every node in an element: the seeds are gone
            self.assertEqual(info["nodes"], len(m.points))
            mid = mean_edge(m.points, t, 5.0, 7.0)
            # a tet's mean edge is about its size (within the mesher's spread, 30 %)
            self.assertLess(mid, 1.3 * 0.3, "the span is meshed at the fine size")
            for lo, hi in ((0.0, 1.0), (11.0, 12.0)):
                self.assertGreater(
                    mean_edge(m.points, t, lo, hi), 1.5 * mid, "away from the span the mesh stays coarse"
                )

            # the fine size in the intima only: the adventitia over the span stays coarser
            build(intima_only, Refinement(4.0, 8.0, 0.3, 1.0, layers=("intima",)))
            m = meshio.read(intima_only)
            name_of = {int(v[0]): k for k, v in m.field_data.items() if int(v[1]) == 3}
            per_layer = {}
            for block, tags in zip(m.cells, m.cell_data["gmsh:physical"]):
                if block.type.startswith("tetra"):
                    per_layer.setdefault(name_of[int(tags[0])], []).append(block.data)
            edge = {name: mean_edge(m.points, np.vstack(b), 5.0, 7.0) for name, b in per_layer.items()}
            self.assertLess(edge["intima"], 1.3 * 0.3, edge)
            self.assertGreater(edge["adventitia"], 1.3 * edge["intima"], edge)
            with self.assertRaisesRegex(PatientInputError, r"patient.mesh.refine.layers: unknown layer 'intma'"):
                build(intima_only, Refinement(4, 8, 0.3, 1, ("intma",)))

    def test_the_same_scene_meshes_to_the_same_file(self):
        """Consistency: gmsh orders some containers by memory address, so the same geometry meshed in
        two processes differs (seen: nodes 0.03 mm apart) unless the mesher runs with a fixed memory
        layout; two runs of build_artery_reproducibly, to different files, give the same bytes. Its
        refusals arrive as build_artery's own."""
        pts, r, wall = arc(n=40, length=8.0, r0=0.8, stenosis=0.3)
        spec = WallSpec(media_ratio=0.06, adventitia_ratio=0.065, min_intima=0.05)
        with tempfile.TemporaryDirectory(prefix=f"patient-same-{os.getpid()}-") as d:
            files = [Path(d) / "one.msh", Path(d) / "sub" / "second.msh"]
            files[1].parent.mkdir()
            infos = [
                build_artery_reproducibly(pts, r, wall, spec, 0.7, f, binary=True, log=lambda m: None) for f in files
            ]
            self.assertEqual([i["file"] for i in infos], [str(f) for f in files])
            self.assertEqual(files[0].read_bytes(), files[1].read_bytes())
            with self.assertRaisesRegex(PatientInputError, r"c.csv: patient.mesh.refine.layers: unknown layer 'intma'"):
                build_artery_reproducibly(
                    pts,
                    r,
                    wall,
                    spec,
                    0.7,
                    files[0],
                    where="c.csv",
                    log=lambda m: None,
                    refine=Refinement(2, 4, 0.3, 1, ("intma",)),
                )

    def test_refinement_refused_when_not_finer(self):
        # checked before the placement is read (None here)
        with self.assertRaisesRegex(PatientInputError, r"s.yaml: patient.mesh.refine.size: expected a size below"):
            refinement_of({"size": 0.8, "refine": {"size": 0.8}}, None, "s.yaml")
        with self.assertRaisesRegex(PatientInputError, r"s.yaml: patient.mesh.refine.sise: unknown key"):
            refinement_of({"size": 0.8, "refine": {"sise": 0.3}}, None, "s.yaml")
        with self.assertRaisesRegex(PatientInputError, r"s.yaml: patient.mesh.refine.layers: expected a list of layer"):
            refinement_of({"size": 0.8, "refine": {"size": 0.3, "layers": [1]}}, None, "s.yaml")

    def test_thin_wall_refused(self):
        pts, r, wall = arc(n=30, length=6.0)
        with self.assertRaisesRegex(PatientInputError, "too thin"):
            layer_radii(r, 0.2 * wall, WallSpec(0.06, 0.065, 0.05), "c.csv")

    def test_shape_quality(self):
        """6 sqrt(2) V / l_rms^3: 1 for the regular tetrahedron at any size and position, the
        analytic value for a flattened one, -> 0 as it flattens to a sliver."""
        regular = np.array([[1, 1, 1], [-1, 1, -1], [1, -1, -1], [-1, -1, 1]], float)  # positively oriented
        flat = regular * [1.0, 1.0, 0.01]  # squashed along z: V and the z edges scale
        q = _shape_quality(np.array([regular, 3.0 * regular + 5.0, flat]))
        np.testing.assert_allclose(q[:2], 1.0, rtol=1e-12)
        # squashed: V = 8/3 * 0.01 (the regular one's 8/3 times the z scale), l_rms from its six edges
        e2 = [np.sum((flat[a] - flat[b]) ** 2) for a in range(4) for b in range(a + 1, 4)]
        expected = 6 * math.sqrt(2) * (8.0 / 3.0 * 0.01) / (np.mean(e2) ** 1.5)
        self.assertAlmostEqual(q[2], expected, places=12)
        self.assertLess(q[2], SLIVER_QUALITY * 3)

    def test_optimizer_result_discarded_when_it_inverts_a_corner_tetrahedron(self):
        """The high-order optimizer may move corner nodes and leave a tet4 inverted, which no
        straightening mends: then every node is put back where it was before the optimizer ran.
        Stands in for the optimizer with one that mirrors a corner of an element through its
        opposite face (that element's tet4 inverted), and with one that only moves a mid-edge node
        (a result that is kept)."""
        import gmsh

        def mirror_a_corner(_how):
            _, nodes, _, _, c = _jacobian_samples()
            e = int(np.argmax(c[:, :, 2].mean(axis=1)))  # any element: the one highest in z
            p, a, b, d = c[e]
            n = np.cross(b - a, d - a)
            n /= np.linalg.norm(n)
            gmsh.model.mesh.setNode(int(nodes[e, 0]), list(p - 2.0 * (p - a).dot(n) * n), [])

        def nudge_a_mid_edge_node(_how):
            _, nodes, _, _, c = _jacobian_samples()
            gmsh.model.mesh.setNode(int(nodes[0, 4]), list(0.5 * (c[0, 0] + c[0, 1]) + 1e-3), [])

        gmsh.initialize()
        real = gmsh.model.mesh.optimize
        try:
            gmsh.option.setNumber("General.Terminal", 0)
            gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
            gmsh.model.occ.synchronize()
            gmsh.option.setNumber("Mesh.MeshSizeMax", 0.5)
            gmsh.model.mesh.generate(3)
            gmsh.model.mesh.setOrder(2)
            _, before, _ = gmsh.model.mesh.getNodes()
            for fake, kept in ((mirror_a_corner, False), (nudge_a_mid_edge_node, True)):
                messages = []
                gmsh.model.mesh.optimize = fake
                samples = _optimize_high_order(messages.append)
                _, after, _ = gmsh.model.mesh.getNodes()
                self.assertEqual(np.array_equal(after, before), not kept, fake.__name__)
                self.assertEqual(any("discarded" in m for m in messages), not kept, messages)
                self.assertTrue((samples[3] > 0.0).all(), fake.__name__)  # every tet4 positive
        finally:
            gmsh.model.mesh.optimize = real
            gmsh.finalize()

    def test_edge_table_is_gmsh_order(self):
        import gmsh

        gmsh.initialize()
        try:
            props = gmsh.model.mesh.getElementProperties(11)  # (name, dim, order, n, local coords, ...)
            ref = np.array(props[4]).reshape(-1, 3)
            for k, (a, b) in enumerate(TET10_EDGES):
                np.testing.assert_allclose(ref[4 + k], 0.5 * (ref[a] + ref[b]))
        finally:
            gmsh.finalize()


class Straightening(unittest.TestCase):
    def test_bow_of_a_circle(self):
        # exact: three points of a circle of radius 5 spanning 60 degrees
        from patient.straightening import bow

        R, h = 5.0, math.radians(30)
        p = [np.array([R * math.sin(a), R * (1 - math.cos(a)), 0.0]) for a in (-h, 0.0, h)]
        b = bow(*p)
        self.assertAlmostEqual(b["radius"], R, places=12)
        self.assertAlmostEqual(b["chord"], 2 * R * math.sin(h), places=12)
        self.assertAlmostEqual(b["sagitta"], R * (1 - math.cos(h)), places=12)
        self.assertEqual(bow(np.zeros(3), np.array([1.0, 0, 0]), np.array([2.0, 0, 0]))["radius"], math.inf)


if __name__ == "__main__":
    unittest.main(verbosity=2)
