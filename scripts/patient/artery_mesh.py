"""Three-layer tet10 artery around a lumen centerline, meshed with gmsh (paper §4.2.1).

Wall: the lumen radius r and the total wall thickness per station (the centerline CSV's `wall`
column or one number). Media and adventitia have thicknesses proportional to the outer diameter
D = 2 (r + wall) (paper §4.2.1, after Holzapfel et al. 2005, Am J Physiol Heart 289:H2048); the
rest of the wall is intima. Each interface is a loft (OpenCASCADE ThruSections) through circles in
the normal planes of the centerline stations, or, from a lumen surface, through the surface's true
sections and their radial offsets (periodic splines; lumen_sections.py), with the wall thickness
varying around the vessel where the surface carries it; the four nested solids are fragmented into
conforming layers and the lumen core removed.

Physical groups (the names the solid solver and the scene use): volumes `intima`, `media`,
`adventitia`; surfaces `endothelium` (lumen wall), `outer`, `end0` (first station), `end1`.
"""
import collections
import dataclasses
import itertools
import math
from dataclasses import dataclass

import numpy as np

from . import second_order
from .centerline_csv import arc_length
from .errors import PatientInputError

LAYERS = ("intima", "media", "adventitia")


@dataclass
class WallSpec:
    media_ratio: float  # media thickness / outer diameter
    adventitia_ratio: float  # adventitia thickness / outer diameter
    min_intima: float  # mm: thinner intima is refused (no elements fit in it)


@dataclass
class Refinement:
    """Finer elements where the stresses are read: over the lumen arc lengths s_from..s_to (the
    balloon's span and its margins) the element size is `size`; it grows to the mesh size over
    `transition` mm beyond the outer wall's reach (gmsh Distance + Threshold fields). With `layers`,
    only in those layers (and on their boundaries: the next layer grows from the fine interface)."""

    s_from: float  # mm of lumen arc length
    s_to: float
    size: float  # mm
    transition: float  # mm
    layers: tuple = ()  # volume group names; empty: every layer


