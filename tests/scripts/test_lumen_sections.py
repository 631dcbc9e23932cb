#!/usr/bin/python3
"""Non-circular lumens and walls of varying thickness from a lumen surface
(scripts/patient/lumen_sections.py, artery_mesh.py with `sections`).

Analytic checks on a straight elliptic tube along z (semi-axes A = 1.2 mm along x, B = 0.8 mm along y,
its center shifted by E = 0.2 mm along +x, 96 facets around) carrying a wall-thickness point array
w = W0 + W1 cos(theta) (theta around the tube, 0 along +x: a wall thicker on one side):
- the sections' polar radius equals the ellipse's around the station point, and the thickness sampled
  on the rays equals w, both within the facets' chord error (1 - cos(pi / 96) = 5e-4 relative);
- the clearance radius (the largest circle around the station point inside the section) is the
  ellipse's distance from its center point, B, within the chord error;
- a C-shaped section around its centroid is refused, naming the station ("not star-shaped");
- the meshed three-layer wall (tet10): its volume and its intima's equal the polar integrals
  L/2 int (r_out^2 - r_in^2) dtheta of the radial offsets (media and adventitia thickness from the
  area-equivalent outer diameter, as artery_mesh.layer_radii) within 0.5 %, and no element is inverted;
- the wall from an outer surface (a circle around the tube) is the distance between the surfaces
  along each ray, within the chord errors; an outer surface cutting into the lumen is refused;
- plaque from a label array: the sectors bound the labelled patches within a ray and a facet spacing
  (angles) and a station and a ring spacing (arc length), a patch across angle 0 is one sector, and
  the regions are meshed as plaque layers by the pipeline;
- a thickness array the file does not have is refused naming it and the arrays it has.
Usage: test_lumen_sections.py   (about 60 s)
"""
import os
import shutil
import sys
import tempfile
import unittest

import meshio
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_measures import tet10_volumes  # noqa: E402
from patient.artery_mesh import WallSpec, build_artery  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.lumen_sections import LumenSections, inscribed_radius, read_wall_field  # noqa: E402
from patient.lumen_surface import read_lumen_surface  # noqa: E402
from patient.plaque_labels import read_labels, regions_from_labels  # noqa: E402

A, B, E, LENGTH = 1.2, 0.8, 0.2, 6.0
W0, W1 = 1.0, 0.3
NC, NA = 96, 30
SPEC = WallSpec(media_ratio=0.06, adventitia_ratio=0.065, min_intima=0.05)


def ellipse_tube(section=None):
    """Points, triangles and wall thickness of the straight tube; section(phi) -> (x, y) overrides the ellipse."""
    phi = 2 * np.pi * np.arange(NC) / NC
    x, y = section(phi) if section else (E + A * np.cos(phi), B * np.sin(phi))
    z = np.linspace(0.0, LENGTH, NA + 1)
    pts = np.array([[x[j], y[j], zi] for zi in z for j in range(NC)])
    tris = []
    for i in range(NA):
        for j in range(NC):
            a, b, c, d = i * NC + j, i * NC + (j + 1) % NC, (i + 1) * NC + j, (i + 1) * NC + (j + 1) % NC
            tris += [[a, b, d], [a, d, c]]
    theta = np.arctan2(pts[:, 1], pts[:, 0] - E)
    return pts, np.array(tris), W0 + W1 * np.cos(theta)


def plaque_labels(pts):
    """1 (calcified) over 30..90 deg and z 2..4 mm, 2 (lipid) over 200..260 deg and z 2.5..3.5 mm."""
    deg = np.mod(np.degrees(np.arctan2(pts[:, 1], pts[:, 0] - E)), 360.0)
    z = pts[:, 2]
    lab = np.zeros(len(pts), dtype=np.int32)
    lab[(deg >= 30) & (deg <= 90) & (z >= 2) & (z <= 4)] = 1
    lab[(deg >= 200) & (deg <= 260) & (z >= 2.5) & (z <= 3.5)] = 2
    return lab


def ellipse_rho(theta):
    """Polar radius of the ellipse around its center."""
    return A * B / np.sqrt((B * np.cos(theta)) ** 2 + (A * np.sin(theta)) ** 2)


