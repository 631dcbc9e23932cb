#!/usr/bin/python3
"""Writes the gmsh test meshes of tests/solid (GmshReader.* in ../test_gmsh_reader.cpp).

A 90-degree piece of a hollow cylinder (axis +z, z in [0, 1] mm) with two layers, media
(r 1.5..1.7 mm) and adventitia (r 1.7..2.0 mm), meshed with second-order tetrahedra (tet10)
and written twice from the same mesh:

  layered_tube_ascii.msh   MSH 4.1 ASCII
  layered_tube_binary.msh  MSH 4.1 binary

and a unit cube of a few linear tetrahedra in the legacy format the reader must refuse:

  cube_v22.msh             MSH 2.2 ASCII

Physical groups: volumes "media", "adventitia"; surfaces "inner" (r = 1.5), "outer" (r = 2),
"end0" (z = 0), "end1" (z = 1). The two cut planes of the sector have no group.

Run from anywhere: /usr/bin/python3 tests/solid/data/make_layered_tube.py
(needs the gmsh Python module, Debian python3-gmsh; the files were made with gmsh 4.8).
"""
import math
import os

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))
LENGTH = 1.0
RADII = [1.5, 1.7, 2.0]  # interfaces from inside to outside
LAYERS = ["media", "adventitia"]
ANGLE = 0.5 * math.pi
MESH_SIZE = 0.5  # mm; coarse, each file is about 50 kB (254 tet10)


def layer_volumes():
    """One OCC volume per layer: sector of the outer cylinder minus sector of the inner one."""
    occ = gmsh.model.occ
    shells = []
    for r0, r1 in zip(RADII[:-1], RADII[1:]):
        outer = occ.addCylinder(0, 0, 0, 0, 0, LENGTH, r1, angle=ANGLE)
        inner = occ.addCylinder(0, 0, 0, 0, 0, LENGTH, r0, angle=ANGLE)
        cut, _ = occ.cut([(3, outer)], [(3, inner)])
        shells.append(cut[0][1])
    # fragment: the layers share their interface surface, so the mesh is conforming across it
    _, children = occ.fragment([(3, shells[0])], [(3, t) for t in shells[1:]])
    occ.synchronize()
    return [c[0][1] for c in children]


def classify_surface(tag):
    """'inner', 'outer', 'end0', 'end1' or None (cut planes, layer interface), from the point at the
    middle of the surface's parameter range: it lies on the underlying plane or cylinder."""
    umin, umax = gmsh.model.getParametrizationBounds(2, tag)
    x, y, z = gmsh.model.getValue(2, tag, [0.5 * (umin[0] + umax[0]), 0.5 * (umin[1] + umax[1])])
    r = math.hypot(x, y)
    for name, hit in [
        ("end0", abs(z) < 1e-9),
        ("end1", abs(z - LENGTH) < 1e-9),
        ("inner", abs(r - RADII[0]) < 1e-9),
        ("outer", abs(r - RADII[-1]) < 1e-9),
    ]:
        if hit:
            return name
    return None


def add_groups(volumes):
    for name, vol in zip(LAYERS, volumes):
        gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, [vol]), name)
    groups = {}
    for dim, tag in gmsh.model.getEntities(2):
        name = classify_surface(tag)
        if name:
            groups.setdefault(name, []).append(tag)
    assert sorted(groups) == ["end0", "end1", "inner", "outer"], groups
    for name in ["inner", "outer", "end0", "end1"]:
        gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, groups[name]), name)


def write(name, version, binary):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(os.path.join(HERE, name))


def layered_tube():
    gmsh.model.add("layered_tube")
    add_groups(layer_volumes())
    # without a minimum, gmsh sizes from the geometry (about 0.3 mm here) and the files double
    gmsh.option.setNumber("Mesh.MeshSizeMin", MESH_SIZE)
    gmsh.option.setNumber("Mesh.MeshSizeMax", MESH_SIZE)
    gmsh.option.setNumber("Mesh.ElementOrder", 2)
    gmsh.option.setNumber("Mesh.SaveAll", 0)  # only elements of physical groups
    gmsh.model.mesh.generate(3)
    write("layered_tube_ascii.msh", 4.1, False)
    write("layered_tube_binary.msh", 4.1, True)


def cube_v22():
    gmsh.model.add("cube")
    gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [1])
    gmsh.option.setNumber("Mesh.MeshSizeMin", 2.0)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 2.0)
    gmsh.option.setNumber("Mesh.ElementOrder", 1)
    gmsh.model.mesh.generate(3)
    write("cube_v22.msh", 2.2, False)


def main():
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    layered_tube()
    cube_v22()
    gmsh.finalize()


if __name__ == "__main__":
    main()