def rotation_minimizing_normals(pts):
    """Tangents and first normals along a polyline by the double reflection method (Wang, Jüttler,
    Zheng, Liu 2008, ACM TOG 27(1) 2): circles of successive stations start at corresponding
    points, so the lofted surfaces do not twist."""
    t = np.gradient(pts, axis=0)
    t /= np.linalg.norm(t, axis=1)[:, None]
    ref = np.array([1.0, 0.0, 0.0]) if abs(t[0, 0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    n = np.empty_like(pts)
    n[0] = ref - ref.dot(t[0]) * t[0]
    n[0] /= np.linalg.norm(n[0])
    for i in range(len(pts) - 1):
        v1 = pts[i + 1] - pts[i]
        c1 = v1.dot(v1)
        rL = n[i] - 2.0 / c1 * v1.dot(n[i]) * v1
        tL = t[i] - 2.0 / c1 * v1.dot(t[i]) * v1
        v2 = t[i + 1] - tL
        c2 = v2.dot(v2)
        n[i + 1] = rL - (2.0 / c2 * v2.dot(rL) * v2 if c2 > 1e-300 else 0.0)
        n[i + 1] -= n[i + 1].dot(t[i + 1]) * t[i + 1]
        n[i + 1] /= np.linalg.norm(n[i + 1])
    return t, n


def section_frames(points):
    """(t, n1, n2) per station: the tangent and the rotation-minimizing frame of the sections, angle 0
    along n1 (plaque angles, the lumen sections' rays)."""
    t, n1 = rotation_minimizing_normals(points)
    return t, n1, np.cross(t, n1)


def resample(points, values, spacing):
    """Stations at (about) equal arc-length spacing, values interpolated linearly."""
    s = arc_length(points)
    n = max(int(math.ceil(s[-1] / spacing)), 3) + 1
    si = np.linspace(0.0, s[-1], n)
    P = np.column_stack([np.interp(si, s, points[:, c]) for c in range(3)])
    return si, P, [np.interp(si, s, v) for v in values]


def layer_radii(r, wall, spec, where):
    """Radii of the lumen, intima/media, media/adventitia and outer surfaces per station: (n, 4) from
    one lumen radius and wall per station, or (n, 4, K) from the polar radius and wall along K rays
    of a non-circular section (lumen_sections.py). Media and adventitia keep one thickness per
    station, from the outer diameter of the section's area-equivalent circle (A = 1/2 int rho^2
    dtheta); the intima takes the rest, so an eccentric wall is an eccentric intima."""
    r, wall = np.asarray(r, dtype=float), np.asarray(wall, dtype=float)
    polar = r.ndim == 2
    r_eq = np.sqrt(np.mean(r**2, axis=1)) if polar else r
    D = 2.0 * (r_eq + (wall.mean(axis=1) if polar else wall))
    tm = spec.media_ratio * D
    ta = spec.adventitia_ratio * D
    tm_k, ta_k = (tm[:, None], ta[:, None]) if polar else (tm, ta)
    ti = wall - tm_k - ta_k
    k = int(np.unravel_index(np.argmin(ti), ti.shape)[0])
    if ti.min() < spec.min_intima:
        raise PatientInputError(
            f"{where}: the wall ({wall[k].min():.3f} mm at station {k}) is too thin for media ({tm[k]:.3f} mm) and "
            f"adventitia ({ta[k]:.3f} mm) with an intima of at least {spec.min_intima:g} mm: expected a thicker wall "
            f"or smaller media_ratio/adventitia_ratio"
        )
    return np.stack([r, r + ti, r + ti + tm_k, r + wall], axis=1), ti, tm, ta


def _interp_rows(x, xp, A):
    """A (n, ...) interpolated linearly along its first axis from xp to x."""
    flat = A.reshape(len(xp), -1)
    out = np.column_stack([np.interp(x, xp, flat[:, j]) for j in range(flat.shape[1])])
    return out.reshape((len(x),) + A.shape[1:])


def _polar_at(R, angles):
    """A section's radius at `angles`: R a number (a circle) or K samples at 2 pi k / K (periodic linear)."""
    if np.ndim(R) == 0:
        return np.full(len(angles), float(R))
    K = len(R)
    th = 2.0 * math.pi * np.arange(K + 1) / K
    return np.interp(np.mod(angles, 2.0 * math.pi), th, np.append(R, R[0]))


def _section_curves(occ, center, p, n1, n2, R, a0=0.0, a1=None):
    """The curves of one section around `center` (a point tag at p) in the plane (n1, n2): the closed
    curve of radius R (a number: four circle arcs; K samples: a periodic spline through them), or for
    a1 given the pie slice a0..a1 (lines to the center and the arc or spline between)."""
    closed = a1 is None
    if np.ndim(R) == 0:
        if closed:
            angles = a0 + 0.5 * math.pi * np.arange(4)
        else:  # arcs of at most 90 degrees (OCC's circle arcs must stay below 180)
            angles = np.linspace(a0, a1, max(1, math.ceil((a1 - a0) / (0.5 * math.pi) - 1e-9)) + 1)
    else:
        step = 2.0 * math.pi / len(R)
        angles = (
            a0 + step * np.arange(len(R)) if closed else np.linspace(a0, a1, max(2, math.ceil((a1 - a0) / step)) + 1)
        )
    rad = _polar_at(R, angles)
    q = [occ.addPoint(*(p + rr * (math.cos(a) * n1 + math.sin(a) * n2))) for a, rr in zip(angles, rad)]
    if np.ndim(R) == 0:
        rim = [occ.addCircleArc(q[k], center, q[(k + 1) % len(q)]) for k in range(len(q) if closed else len(q) - 1)]
    else:
        rim = [occ.addSpline(q + [q[0]] if closed else q)]
    return rim if closed else [occ.addLine(center, q[0])] + rim + [occ.addLine(q[-1], center)]


# the seams of the closed sections (where their arcs meet) keep at least this angle from every
# plaque sector's side, else the seam is turned (_seam_angle)
SEAM_CLEARANCE = 15.0  # degrees


def _seam_angle(regions):
    """The angle (degrees) the closed sections of the layers and of the plaque's depth lofts start
    at: 0 unless a plaque sector's side lies within SEAM_CLEARANCE of a seam (the four arcs of a
    circular section meet every 90 degrees), else the angle farthest from every side. A pie side
    lofted along a seam of the layers' lofts meets it at a grazing angle: OpenCASCADE's fragment
    then leaves edges of a micrometre there, which gmsh meshes into slivers (shape quality 1e-5,
    the thin cap over a lipid pool at [90, 270] degrees)."""
    sides = [a % 90.0 for r in regions if not r.full_circle for a in r.angle]

    def clearance(o):
        return min((min(abs(o - a) % 90.0, 90.0 - abs(o - a) % 90.0) for a in sides), default=90.0)

    if clearance(0.0) >= SEAM_CLEARANCE:
        return 0.0
    return max(np.arange(0.0, 90.0, 0.5), key=clearance)


def _plaque_tools(occ, regions, s, P, t, n1, radii, seam=0.0):
    """The OCC solids that carve the plaque regions out of the intima, and for each region which of
    them bound it: one loft per distinct sector (from_s, to_s, angle) through pie slices from the
    centerline (closed sections for a full circle) out past the regions' depths, and one per
    distinct depth bound d (a region's offset > 0, its offset + thickness) over its sector's stretch,
    through closed sections at the lumen radius + d. A region is the intima inside its sector's pie,
    outside its offset's loft and inside its offset + thickness' loft. Regions stacked in depth over
    one sector (a fibrous cap over a lipid pool) thus share the pie's flat sides instead of bringing
    two separately lofted copies of them, which OpenCASCADE's fragment cannot merge on a curved
    centerline (overlapping facets, pieces outside the wall). The pie reaches halfway from the deepest
    bound to the intima's outer surface, or, when a region reaches the intima's outer surface
    (thickness None), out beyond the adventitia, so that its rim coincides with no other surface
    and cuts no layer along its thickness (a rim inside the 0.1-0.2 mm media left bands of half its
    thickness there, meshed into slivers); the pie's pieces outside the wall are dropped. A region alone
    over its sector and at the lumen needs no depth loft: its pie's rim is its depth (a depth loft
    is closed around the vessel and would split the intima where it is thin, e.g. opposite an
    eccentric plaque, into slivers gmsh cannot mesh).
    Returns (solids: list of dimtag lists, of_region: [(pie, inner or None, outer or None)] indices,
    beyond: the indices of the pies that reach outside the wall)."""
    solids, pie_of, depth_of, of_region, beyond = [], {}, {}, [], set()

    def tool(key, index, build):
        if key not in index:
            index[key] = len(solids)
            solids.append([dt for dt in build() if dt[0] == 3])
        return index[key]

    for reg in regions:
        sector = (reg.from_s, reg.to_s, tuple(reg.angle))
        same = [r for r in regions if (r.from_s, r.to_s, tuple(r.angle)) == sector]
        deepest = max((r.offset + r.thickness for r in same if r.thickness is not None), default=0.0)
        to_media = any(r.thickness is None for r in same)

        alone = len(same) == 1 and reg.offset == 0.0

        def rim(lumen, i_out, m_out, a_out, deepest=deepest, to_media=to_media, alone=alone):
            if to_media:
                return a_out + 0.5 * (a_out - m_out)
            return lumen + deepest if alone else 0.5 * (lumen + deepest + i_out)

        pie = tool(sector, pie_of, lambda: _sector_loft(occ, reg, s, P, t, n1, radii, rim))
        if to_media:
            beyond.add(pie)
        if alone:  # the pie's rim is the region's depth: no depth lofts (they would cut the whole ring)
            of_region.append((pie, None, None))
            continue
        bounds = []
        for d in (
            reg.offset if reg.offset > 0.0 else None,
            None if reg.thickness is None else reg.offset + reg.thickness,
        ):
            if d is None:
                bounds.append(None)
                continue
            whole = dataclasses.replace(reg, angle=(seam, seam + 360.0))
            bounds.append(
                tool(
                    (reg.from_s, reg.to_s, d),
                    depth_of,
                    lambda d=d, whole=whole: _sector_loft(
                        occ, whole, s, P, t, n1, radii, lambda lumen, i_out, m_out, a_out: lumen + d
                    ),
                )
            )
        of_region.append((pie, bounds[0], bounds[1]))
    return solids, of_region, beyond


def _sector_loft(occ, reg, s, P, t, n1, radii, radius_of):
    """The loft through the region's sections of radius radius_of(lumen, intima's outer, media's
    outer, adventitia's outer radius) per section: closed curves for a full circle, else pie slices."""
    ss = np.concatenate([[reg.from_s], s[(s > reg.from_s + 1e-6) & (s < reg.to_s - 1e-6)], [reg.to_s]])
    Pk = np.column_stack([np.interp(ss, s, P[:, c]) for c in range(3)])
    tk = np.column_stack([np.interp(ss, s, t[:, c]) for c in range(3)])
    tk /= np.linalg.norm(tk, axis=1)[:, None]
    nk = np.column_stack([np.interp(ss, s, n1[:, c]) for c in range(3)])
    nk -= np.einsum("ij,ij->i", nk, tk)[:, None] * tk
    nk /= np.linalg.norm(nk, axis=1)[:, None]
    bk = np.cross(tk, nk)
    R = radius_of(*(_interp_rows(ss, s, radii[:, j]) for j in range(4)))
    a0, a1 = (math.radians(a) for a in reg.angle)
    wires = []
    for i in range(len(ss)):
        c = occ.addPoint(*Pk[i])
        wires.append(
            occ.addWire(_section_curves(occ, c, Pk[i], nk[i], bk[i], R[i], a0, None if reg.full_circle else a1))
        )
    return occ.addThruSections(wires, makeSolid=True, makeRuled=False)


def section_at(sections, P, t, n1, n2, s, i):
    """The section at station i, sections.sample's (rho, wall, labels); at an end station whose plane
    leaves the surface (a cut end not normal to the centerline, the station within a hair of it), the
    next station's."""
    try:
        return sections.sample(P[i], t[i], n1[i], n2[i], f"s = {s[i]:.2f} mm")
    except PatientInputError:
        if i not in (0, len(P) - 1):
            raise
        j = 1 if i == 0 else len(P) - 2
        return sections.sample(P[j], t[j], n1[j], n2[j], f"s = {s[j]:.2f} mm (for the end at {s[i]:.2f} mm)")


def build_artery(
    points,
    radius,
    wall,
    spec,
    mesh_size,
    out_path,
    binary=False,
    loft_spacing=0.5,
    where="patient",
    log=print,
    plaque=(),
    sections=None,
    refine=None,
):
    """Mesh the artery and write it as gmsh MSH 4.1; returns a dict of mesh facts. `plaque`: the
    regions of the intima with their own volume group (plaque.PlaqueRegion, checked). `sections`: a
    lumen_sections.LumenSections whose true sections replace the circles of `radius` (and whose
    wall-thickness field, if it has one, replaces `wall`). `refine`: a Refinement, or None for one
    size throughout."""
    import gmsh

    groups = list(LAYERS) + sorted({reg.layer for reg in plaque})  # the volume groups the mesh will have
    unknown = sorted(set(refine.layers) - set(groups)) if refine else []
    if unknown:
        raise PatientInputError(
            f"{where}: patient.mesh.refine.layers: unknown layer {unknown[0]!r}, expected some of {', '.join(groups)}"
        )
    s, P, (r, w) = resample(points, [radius, wall], loft_spacing)
    t, n1, n2 = section_frames(P)
    if sections is not None:
        from .lumen_sections import low_pass

        polar = [section_at(sections, P, t, n1, n2, s, i) for i in range(len(P))]
        r = low_pass([p[0] for p in polar])
        w = low_pass([p[1] for p in polar]) if sections.wall_from else np.repeat(w[:, None], r.shape[1], 1)
    radii, ti, tm, ta = layer_radii(r, w, spec, where)
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("artery")
        occ = gmsh.model.occ
        solids = []
        seam = _seam_angle(plaque)
        for layer in range(4):
            wires = []
            for i in range(len(P)):
                c = occ.addPoint(*P[i])
                wires.append(
                    occ.addWire(_section_curves(occ, c, P[i], n1[i], n2[i], radii[i, layer], math.radians(seam)))
                )
            vol = occ.addThruSections(wires, makeSolid=True, makeRuled=False)
            solids.append([dt for dt in vol if dt[0] == 3])
        all_in = [dt for sl in solids for dt in sl]
        tools, tools_of, beyond = _plaque_tools(occ, plaque, s, P, t, n1, radii, seam)
        flat = [(k, dt) for k, sl in enumerate(tools) for dt in sl]
        _, pieces_of = occ.fragment(all_in + [dt for _, dt in flat], [])
        occ.synchronize()
        # a piece inside k of the four nested solids: 4 = lumen core, 3 intima, 2 media, 1 adventitia;
        # an intima piece inside a region's pie, outside its offset's loft and inside its offset +
        # thickness' loft is that region's plaque
        count, inside = {}, {}
        for i, inp in enumerate(pieces_of):
            for dt in inp:
                if i < len(all_in):
                    count[dt] = count.get(dt, 0) + 1
                else:
                    inside.setdefault(dt, set()).add(flat[i - len(all_in)][0])
        region_of = {}
        for dt, tags in inside.items():
            for reg, (pie, inner, outer) in zip(plaque, tools_of):
                if pie in tags and (inner is None or inner not in tags) and (outer is None or outer in tags):
                    region_of[dt] = reg.layer
                    break
        by_layer = {name: [] for name in groups}
        core = []
        for dt, k in count.items():
            if k == 4:
                core.append(dt)
            elif LAYERS[3 - k] == "intima" and dt in region_of:
                by_layer[region_of[dt]].append(dt[1])
            else:
                by_layer[LAYERS[3 - k]].append(dt[1])
        outside = sorted(set(inside) - set(count))
        dropped = [dt for dt in outside if inside[dt] <= beyond]  # pies made to reach beyond the wall
        outside = [dt for dt in outside if dt not in dropped]
        if outside:  # another tool reaching beyond the outer wall: a bug of its radii, not an input error
            c = occ.getCenterOfMass(*outside[0])
            vol = sum(occ.getMass(*dt) for dt in outside)
            raise RuntimeError(
                f"a plaque region reaches outside the wall near ({', '.join(f'{x:.2f}' for x in c)}) mm "
                f"({len(outside)} pieces, {vol:.3g} mm^3)"
            )
        if any(not v for v in by_layer.values()) or not core:
            empty = [name for name, v in by_layer.items() if not v]
            raise RuntimeError(f"gmsh fragment did not give three nested layers and the plaque (empty: {empty})")

        def boundary(v):
            return [tag for d, tag in gmsh.model.getBoundary([(3, v)], oriented=False, combined=False) if d == 2]

        def faces(vols):
            return {tag for v in vols for tag in boundary(v)}

        core_faces = faces([c[1] for c in core])
        f_int, f_med, f_adv = (faces(by_layer[n]) for n in LAYERS)
        f_int |= faces([v for name in groups[len(LAYERS) :] for v in by_layer[name]])  # plaque: the intima's part

        def on_plane(tag, p, normal):
            c = np.array(occ.getCenterOfMass(2, tag))
            return abs((c - p).dot(normal)) < 1e-3 * (1.0 + loft_spacing)

        walls = f_int | f_med | f_adv
        end0 = sorted(f for f in walls if on_plane(f, P[0], t[0]))
        end1 = sorted(f for f in walls if on_plane(f, P[-1], t[-1]))
        endo = sorted((core_faces & f_int) - set(end0) - set(end1))
        # a pie reaching beyond the wall cuts the adventitia into pieces: the faces between two of
        # them bound two wall volumes and are no part of the outer surface
        bounds = collections.Counter(tag for vs in by_layer.values() for v in vs for tag in boundary(v))
        outer = sorted(f for f in f_adv - f_med - set(end0) - set(end1) if bounds[f] == 1)
        occ.remove(core + dropped, recursive=True)
        occ.synchronize()
        for name in groups:
            gmsh.model.setPhysicalName(3, gmsh.model.addPhysicalGroup(3, by_layer[name]), name)
        for name, tags in (("endothelium", endo), ("outer", outer), ("end0", end0), ("end1", end1)):
            if not tags:
                raise RuntimeError(f"no faces found for the surface '{name}'")
            gmsh.model.setPhysicalName(2, gmsh.model.addPhysicalGroup(2, tags), name)
        gmsh.option.setNumber("Mesh.MeshSizeMax", mesh_size)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.2 * (refine.size if refine else mesh_size))
        gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
        gmsh.option.setNumber("Mesh.Algorithm3D", 1)  # Delaunay
        gmsh.option.setNumber("Mesh.Optimize", 1)
        gmsh.option.setNumber("General.NumThreads", 1)
        seeds = []
        if refine:
            volumes = [v for name in refine.layers for v in by_layer[name]]
            seeds = _refinement_field(refine, s, P, radii, mesh_size, volumes)
        gmsh.model.mesh.generate(3)
        if seeds:  # the field's seed points are no part of the artery: their nodes go, the rest renumbered
            gmsh.model.mesh.clear(seeds)
            gmsh.model.mesh.renumberNodes()
        _, off_geometry = second_order.set_order_two()  # tet10 / tri6 on the curved geometry
        if off_geometry:
            log(f"patient: {off_geometry} mid-edge nodes of the boundary left on their chords (no close point found)")
        samples = _jacobian_samples()
        if samples[2].size and samples[2].min() <= 0.0:
            # a mid-edge node pulled onto the curved boundary can invert a thin element: untangle
            # with gmsh's optimizer, and straighten what it leaves inverted
            samples = _optimize_high_order(log)
        straightened, still_inverted, samples = _straighten_inverted(samples)
        if straightened:
            log(
                f"patient: {straightened} tet10 straightened (mid-edge nodes at the edge midpoints) to keep "
                f"every Jacobian positive"
            )
        if still_inverted:
            raise RuntimeError("gmsh produced an inverted tetrahedron")
        quality, where_bad = _min_scaled_jacobian(samples)
        if not quality > 0.0:  # positive at the samples but the corners' tetrahedron inverted: tangled
            raise RuntimeError(
                f"gmsh produced a tangled tet10 near ({', '.join(f'{x:.2f}' for x in where_bad)}) mm (its corner "
                f"tetrahedron inverted, scaled Jacobian {quality:.3g}) {_size_hint(ti, tm, ta, mesh_size)}"
            )
        shape = _shape_quality(samples[4])
        layer_of = {
            int(t): name
            for name in groups
            for v in by_layer[name]
            for tg in gmsh.model.mesh.getElements(3, v)[1]
            for t in tg
        }
        layers_of_samples = np.array([layer_of[int(t)] for t in samples[0]])
        worst = int(np.argmin(shape)) if len(shape) else 0
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
        gmsh.option.setNumber("Mesh.SaveAll", 0)
        gmsh.write(str(out_path))
        types, tags, elem_nodes = gmsh.model.mesh.getElements(3)
        n_tets = sum(len(tg) for tg in tags)
        # the nodes the file holds (of the elements written), not every node gmsh's model has
        node_tags = np.unique(np.concatenate(elem_nodes))
        per_layer = {
            name: sum(len(tg) for v in by_layer[name] for tg in gmsh.model.mesh.getElements(3, v)[1]) for name in groups
        }
        return {
            "file": str(out_path),
            "elements": int(n_tets),
            "nodes": int(len(node_tags)),
            "dofs": 3 * int(len(node_tags)),
            "per_layer": per_layer,
            "mesh_size": mesh_size,
            "refinement": None if refine is None else dataclasses.asdict(refine),
            "straightened_tet10": int(straightened),
            "min_scaled_jacobian": quality,
            # the corner tetrahedra's shape (1 regular, -> 0 flat: slivers), per layer and where worst
            "min_shape_quality": {
                name: float(shape[layers_of_samples == name].min())
                for name in groups
                if (layers_of_samples == name).any()
            },
            "worst_shape": {
                "layer": str(layers_of_samples[worst]) if len(shape) else None,
                "quality": float(shape[worst]) if len(shape) else math.nan,
                "at": [float(x) for x in samples[4][worst].mean(axis=0)] if len(shape) else None,
            },
            "stations": int(len(P)),
            "sections": "circles" if r.ndim == 1 else f"lumen surface, {r.shape[1]} rays",
            "lumen_aspect_max": float(np.max(r.max(axis=1) / r.min(axis=1))) if r.ndim == 2 else 1.0,
            "thickness_range": {
                "intima": [float(ti.min()), float(ti.max())],
                "media": [float(tm.min()), float(tm.max())],
                "adventitia": [float(ta.min()), float(ta.max())],
                "wall": [float(w.min()), float(w.max())],
            },
        }
    except RuntimeError as e:  # the checks above: a geometry that does not give three clean layers
        raise PatientInputError(f"{where}: cannot mesh the artery from this centerline: {e}") from e
    except Exception as e:
        if type(e) is not Exception:  # a bug of ours, not gmsh's verdict on the geometry
            raise
        # gmsh's Python API raises a bare Exception when it cannot build or mesh the geometry
        raise PatientInputError(
            f"{where}: gmsh cannot mesh the artery from this centerline: {' '.join(str(e).split())} "
            f"{_size_hint(ti, tm, ta, mesh_size)}"
        ) from e
    finally:
        gmsh.finalize()


def _refinement_field(refine, s, P, radii, mesh_size, volumes):
    """The background size field of a Refinement: the distance to centerline points of its span
    (spaced at most half the fine size), the fine size out to the outer wall's largest radius in the
    span plus half an element, growing linearly to mesh_size over the transition; restricted to
    `volumes` (and their boundaries) unless empty. Returns the seed points' (dim, tag), to be
    cleared from the mesh after meshing."""
    import gmsh

    occ = gmsh.model.occ
    lo, hi = max(refine.s_from, s[0]), min(refine.s_to, s[-1])
    n = max(int(math.ceil((hi - lo) / (0.5 * refine.size))), 1) + 1
    si = np.linspace(lo, hi, n)
    seeds = [(0, occ.addPoint(*(np.interp(x, s, P[:, c]) for c in range(3)))) for x in si]
    occ.synchronize()
    span = (s >= lo - 1e-9) & (s <= hi + 1e-9)
    outer = radii[:, 3]
    reach = float((outer[span] if span.any() else outer).max()) + 0.5 * refine.size
    field = gmsh.model.mesh.field
    dist = field.add("Distance")
    field.setNumbers(dist, "PointsList", [tag for _, tag in seeds])
    size = field.add("Threshold")
    field.setNumber(size, "InField", dist)
    field.setNumber(size, "SizeMin", refine.size)
    field.setNumber(size, "SizeMax", mesh_size)
    field.setNumber(size, "DistMin", reach)
    field.setNumber(size, "DistMax", reach + refine.transition)
    if volumes:
        where = field.add("Restrict")
        field.setNumber(where, "InField", size)
        faces = gmsh.model.getBoundary([(3, v) for v in volumes], combined=False, oriented=False)
        curves = gmsh.model.getBoundary(faces, combined=False, oriented=False)
        field.setNumbers(where, "VolumesList", volumes)
        field.setNumbers(where, "SurfacesList", sorted({abs(t) for _, t in faces}))
        field.setNumbers(where, "CurvesList", sorted({abs(t) for _, t in curves}))
        size = where
    field.setAsBackgroundMesh(size)
    # the size comes from the field alone: not from the seed points' own size, not extended inward
    # from the (coarse) boundary
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    return seeds


def _size_hint(ti, tm, ta, mesh_size):
    """What to change when gmsh fails: the usual cause is a layer much thinner than the elements, whose
    surface meshes then cross or whose tetrahedra fold."""
    t, name = min((float(np.min(v)), n) for v, n in ((ti, "intima"), (tm, "media"), (ta, "adventitia")))
    return (
        f"(the thinnest layer, the {name}, is {t:.3f} mm against a mesh size of {mesh_size:g} mm: a smaller "
        "patient.mesh.size or a thicker wall may mesh)"
    )


def _jacobian_samples():
    """(element tags, nodes (ne, 10), det J (ne, ns), straight-sided det J (ne,), corners (ne, 4, 3))
    of the tet10 at the samples every validity check uses: the Gauss points and the ten nodes (a
    curved tet10 can fold at a corner while its Gauss points stay positive)."""
    import gmsh

    tags, nodes = gmsh.model.mesh.getElementsByType(11)
    gauss, _ = gmsh.model.mesh.getIntegrationPoints(11, "Gauss4")
    corners = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    mids = np.array([0.5 * (corners[a] + corners[b]) for a, b in TET10_EDGES])
    local = np.concatenate([gauss, corners.ravel(), mids.ravel()])
    _, dets, coords = gmsh.model.mesh.getJacobians(11, local)
    dets = np.asarray(dets).reshape(len(tags), -1)
    ng = len(gauss) // 3
    c = np.asarray(coords).reshape(len(tags), -1, 3)[:, ng : ng + 4]
    straight = np.einsum("ij,ij->i", c[:, 1] - c[:, 0], np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 0]))
    return tags, np.asarray(nodes).reshape(-1, 10), dets, straight, c


