#!/usr/bin/python3
"""Plaque regions of the intima (`patient.plaque`, scripts/patient/plaque.py, artery_mesh.py).

Geometry against exact values: on a straight stenosed centerline along z (the sections' angle 0 is
then +x, 90 is +y), a calcified arc (30 to 120 deg, 0.25 mm from the lumen, s = 2 to 4.5 mm), and a
fibrous cap 0.1 mm thick over a lipid pool through the rest of the intima (200 to 300 deg, s = 2.5
to 4 mm) are meshed as their own volume groups: every plaque element's centroid lies in its sector,
and the tet10 volumes (4-point rule) equal the analytic sector volumes, the integral of
(angle / 360) pi (r_out^2 - r_in^2) ds, within 1 %. Materials: the type's from plaque_types.yaml,
the scene's own when it gives one.
Bad input refused before meshing, naming the entry: overlapping regions, a region beyond the
centerline, thicker than the intima, a type without parameters, a bad angle.
The same cap over a pool on a centerline bent at 10 mm: both meshed, volumes equal to the exact
swept annular sectors (Pappus) within 1 %; with the sector's sides on the seams of the layers'
circular sections (90 and 270 deg), no sliver, and the outer surface's area is the wall's (Pappus,
within 0.5 %).
With BIN_DIR: the solid alone under blood pressure on that mesh (consistency with the stiffness
order): the calcified arc (E 8.95 MPa) stretches around the lumen (hoop Green strain) less than half
as much as the intima beside it, and carries a larger mean first principal stress.
Usage: test_plaque.py [BIN_DIR]   (about 60 s with BIN_DIR)
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import yaml

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from mesh_measures import tet10_volumes, tri6_areas  # noqa: E402
from patient.artery_mesh import WallSpec, layer_radii  # noqa: E402
from patient.centerline_csv import write_centerline_csv  # noqa: E402
from patient.errors import PatientInputError  # noqa: E402
from patient.plaque import plaque_materials, plaque_types, read_plaque  # noqa: E402
from patient.prepare import SLIVER_QUALITY, prepare_scene  # noqa: E402

BIN = sys.argv.pop(1) if len(sys.argv) > 1 else None
LENGTH, WALL = 6.5, 0.8
CALCIFIED = {"type": "calcified", "from_s": 2.0, "to_s": 4.5, "angle": [30, 120], "thickness": 0.25}
# a fibrous cap 0.1 mm thick over a lipid pool that fills the rest of the intima
CAP = {"type": "fibrous", "from_s": 2.5, "to_s": 4.0, "angle": [200, 300], "thickness": 0.1}
POOL = {"type": "lipid", "from_s": 2.5, "to_s": 4.0, "angle": [200, 300], "offset": 0.1}


def lumen_radius(s):
    return 0.85 * (1 - 0.2 * np.exp(-(((s - 3.25) / 1.2) ** 2)))


def scene(plaque):
    with open(os.path.join(ROOT, "configs", "patient_like.yaml")) as f:
        sc = yaml.safe_load(f)
    sc["patient"]["centerline"] = "straight.csv"
    sc["patient"]["mesh"] = {"size": 0.7, "binary": True}
    sc["patient"]["plaque"] = plaque
    sc["stent"]["generator"].update(rings=3, ring_pitch=1.5)
    sc["balloon"]["mesh"].update(length=5.5, n_axial=38)
    return sc


class Plaque(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="plaque-")
        s = np.linspace(0.0, LENGTH, 53)
        write_centerline_csv(
            os.path.join(cls.tmp, "straight.csv"),
            np.column_stack([0 * s, 0 * s, s]),
            lumen_radius(s),
            np.full(len(s), WALL),
        )
        cls.scene_path = os.path.join(cls.tmp, "scene.yaml")
        cls.out = os.path.join(cls.tmp, "prepared")
        os.makedirs(cls.out)
        cls.done, cls.report = prepare_scene(scene([CALCIFIED, CAP, POOL]), cls.scene_path, cls.out, log=lambda m: None)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp)

    def test_regions_where_declared(self):
        import meshio

        m = meshio.read(os.path.join(self.out, "artery.msh"))
        names = {tag: name for name, (tag, dim) in m.field_data.items() if dim == 3}
        X = m.points
        vol, centroids = {}, {}
        for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
            if block.type == "tetra10":
                name = names[phys[0]]
                vol[name] = vol.get(name, 0.0) + tet10_volumes(X, block.data).sum()
                centroids.setdefault(name, []).append(X[block.data[:, :4]].mean(axis=1))
        self.assertEqual(
            set(vol), {"intima", "media", "adventitia", "plaque_calcified", "plaque_fibrous", "plaque_lipid"}
        )
        z = np.linspace(0.0, LENGTH, 6501)
        r = lumen_radius(z)
        _, ti, _, _ = layer_radii(r, np.full(len(z), WALL), WallSpec(0.06, 0.065, 0.05), "test")
        for reg, inner, outer in (
            (CALCIFIED, r, r + CALCIFIED["thickness"]),
            (CAP, r, r + CAP["thickness"]),
            (POOL, r + POOL["offset"], r + ti),
        ):
            name = f"plaque_{reg['type']}"
            c = np.concatenate(centroids[name])
            ang = np.degrees(np.arctan2(c[:, 1], c[:, 0])) % 360.0
            a0, a1 = reg["angle"]
            self.assertTrue(((ang > a0) & (ang < a1)).all(), f"{name}: angles {ang.min():.1f} to {ang.max():.1f}")
            self.assertTrue(((c[:, 2] > reg["from_s"]) & (c[:, 2] < reg["to_s"])).all(), name)
            on = (z >= reg["from_s"]) & (z <= reg["to_s"])
            exact = np.trapz((a1 - a0) / 360.0 * np.pi * (outer[on] ** 2 - inner[on] ** 2), z[on])
            self.assertAlmostEqual(vol[name] / exact, 1.0, delta=0.01, msg=f"{name}: {vol[name]:.4f} vs {exact:.4f}")
        self.assertEqual(self.done["artery"]["layers"]["plaque_calcified"]["E"], plaque_types()["calcified"]["E"])
        self.assertGreater(self.report["artery_mesh"]["min_scaled_jacobian"], 0.0)

    def test_regions_from_a_label_mesh(self):
        """patient.plaque_mesh: the fixture's own tet10 mesh written as VTU with a cell label per
        element (1 calcified, 2 fibrous, 3 lipid, 0 the rest) gives back the declared regions: the
        sectors within a centerline station and a ray (7.5 deg), offset and thickness within two of
        the 16 depth samples through the intima."""
        import meshio

        m = meshio.read(os.path.join(self.out, "artery.msh"))
        names = {tag: name for name, (tag, dim) in m.field_data.items() if dim == 3}
        types = ["calcified", "fibrous", "lipid"]
        cells, labels = [], []
        for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
            if block.type == "tetra10":
                name = names[phys[0]]
                cells.append(block.data)
                labels.append(np.full(len(block.data), types.index(name[7:]) + 1 if name.startswith("plaque_") else 0))
        path = os.path.join(self.tmp, "labels.vtu")
        cell_data = {"label": [np.concatenate(labels)]}
        meshio.write(path, meshio.Mesh(m.points, [("tetra10", np.concatenate(cells))], cell_data=cell_data))
        sc = scene([])
        sc["patient"]["plaque_mesh"] = {"file": path, "array": "label", "types": types}
        out = os.path.join(self.tmp, "from_mesh")
        os.makedirs(out)
        _, report = prepare_scene(sc, self.scene_path, out, log=lambda m: None)
        got = {r["layer"]: r for r in report["plaque"]}
        for r in report["plaque"]:
            print(r["layer"], {k: r[k] for k in ("from_s", "to_s", "angle", "offset", "thickness")})
        self.assertEqual(set(got), {"plaque_calcified", "plaque_fibrous", "plaque_lipid"}, report["plaque"])
        z = np.linspace(0.0, LENGTH, 6501)
        _, ti, _, _ = layer_radii(lumen_radius(z), np.full(len(z), WALL), WallSpec(0.06, 0.065, 0.05), "test")
        sample = 2 * ti.max() / 16
        station = LENGTH / 52
        for reg in (CALCIFIED, CAP, POOL):
            r = got[f"plaque_{reg['type']}"]
            for k in ("from_s", "to_s"):
                self.assertAlmostEqual(r[k], reg[k], delta=station, msg=f"{reg['type']} {k}: {r[k]:.3f}")
            for a, b in zip(r["angle"], reg["angle"]):
                self.assertAlmostEqual(a, b, delta=7.5, msg=f"{reg['type']} angle: {r['angle']}")
            self.assertAlmostEqual(r["offset"], reg.get("offset", 0.0), delta=sample, msg=f"{reg['type']}: {r}")
            if "thickness" in reg:
                self.assertAlmostEqual(r["thickness"], reg["thickness"], delta=sample, msg=f"{reg['type']}: {r}")
            else:
                self.assertEqual(r["thickness"], "intima", f"{reg['type']}: {r}")
        # a label without a type name, an absent array: refused naming the file and the key
        sc["patient"]["plaque_mesh"]["types"] = types[:2]
        with self.assertRaisesRegex(PatientInputError, "plaque_mesh.types: expected a name for every label"):
            prepare_scene(sc, self.scene_path, out, log=lambda m: None)
        sc["patient"]["plaque_mesh"].update(types=types, array="tissue")
        with self.assertRaisesRegex(PatientInputError, "labels.vtu: expected a cell data array 'tissue'.*label"):
            prepare_scene(sc, self.scene_path, out, log=lambda m: None)

    def test_scene_material_wins(self):
        regions = read_plaque([CALCIFIED, CAP, POOL], LENGTH, "s.yaml")
        own = {"plaque_calcified": {"E": 5.0, "nu": 0.4}}
        self.assertEqual(set(plaque_materials(regions, own, "s.yaml")), {"plaque_fibrous", "plaque_lipid"})

    def test_bad_input_refused_before_meshing(self):
        cases = [
            ([CALCIFIED, dict(CALCIFIED, angle=[100, 150])], "plaque[1]: expected regions that do not overlap"),
            ([dict(CALCIFIED, to_s=LENGTH + 1)], "plaque[0]: expected 0 <= from_s < to_s"),
            ([dict(CALCIFIED, thickness=0.5)], "plaque[0]: expected offset + thickness at most the intima"),
            ([CAP, dict(POOL, offset=0.05)], "plaque[1]: expected regions that do not overlap"),
            ([dict(CALCIFIED, type="fibrocalcific")], "artery.layers.plaque_fibrocalcific"),
            ([dict(CALCIFIED, angle=[120, 30])], "plaque[0].angle"),
            ([dict(CALCIFIED, colour="red")], "plaque[0].colour: unknown key"),
        ]
        for plaque, expect in cases:
            out = os.path.join(self.tmp, "bad")
            shutil.rmtree(out, ignore_errors=True)
            os.makedirs(out)
            with self.assertRaises(PatientInputError) as e:
                prepare_scene(scene(plaque), self.scene_path, out, log=lambda m: None)
            self.assertIn(expect, str(e.exception))
            self.assertFalse(os.path.exists(os.path.join(out, "artery.msh")), expect)

    @unittest.skipIf(BIN is None, "no BIN_DIR given")
    def test_solid_under_blood_pressure(self):
        import h5py

        sc = {k: v for k, v in self.done.items() if k not in ("balloon", "stent", "contact", "coupling")}
        sc["time"] = {"end": 1.0, "steps": 1}
        sc["load_curves"] = {"ramp": [[0.0, 0.0], [1.0, 1.0]]}
        sc["artery"]["blood_pressure"] = {"value": 0.01133, "curve": "ramp"}  # 85 mmHg
        sc["solid"] = {"ranks": 1, "petsc_options": "-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps"}
        sc["output"] = {"every": 1}
        path = os.path.join(self.tmp, "solid.yaml")
        with open(path, "w") as f:
            yaml.safe_dump(sc, f, sort_keys=False)
        run = os.path.join(self.tmp, "solid-run")
        p = subprocess.run(
            [os.path.join(BIN, "solid_solver"), "--scene", path, "--run-dir", run],
            capture_output=True,
            text=True,
            timeout=900,
        )
        self.assertEqual(p.returncode, 0, p.stdout[-2000:] + p.stderr[-2000:])
        with h5py.File(os.path.join(run, "solid", "solid.h5")) as f:
            X = f["/mesh/coordinates"][:]
            last = max(f["/steps"].keys(), key=int)
            u = f[f"/steps/{last}/displacement"][:]
            p1 = f[f"/steps/{last}/tet10/stress_p1"][:]
            block = f["/mesh/tet10/block_id"][:]
            conn = f["/mesh/tet10/connectivity"][:]
        with open(os.path.join(run, "solid", "summary.json")) as f:
            blocks = {b["id"]: b["name"] for b in json.load(f)["blocks"]}
        # hoop Green strain per element from its corners (tet4 gradient at the centroid): the stiff
        # arc stretches around the lumen far less than the intima beside it
        c = X[conn[:, :4]]
        D = np.stack([c[:, k] - c[:, 0] for k in (1, 2, 3)], axis=2)  # dX/dxi
        du = np.stack([u[conn[:, k]] - u[conn[:, 0]] for k in (1, 2, 3)], axis=2)
        F = np.eye(3) + np.einsum("eij,ejk->eik", du, np.linalg.inv(D))
        E = 0.5 * (np.einsum("eji,ejk->eik", F, F) - np.eye(3))
        cen = c.mean(axis=1)
        eth = np.column_stack([-cen[:, 1], cen[:, 0], 0 * cen[:, 0]])
        eth /= np.linalg.norm(eth, axis=1)[:, None]
        hoop = np.einsum("ei,eij,ej->e", eth, E, eth)
        ang = np.degrees(np.arctan2(cen[:, 1], cen[:, 0])) % 360.0
        name_of = np.array([blocks[b] for b in block])
        middle = np.abs(cen[:, 2] - 3.25) < 0.75
        calcified = hoop[middle & (name_of == "plaque_calcified")].mean()
        intima = hoop[middle & (name_of == "intima") & ((ang > 320) | (ang < 10))].mean()
        print(f"hoop Green strain: calcified {calcified:.3e}, intima beside it {intima:.3e}", flush=True)
        self.assertLess(calcified, 0.5 * intima, f"hoop strain {calcified:.2e} (calcified) vs {intima:.2e} (intima)")
        mean = {name: p1[block == k].mean() for k, name in blocks.items()}
        self.assertGreater(mean["plaque_calcified"], mean["intima"], mean)


class CapOverPoolInABend(unittest.TestCase):
    """The same fibrous cap over a lipid pool on a centerline bent at RC = 10 mm (before, the two
    regions' separately lofted flat sides left a piece outside the wall there): both meshed, and each
    volume equal to the exact one of an annular sector swept along the arc (Pappus: the volume
    element shrinks by 1 - rho cos(theta) / RC towards the bend's center, theta = 0 there),
    integral ds [(a1 - a0)(ro^2 - ri^2) / 2 - (sin a1 - sin a0)(ro^3 - ri^3) / (3 RC)], within 1 %
    as on the straight centerline."""

    RC = 10.0

    def mesh(self, plaque):
        import meshio

        tmp = tempfile.mkdtemp(prefix="plaque-bend-")
        try:
            s = np.linspace(0.0, LENGTH, 53)
            phi = s / self.RC  # in the x-z plane, starting along z, bending towards +x (angle 0)
            pts = np.column_stack([self.RC * (1 - np.cos(phi)), 0 * s, self.RC * np.sin(phi)])
            write_centerline_csv(os.path.join(tmp, "bent.csv"), pts, lumen_radius(s), np.full(len(s), WALL))
            sc = scene(plaque)
            sc["patient"]["centerline"] = "bent.csv"
            out = os.path.join(tmp, "prepared")
            os.makedirs(out)
            _, report = prepare_scene(sc, os.path.join(tmp, "scene.yaml"), out, log=lambda m: None)
            m = meshio.read(os.path.join(out, "artery.msh"))
        finally:
            shutil.rmtree(tmp)
        names = {tag: name for name, (tag, dim) in m.field_data.items()}
        vol = {}
        for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
            if block.type == "tetra10":
                vol[names[phys[0]]] = vol.get(names[phys[0]], 0.0) + tet10_volumes(m.points, block.data).sum()
            if block.type == "triangle6":
                for tag in np.unique(phys):
                    area = tri6_areas(m.points, block.data[phys == tag]).sum()
                    vol[names[tag]] = vol.get(names[tag], 0.0) + area
        return vol, report["artery_mesh"]  # volumes by layer, areas by surface

    def check_volumes(self, vol, cap, pool):
        z = np.linspace(0.0, LENGTH, 6501)
        r = lumen_radius(z)
        _, ti, _, _ = layer_radii(r, np.full(len(z), WALL), WallSpec(0.06, 0.065, 0.05), "test")
        for reg, ri, ro in ((cap, r, r + cap["thickness"]), (pool, r + pool["offset"], r + ti)):
            name = f"plaque_{reg['type']}"
            a0, a1 = np.radians(reg["angle"])
            on = (z >= reg["from_s"]) & (z <= reg["to_s"])
            dA = (a1 - a0) * (ro**2 - ri**2) / 2 - (np.sin(a1) - np.sin(a0)) * (ro**3 - ri**3) / (3 * self.RC)
            exact = np.trapz(dA[on], z[on])
            print(f"{name}: meshed {vol[name]:.5f} mm^3, exact {exact:.5f} mm^3")
            self.assertAlmostEqual(vol[name] / exact, 1.0, delta=0.01, msg=f"{name}: {vol[name]:.4f} vs {exact:.4f}")

    def test_volumes(self):
        vol, _ = self.mesh([CAP, POOL])
        self.check_volumes(vol, CAP, POOL)

    def test_sides_on_the_seams_of_the_layers(self):
        """The sector's sides at 90 and 270 deg, where the four arcs of the layers' circular sections
        meet: the sections start elsewhere (artery_mesh._seam_angle), and no element is a sliver
        (shape quality at least the launcher's warning level, prepare.SLIVER_QUALITY; 1e-5 when the
        sides lay on the seams)."""
        cap, pool = ({**reg, "angle": [90, 270]} for reg in (CAP, POOL))
        vol, mesh = self.mesh([cap, pool])
        print(f"shape quality per layer: {mesh['min_shape_quality']}")
        for layer, q in mesh["min_shape_quality"].items():
            self.assertGreater(q, SLIVER_QUALITY, f"{layer}: {q:.2e} ({mesh['worst_shape']})")
        self.check_volumes(vol, cap, pool)
        # the pool's pie reaches beyond the wall and cuts the adventitia: the outer surface stays
        # the wall's outer surface only, 2 pi r_out sqrt(1 + r_out'^2) ds along the arc (Pappus;
        # the faces between the cut pieces, 2-3 % more, are not part of it)
        z = np.linspace(0.0, LENGTH, 6501)
        r_out = lumen_radius(z) + WALL
        exact = np.trapz(2 * np.pi * r_out * np.sqrt(1 + np.gradient(r_out, z) ** 2), z)
        print(f"outer surface: meshed {vol['outer']:.4f} mm^2, exact {exact:.4f} mm^2")
        self.assertAlmostEqual(vol["outer"] / exact, 1.0, delta=0.005)


if __name__ == "__main__":
    unittest.main(verbosity=2)
