#!/usr/bin/python3
"""A synthetic segmented coronary lumen with an eccentric, elliptic lesion, written as a surface
the patient pipeline reads (`patient.lumen_surface`): what a segmentation of a lesioned segment
looks like, with the geometry known exactly, so that the pipeline can be checked against it and a
scene can run it end to end (configs/lesion_surface.yaml).

The vessel: a centerline arc of radius 40 mm in the x-z plane (it starts at the origin along +z and
bends towards +x), 20 mm long; a reference lumen of 2.8 mm (a mid-sized coronary, e.g. the proximal
LAD of Dodge et al. 1992, Circulation 86:232). The lesion, centered at s = 10 mm over a Gaussian of
2.5 mm: the lumen narrows to 60 % of the reference (the area-equivalent diameter: a 40 % diameter
stenosis), becomes an ellipse of aspect ratio 1.4 (long axis in the plane of the bend), and its
center moves 0.3 mm towards -y, away from a plaque that thickens the wall on the +y side from
0.6 mm to up to 1.2 mm (point-data array `wall_thickness`, mm). With the sections' angle measured
from the in-plane normal towards the bend's center (patient pipeline: 0 deg), +y is 90 deg: a
calcified arc there is `angle: [60, 120]`.

  scripts/make_lesion_surface.py configs/lesions/eccentric_lesion.vtk [--stl lumen.stl]
  scripts/make_lesion_surface.py configs/lesions/elliptic_aspect2.vtk --aspect 2 --narrowing 0.3 --shift 0

The point-data array `plaque_label` marks that arc (1: calcified, 0: none) where the lesion is above
half its depth, for `patient.lumen_surface.plaque: {array: plaque_label, types: [calcified]}`.
VTP (VTK XML PolyData) and VTK (legacy, binary) keep the arrays; STL keeps the surface only.
Units: mm."""
import argparse

import meshio
import numpy as np
from patient.surface_file import write_vtp

ARC_RADIUS, LENGTH = 40.0, 20.0  # mm
R_REF, WALL = 1.4, 0.6  # mm: reference lumen radius, wall outside the lesion
WIDTH = 2.5  # mm: the lesion's Gaussian width along the centerline (its center at mid-length)
NARROWING, ASPECT, SHIFT, PLAQUE = 0.4, 1.4, 0.3, 0.6  # diameter stenosis, ellipse, mm, mm
DS, AROUND = 0.2, 64  # mm between rings of vertices, vertices around


def lesion(s, site):
    """0 away from the lesion, 1 at its center `site`."""
    return np.exp(-(((s - site) / WIDTH) ** 2))


def surface(narrowing=NARROWING, aspect=ASPECT, shift=SHIFT, length=LENGTH, r_ref=R_REF):
    """(points (n, 3), triangles (m, 3), wall thickness per point (n,), plaque label per point (n,)),
    the lesion at mid-length."""
    s = np.linspace(0.0, length, int(round(length / DS)) + 1)
    phi = s / ARC_RADIUS
    center = np.column_stack([ARC_RADIUS * (1 - np.cos(phi)), np.zeros_like(s), ARC_RADIUS * np.sin(phi)])
    n1 = np.column_stack([np.cos(phi), np.zeros_like(s), -np.sin(phi)])  # towards the bend's center
    n2 = np.array([0.0, 1.0, 0.0])
    theta = 2 * np.pi * np.arange(AROUND) / AROUND
    g = lesion(s, site=0.5 * length)[:, None]
    r_eq = r_ref * (1 - narrowing * g)
    k = 1 + (np.sqrt(aspect) - 1) * g  # semi-axes r_eq k and r_eq / k: the area of the equivalent circle
    x = r_eq * k * np.cos(theta)
    y = r_eq / k * np.sin(theta) - shift * g
    pts = center[:, None, :] + x[..., None] * n1[:, None, :] + y[..., None] * n2
    wall = WALL + PLAQUE * g * np.clip(np.sin(theta), 0.0, None) ** 2
    # the calcified arc as a label (1) where the plaque is thickest: 60-120 deg, lesion above half
    label = ((g > 0.5) & (np.sin(theta) >= np.sin(np.pi / 3))).astype(float) * np.ones_like(theta)
    n = len(s)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(AROUND), indexing="ij")
    a, b = i * AROUND + j, i * AROUND + (j + 1) % AROUND
    tris = np.concatenate([np.stack([a, b, b + AROUND], -1), np.stack([a, b + AROUND, a + AROUND], -1)])
    return pts.reshape(-1, 3), tris.reshape(-1, 3), wall.ravel(), label.ravel()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", help="the surface with its wall_thickness array (.vtp, .vtk, .vtu, .ply)")
    ap.add_argument("--stl", help="also the surface alone as STL")
    ap.add_argument("--narrowing", type=float, default=NARROWING, help="diameter stenosis of the equivalent lumen")
    ap.add_argument("--aspect", type=float, default=ASPECT, help="the ellipse's aspect ratio at the throat")
    ap.add_argument("--shift", type=float, default=SHIFT, help="mm the lumen moves away from the plaque")
    ap.add_argument("--length", type=float, default=LENGTH, help="mm of centerline (the lesion at mid-length)")
    ap.add_argument("--radius", type=float, default=R_REF, help="mm, the reference lumen radius")
    a = ap.parse_args()
    pts, tris, wall, label = surface(a.narrowing, a.aspect, a.shift, a.length, a.radius)
    arrays = {"wall_thickness": wall, "plaque_label": label}
    if a.out.lower().endswith(".vtp"):  # VTK XML PolyData, as SimVascular and VMTK write surfaces
        write_vtp(a.out, pts, polys=tris, point_data=arrays)
    else:
        meshio.write(a.out, meshio.Mesh(pts, [("triangle", tris)], point_data=arrays), binary=True)
    if a.stl:
        meshio.write(a.stl, meshio.Mesh(pts, [("triangle", tris)]), binary=True)
    print(f"{a.out}: {len(pts)} points, {len(tris)} triangles")


if __name__ == "__main__":
    main()