def _min_scaled_jacobian(samples):
    """The smallest scaled Jacobian of the tet10: det J at the Gauss points and the ten nodes, over
    det J of the element's straight-sided tet4 (1 for a straight-sided tet10, <= 0 inverted or
    folded; the measure gmsh's high-order optimizer works on), and the centroid of the worst element.
    gmsh 4.8's own quality API has no scaled Jacobian, so it is computed from getJacobians.
    samples: _jacobian_samples() of the mesh as it is."""
    tags, _, dets, straight, c = samples
    if not len(tags):
        return math.nan, np.zeros(3)
    q = dets.min(axis=1) / straight
    k = int(np.argmin(q))
    return float(q[k]), c[k].mean(axis=0)


# Below this shape quality a tetrahedron is a sliver: the shipped patient meshes reach 0.02-0.27
# at worst, a 0.08 mm fibrous cap meshed at 1 mm 0.0001 (its wall's Newton then diverged)
SLIVER_QUALITY = 0.01


def _shape_quality(corners):
    """Shape quality of each element's corner tetrahedron, corners (n, 4, 3): 6 sqrt(2) V / l_rms^3
    (V its volume, l_rms the root mean square of its six edge lengths), 1 for the regular
    tetrahedron and tending to 0 for a flat one (a sliver), whatever its size (Parthasarathy,
    Graichen, Hathaway, Finite Elem Anal Des 15 (1994) 255); negative for an inverted one. The scaled
    Jacobian above measures how curved a tet10 is against its tet4; this measures the tet4 itself."""
    c = np.asarray(corners)
    if not len(c):
        return np.zeros(0)
    volume = np.einsum("ij,ij->i", c[:, 1] - c[:, 0], np.cross(c[:, 2] - c[:, 0], c[:, 3] - c[:, 0])) / 6.0
    l2 = sum(np.sum((c[:, a] - c[:, b]) ** 2, axis=1) for a, b in itertools.combinations(range(4), 2)) / 6.0
    return 6.0 * math.sqrt(2.0) * volume / l2**1.5