class LumenSections_(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="angio-sections-")
        pts, tris, w = ellipse_tube()
        cls.path = os.path.join(cls.tmp, "ellipse.vtk")
        data = {"wall_thickness": w, "plaque": plaque_labels(pts)}
        meshio.write(cls.path, meshio.Mesh(pts, [("triangle", tris)], point_data=data))
        cls.surface = read_lumen_surface(cls.path)
        cls.sections = LumenSections(cls.surface, read_wall_field(cls.path, cls.surface, "wall_thickness"))
        cls.frame = (np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_polar_radius_and_thickness_on_the_rays(self):
        t, n1, n2 = self.frame
        for z in (0.05, 2.5, 5.95):
            rho, w = self.sections.polar(np.array([E, 0.0, z]), t, n1, n2, f"z = {z}")
            theta = 2 * np.pi * np.arange(len(rho)) / len(rho)
            self.assertLess(np.max(np.abs(rho / ellipse_rho(theta) - 1)), 1e-3)
            # w interpolated linearly along facets of the 96-gon: within the chord error of W1 cos
            self.assertLess(np.max(np.abs(w - (W0 + W1 * np.cos(theta)))), 2e-3)

    def test_clearance_radius_is_the_minor_semi_axis(self):
        t, n1, n2 = self.frame
        r = inscribed_radius(self.sections.polar(np.array([E, 0.0, 3.0]), t, n1, n2, "z = 3")[0])
        self.assertLess(abs(r / B - 1), 1e-3)
        self.assertLess(r, ellipse_rho(np.linspace(0, 2 * np.pi, 97)).min() + 1e-9)

    def test_a_c_shaped_section_is_refused(self):
        def c_shape(phi):  # a ring band 0.7..1.0 from 30 to 330 deg: its centroid lies in the hole
            u = np.concatenate([np.linspace(np.radians(30), np.radians(330), NC // 2)] * 2)
            r = np.concatenate([np.full(NC // 2, 1.0), np.full(NC // 2, 0.7)])
            order = np.concatenate([np.arange(NC // 2), NC // 2 + np.arange(NC // 2)[::-1]])
            return (r * np.cos(u))[order], (r * np.sin(u))[order]

        pts, tris, _ = ellipse_tube(c_shape)
        path = os.path.join(self.tmp, "c.stl")
        meshio.write(path, meshio.Mesh(pts, [("triangle", tris)]))
        sections = LumenSections(read_lumen_surface(path))
        t, n1, n2 = self.frame
        with self.assertRaisesRegex(PatientInputError, r"c\.stl: the section at z = 3 .*not star-shaped"):
            sections.polar(np.array([-0.2, 0.0, 3.0]), t, n1, n2, "z = 3")

    def test_wall_from_an_outer_surface(self):
        """The thickness along each ray is the distance from the ellipse to a circular outer wall of radius
        RO around the z axis (the rays start at (E, 0)): t(theta) = -E cos + sqrt(RO^2 - E^2 sin^2) - rho;
        within the two 96-gons' chord errors. An outer surface cutting into the lumen is refused."""
        t, n1, n2 = self.frame
        paths = {}
        for name, radius in (("outer", 2.2), ("inner", 1.1)):
            pts, tris, _ = ellipse_tube(lambda phi, r=radius: (r * np.cos(phi), r * np.sin(phi)))
            paths[name] = os.path.join(self.tmp, f"{name}.stl")
            meshio.write(paths[name], meshio.Mesh(pts, [("triangle", tris)]))
        outer = LumenSections(read_lumen_surface(paths["outer"]))
        sections = LumenSections(self.surface, outer=outer)
        rho, w = sections.polar(np.array([E, 0.0, 3.0]), t, n1, n2, "z = 3")
        theta = 2 * np.pi * np.arange(len(rho)) / len(rho)
        exact = -E * np.cos(theta) + np.sqrt(2.2**2 - (E * np.sin(theta)) ** 2) - ellipse_rho(theta)
        self.assertLess(np.max(np.abs(w - exact)), 3e-3)
        self.assertEqual(sections.wall_from, "outer surface")
        inside = LumenSections(self.surface, outer=LumenSections(read_lumen_surface(paths["inner"])))
        with self.assertRaisesRegex(PatientInputError, r"inner\.stl: the outer wall at z = 3 lies inside the lumen"):
            inside.polar(np.array([E, 0.0, 3.0]), t, n1, n2, "z = 3")

    def test_plaque_sectors_from_labels(self):
        """Sectors that bound each label patch: within half a ray (3.75 deg) plus the facets' spacing
        (3.75 deg) of the labelled angles, within half a station plus the rings' spacing (0.2 mm) of the
        labelled z; a patch across angle 0 is one sector through 0; too many labels are refused."""
        t, n1, n2 = self.frame
        labelled = LumenSections(self.surface, labels=read_labels(self.path, self.surface, "plaque"))
        z = np.linspace(0.1, LENGTH - 0.1, 59)
        grid = [labelled.sample(np.array([E, 0.0, zi]), t, n1, n2, f"z = {zi}")[2] for zi in z]
        got = regions_from_labels(np.array(grid), z - z[0], ["calcified", "lipid"], 0.3, "test")
        self.assertEqual([e["type"] for e in got], ["calcified", "lipid"])
        for e, (a0, a1, z0, z1) in zip(got, ((30, 90, 2.0, 4.0), (200, 260, 2.5, 3.5))):
            self.assertLess(abs(e["angle"][0] - a0), 7.5, e)
            self.assertLess(abs(e["angle"][1] - a1), 7.5, e)
            self.assertLess(abs(e["from_s"] + z[0] - z0), 0.25, e)
            self.assertLess(abs(e["to_s"] + z[0] - z1), 0.25, e)
            self.assertEqual(e["thickness"], 0.3)
        across = np.zeros((5, 48), dtype=int)
        across[1:4, [46, 47, 0, 1]] = 1
        (e,) = regions_from_labels(across, np.arange(5.0), ["fibrous"], None, "test")
        self.assertEqual(e["angle"], [-18.75, 11.25])  # rays at 345, 352.5, 0, 7.5 deg
        self.assertEqual((e["from_s"], e["to_s"]), (0.5, 3.5))
        self.assertNotIn("thickness", e)
        with self.assertRaisesRegex(PatientInputError, "test.types: expected a name for every label"):
            regions_from_labels(2 * across, np.arange(5.0), ["fibrous"], None, "test")

    def test_a_given_centerline_through_the_surface(self):
        """patient.centerline and patient.lumen_surface together: the CSV's points, the radius of the
        surface's sections (an ellipse around its center: sqrt(A B)), the CSV's wall column kept."""
        from pathlib import Path

        from patient.centerline_csv import read_centerline_csv, write_centerline_csv
        from patient.prepare import lumen_csv

        z = np.linspace(0.1, LENGTH - 0.1, 30)
        pts = np.column_stack([np.full_like(z, E), np.zeros_like(z), z])
        given = os.path.join(self.tmp, "given.csv")
        write_centerline_csv(given, pts, np.ones_like(z), wall=np.full_like(z, 0.7))
        pat = {"centerline": given, "lumen_surface": {"file": self.path}, "wall": {"thickness": "from_centerline"}}
        out = Path(self.tmp) / "given"
        out.mkdir(exist_ok=True)
        csv, sections, _ = lumen_csv(dict(pat, outer_surface=None), Path(self.tmp) / "scene.yaml", out, lambda m: None)
        cl = read_centerline_csv(csv)
        self.assertLess(np.abs(cl.points - pts).max(), 1e-6)
        self.assertLess(np.abs(cl.radius / np.sqrt(A * B) - 1).max(), 2e-3)
        self.assertTrue(np.allclose(cl.wall, 0.7))
        self.assertIsNotNone(sections)

    def test_missing_thickness_array_is_refused(self):
        with self.assertRaisesRegex(
            PatientInputError, r"ellipse\.vtk: expected a point data array 'wall'.*wall_thickness"
        ):
            read_wall_field(self.path, self.surface, "wall")

    def test_layered_wall_volumes(self):
        z = np.linspace(0.01, LENGTH - 0.01, 13)  # inside the open ends, as a computed centerline is
        points = np.column_stack([np.full_like(z, E), np.zeros_like(z), z])
        r_eq = np.sqrt(A * B)
        out = os.path.join(self.tmp, "wall.msh")
        info = build_artery(
            points, np.full_like(z, r_eq), np.full_like(z, W0), SPEC, 0.5, out, loft_spacing=0.5,
            log=lambda m: None, sections=self.sections,
        )  # fmt: skip
        self.assertGreater(info["min_scaled_jacobian"], 0.0)
        self.assertAlmostEqual(info["lumen_aspect_max"], A / B, delta=0.01)
        m = meshio.read(out)
        vol = {}
        for name, tags in m.cell_sets_dict.items():
            for ctype, idx in tags.items():
                if ctype == "tetra10":
                    conn = m.cells_dict["tetra10"][idx]
                    vol[name] = tet10_volumes(np.asarray(m.points), conn).sum()
        # exact: polar integrals of the radial offsets (dense quadrature)
        th = np.linspace(0.0, 2 * np.pi, 4001)[:-1]
        rho, w = ellipse_rho(th), W0 + W1 * np.cos(th)
        D = 2 * (np.sqrt(np.mean(rho**2)) + np.mean(w))
        ti = w - (SPEC.media_ratio + SPEC.adventitia_ratio) * D

        def ring(r_in, r_out):
            return (z[-1] - z[0]) * 0.5 * np.mean(r_out**2 - r_in**2) * 2 * np.pi

        exact = {"intima": ring(rho, rho + ti), "wall": ring(rho, rho + w)}
        total = vol["intima"] + vol["media"] + vol["adventitia"]
        print(
            f"intima {vol['intima'] / exact['intima'] - 1:+.2e}, wall {total / exact['wall'] - 1:+.2e}", file=sys.stderr
        )
        # the loft goes through 16 low-passed samples: about 1e-3 mm off the ellipse (aspect 1.5), i.e.
        # up to 2 x 1e-3 / (2 rho + w) ~ 7e-4 of the wall's area; 0.5 % leaves the tet10's curved-face
        # error room (measured -3.2e-5 and -1.8e-4)
        self.assertLess(abs(vol["intima"] / exact["intima"] - 1), 0.005, (vol, exact))
        self.assertLess(abs(total / exact["wall"] - 1), 0.005, (vol, exact))

    def test_patient_pipeline_with_the_wall_from_the_surface(self):
        """patient.lumen_surface with wall.thickness from_surface: the report gives the sections' aspect
        ratio, inscribed diameter (2 B) and wall range (W0 -+ W1); the balloon, on the axis, clears the
        inscribed circle; keys that cannot go together are refused naming them."""
        import yaml

        from patient.prepare import prepare_scene

        with open(os.path.join(ROOT, "configs", "patient_like.yaml")) as f:
            scene = yaml.safe_load(f)
        del scene["patient"]["centerline"]
        scene["patient"]["lumen_surface"] = {"file": self.path}
        scene["patient"]["wall"]["thickness"] = "from_surface"
        scene["patient"]["stenosis"] = 3.0  # a uniform tube: its middle
        scene["patient"]["lumen_surface"]["plaque"] = {"array": "plaque", "types": ["calcified", "lipid"]}
        scene["patient"]["mesh"]["size"] = 0.8
        scene["balloon"]["mesh"].update(length=5.0, n_axial=34)
        scene["stent"]["generator"].update(rings=2, ring_pitch=1.5)
        scene_path = os.path.join(self.tmp, "scene.yaml")
        out = os.path.join(self.tmp, "prepared")
        os.makedirs(out, exist_ok=True)
        _, report = prepare_scene(scene, scene_path, out, log=lambda m: None)
        sec = report["lumen_sections"]
        self.assertAlmostEqual(sec["aspect_max"], A / B, delta=0.01)
        self.assertAlmostEqual(min(sec["inscribed_diameter_range"]), 2 * B, delta=0.01)
        self.assertAlmostEqual(sec["wall_range"][0], W0 - W1, delta=0.01)
        self.assertAlmostEqual(sec["wall_range"][1], W0 + W1, delta=0.01)
        self.assertEqual(sec["wall_from"], "surface")
        self.assertAlmostEqual(report["placement"]["clearance"]["balloon"], B - 0.49, delta=0.01)
        self.assertGreater(report["artery_mesh"]["min_scaled_jacobian"], 0.0)
        self.assertEqual([p["layer"] for p in report["plaque"]], ["plaque_calcified", "plaque_lipid"])
        self.assertGreater(report["artery_mesh"]["per_layer"]["plaque_lipid"], 0)
        bad = [
            ({"sections": "circles"}, {}, "from_surface needs patient.lumen_surface.sections: surface"),
            ({"wall_array": "thickness"}, {}, "expected a point data array 'thickness'"),
        ]
        for surface_keys, _, message in bad:
            sc = yaml.safe_load(yaml.safe_dump(scene))
            sc["patient"]["lumen_surface"].update(surface_keys)
            with self.assertRaisesRegex(PatientInputError, message):
                prepare_scene(sc, scene_path, out, log=lambda m: None)
        sc = yaml.safe_load(yaml.safe_dump(scene))
        sc["patient"]["wall"]["thickness"] = "from_outer_surface"
        with self.assertRaisesRegex(PatientInputError, "from_outer_surface needs patient.outer_surface"):
            prepare_scene(sc, scene_path, out, log=lambda m: None)
        sc["patient"]["wall"]["thickness"] = 0.6
        sc["patient"]["outer_surface"] = {"file": self.path}
        with self.assertRaisesRegex(PatientInputError, "patient.outer_surface: expected patient.wall.thickness"):
            prepare_scene(sc, scene_path, out, log=lambda m: None)
        sc = yaml.safe_load(yaml.safe_dump(scene))
        del sc["patient"]["lumen_surface"]
        sc["patient"]["centerline"] = os.path.join(ROOT, "configs", "centerlines", "patient_like.csv")
        with self.assertRaisesRegex(PatientInputError, "from_surface needs patient.lumen_surface"):
            prepare_scene(sc, scene_path, out, log=lambda m: None)


if __name__ == "__main__":
    unittest.main(verbosity=2)