# gmsh tet10 mid-edge nodes 4..9 on the edges 01 12 20 30 32 31 (gmsh manual, "Node ordering")
TET10_EDGES = ((0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1))


def _optimize_high_order(log):
    """gmsh's high-order optimizer on the mesh as it is; returns _jacobian_samples() of the result.
    The optimizer also moves corner nodes, and what it does depends on the machine and on gmsh's
    memory layout (reproducible_mesh.py; seen: the same scene meshed valid on one machine and with a
    corner tetrahedron inverted, scaled Jacobian -4.55, on another). Straightening cannot mend an inverted
    corner tetrahedron, so when the optimizer leaves one its result is discarded: every node goes back
    where it was, and _straighten_inverted, valid whenever the tet4 are, takes over."""
    import gmsh

    tags, coords, _ = gmsh.model.mesh.getNodes()
    before = np.asarray(coords).reshape(-1, 3)
    gmsh.option.setNumber("Mesh.HighOrderOptimize", 2)
    try:
        gmsh.model.mesh.optimize("HighOrder")
    except Exception as e:  # gmsh raises a bare Exception when it cannot reach its target
        log(f"patient: gmsh's high-order optimization stopped ({' '.join(str(e).split())})")
    samples = _jacobian_samples()
    folded = int(np.count_nonzero(samples[3] <= 0.0))
    if folded:
        log(
            f"patient: gmsh's high-order optimization inverted {folded} corner tetrahedra: its result "
            f"discarded, the elements it was to untangle straightened instead"
        )
        for tag, x in zip(tags, before):
            gmsh.model.mesh.setNode(int(tag), list(x), [])
        samples = _jacobian_samples()
    return samples


def _straighten_inverted(samples, max_rounds=5):
    """Moves the mid-edge nodes of tet10 with a non-positive Jacobian (at any sample of
    _jacobian_samples; `samples` those of the mesh as it is) to their edge midpoints (a
    straight-sided tet10 is valid whenever its tet4 is); returns (how many elements were changed,
    how many are still inverted after max_rounds, the samples of the mesh as it is then)."""
    import gmsh

    changed = set()
    for round_ in range(max_rounds + 1):
        if round_ > 0:
            samples = _jacobian_samples()
        tags, nodes, dets, _, corner = samples
        bad = np.nonzero(dets.min(axis=1) <= 0.0)[0]
        if not len(bad) or round_ == max_rounds:
            break
        for e in bad:
            changed.add(int(tags[e]))
            for k, (a, b) in enumerate(TET10_EDGES):
                gmsh.model.mesh.setNode(int(nodes[e, 4 + k]), list(0.5 * (corner[e, a] + corner[e, b])), [])
    return len(changed), len(bad), samples
