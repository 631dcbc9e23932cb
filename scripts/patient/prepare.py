"""Turning a scene with a `patient:` section into the scene the solvers read (paper §2.4, §4.2):
the lumen centerline CSV is read and checked, the stenosis site found, the balloon centerline fitted
(placement.py), the three-layer tet10 artery meshed (artery_mesh.py), and the scene completed with
  artery.mesh      = {file: artery.msh, inner: endothelium, outer: outer, ends: [end0, end1],
                      centerline: {file: lumen_centerline.txt}}     (fibers from the lumen centerline)
  balloon.mesh     + {centerline: {file: device_centerline.txt}, start: ...}
  stent.generator  + {centerline: {file: device_centerline.txt}, start: ...}
Relative `file:` paths elsewhere in the scene are made absolute, so the completed scene can live in
the run directory. A placement.json records what was done (spline knots, eq. (3), clearances).

  /usr/bin/python3 -m patient.prepare SCENE OUT_DIR     (from scripts/; the launcher calls prepare_scene)
"""
import copy
import dataclasses
import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np
import insertion_tool
import scene_keys

from .artery_mesh import SLIVER_QUALITY, Refinement, WallSpec, layer_radii, section_at, section_frames
from .centerline_csv import read_centerline_csv, write_centerline_csv, write_points
from .centerline_vtp import read_centerline
from .errors import PatientInputError
from .lumen_centerline import lumen_centerline
from .lumen_sections import LumenSections, inscribed_radius, read_wall_field
from .lumen_surface import read_lumen_surface
from .placement import Device, devices_fit, place_device, stenosis_site
from .plaque import check_within_intima, plaque_materials, read_plaque
from .plaque_labels import check_types, read_labels, regions_from_labels
from .plaque_volume import regions_from_mesh
from .reproducible_mesh import build_artery_reproducibly

# The keys of `patient:` (their types, defaults and ranges) are declared in core/scene/keys.yaml
# and checked by scene_keys.check_map.
# A lesion narrower than a crimped device is opened by the virtual insertion tool (insertion_tool.py)
# during the blood-pressure phase, before t = 0; clearance 0.065 mm and penalty 300 N/mm^3
# (patient.insertion): configs/stability/severe_stenosis_insertion.yaml runs with them.


def _section(scene, path, scene_path, what):
    node = scene
    for k in path:
        if not isinstance(node, dict) or k not in node:
            raise PatientInputError(f"{scene_path}: {'.'.join(path)}: missing, expected {what}")
        node = node[k]
    return node


def _absolute_files(node, base):
    if isinstance(node, dict):
        for k, v in node.items():
            if k == "file" and isinstance(v, str) and not Path(v).is_absolute():
                node[k] = str((base / v).resolve())
            else:
                _absolute_files(v, base)
    elif isinstance(node, list):
        for v in node:
            _absolute_files(v, base)


def device_of(scene, scene_path):
    """Balloon and crimped-stent dimensions from the scene's balloon.mesh and stent sections."""
    bm = _section(
        scene, ["balloon", "mesh"], scene_path, "the balloon tube {generator: tube, length, outer_diameter, ...}"
    )
    for k in ("center", "centerline", "start", "file"):
        if k in bm:
            raise PatientInputError(
                f"{scene_path}: balloon.mesh.{k}: expected none with a `patient:` section "
                f"(the balloon is placed on the fitted centerline, paper §2.4)"
            )
    for k in ("length", "outer_diameter"):
        v = bm.get(k)
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0):
            raise PatientInputError(f"{scene_path}: balloon.mesh.{k}: expected a positive number (mm), got {v!r}")
    g = _section(scene, ["stent", "generator"], scene_path, "a stent generator {type: corrugated_rings, ...}")
    for k in ("centerline", "start"):
        if k in g:
            raise PatientInputError(
                f"{scene_path}: stent.generator.{k}: expected none with a `patient:` section "
                f"(the stent is placed at the stenosis on the balloon centerline)"
            )
    # the generator's declared defaults for the keys the scene leaves out
    rings, pitch, height, crimped = (
        g.get(k, scene_keys.default(f"stent.generator.{k}"))
        for k in ("rings", "ring_pitch", "strut_height", "crimped_diameter")
    )
    for k, v in (("rings", rings), ("ring_pitch", pitch), ("strut_height", height), ("crimped_diameter", crimped)):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0):
            raise PatientInputError(f"{scene_path}: stent.generator.{k}: expected a positive number, got {v!r}")
    section = (scene.get("stent") or {}).get("section") or {}
    sec = section.get("contact_radius", section.get("radius"))
    if not (isinstance(sec, (int, float)) and not isinstance(sec, bool) and sec > 0):
        raise PatientInputError(
            f"{scene_path}: stent.section.radius: expected a positive number (mm), the strut radius that sizes "
            f"the crimped stent (or stent.section.contact_radius), got {sec!r}"
        )
    stent_length = (rings - 1) * pitch + height
    return Device(
        balloon_length=float(bm["length"]),
        balloon_radius=0.5 * float(bm["outer_diameter"]),
        stent_length=float(stent_length),
        stent_radius=insertion_tool.crimped_stent_radius(scene["stent"]),
    )


def add_insertion(done, plc, dev, ins, scene_path):
    """Completes `done` with the virtual insertion of a lesion narrower than the devices: the tool's
    radius curve, contact.insertion and the artery contacts' switch-on time. Returns its report."""
    time = done.get("time") if isinstance(done.get("time"), dict) else {}
    start, end = time.get("start", 0.0), time.get("end")
    tight = (
        f"the lesion (axis {plc.axis_clearance:.3f} mm from the endothelium at the narrowest) is narrower "
        f"than the crimped devices (outer radius {max(dev.stent_radius, dev.balloon_radius):.3f} mm)"
    )
    if not (isinstance(start, (int, float)) and start < 0):
        raise PatientInputError(
            f"{scene_path}: time.start: expected a phase before the inflation (time.start < 0 s, "
            f"e.g. -0.2) in which the virtual insertion tool opens the lumen: {tight}"
        )
    curves = done.get("load_curves") or {}
    bp = done.get("balloon", {}).get("pressure", {})
    bcurve = curves.get(bp.get("curve")) if isinstance(bp, dict) else None
    if bcurve and insertion_tool.quiet_until(bcurve, start) < 0.0:
        raise PatientInputError(
            f"{scene_path}: load_curves.{bp.get('curve')}: expected no balloon pressure before "
            f"t = 0 (the virtual insertion opens the lumen then): {tight}"
        )
    contact = done.setdefault("contact", {})
    if "insertion" in contact:  # the scene's own tool
        return {"tool": "the scene's contact.insertion"}
    if insertion_tool.CURVE in curves:
        raise PatientInputError(
            f"{scene_path}: load_curves.{insertion_tool.CURVE}: expected no curve of this name "
            f"(the patient pipeline writes the insertion tool's radius under it)"
        )
    r0 = insertion_tool.START_FRACTION * plc.axis_clearance  # inside the lumen everywhere along the axis
    r_open = max(dev.stent_radius, dev.balloon_radius) + ins["clearance"]
    t_end = end if isinstance(end, (int, float)) and end > 0 else None
    return insertion_tool.add_tool(done, float(start), 0.0, r0, r_open, ins["penalty"], t_end=t_end)


def lumen_csv(pat, scene_path, out_dir, log):
    """(CSV, sections, plaque labels' spec) of the scene: patient.centerline as given (a VTP written as
    out_dir/lumen_from_centerline.csv); or, with
    patient.lumen_surface, a CSV in out_dir/lumen_from_surface.csv (the centerline computed from the
    surface, or the given one, with the area-equivalent radius of the surface's sections), the
    surface's true sections (lumen_sections.LumenSections, None for circles) and the checked
    patient.lumen_surface.plaque (None without)."""
    if not pat["centerline"] and not pat["lumen_surface"]:
        raise PatientInputError(
            f"{scene_path}: patient: expected centerline (a CSV or VTP), lumen_surface ({{file, units}}), or both (the "
            "CSV's centerline through the surface's sections), got neither"
        )
    if not pat["lumen_surface"]:
        given = (scene_path.parent / pat["centerline"]).resolve()
        if given.suffix.lower() != ".vtp":
            return given, None, None
        cl = read_centerline(given)  # VTK PolyData (VMTK, SimVascular): written as our CSV
        out = out_dir / "lumen_from_centerline.csv"
        write_centerline_csv(out, cl.points, cl.radius, wall=cl.wall, comment=f"centerline of {given}")
        return out, None, None
    spec = scene_keys.check_map(pat["lumen_surface"], "patient.lumen_surface", scene_path, PatientInputError)
    path = (scene_path.parent / spec["file"]).resolve()
    surface = read_lumen_surface(str(path), spec["units"])
    out = out_dir / "lumen_from_surface.csv"
    if pat["centerline"]:  # the given centerline; its radius from the surface (sqrt(A / pi) of each section)
        csv = (scene_path.parent / pat["centerline"]).resolve()
        given = read_centerline(csv)
        points, wall = given.points, given.wall
        t, n1, n2 = section_frames(points)
        s = given.arc_length
        plain = LumenSections(surface)
        rho = [section_at(plain, points, t, n1, n2, s, i)[0] for i in range(len(s))]
        radius = np.sqrt(np.mean(np.square(rho), axis=1))
        comment = f"centerline of {csv} with the equivalent radius of the sections of {path}"
    else:
        points, radius = lumen_centerline(surface, spacing=spec["spacing"])
        wall, comment = None, f"lumen centerline of {path} (scripts/patient/lumen_centerline.py)"
    write_centerline_csv(out, points, radius, wall=wall, comment=comment)
    log(f"patient: lumen surface {path.name}: {len(surface.triangles)} triangles -> {len(points)} centerline stations")
    thickness = (pat["wall"] or {}).get("thickness")
    if thickness == "from_outer_surface" and not pat["outer_surface"]:
        raise PatientInputError(
            f"{scene_path}: patient.wall.thickness: from_outer_surface needs patient.outer_surface ({{file, units}})"
        )
    key = "patient.lumen_surface.plaque"
    plaque = scene_keys.check_map(spec["plaque"], key, scene_path, PatientInputError) if spec["plaque"] else None
    if spec["sections"] == "circles":
        if thickness in ("from_surface", "from_outer_surface"):
            raise PatientInputError(
                f"{scene_path}: patient.wall.thickness: {thickness} needs patient.lumen_surface.sections: surface"
            )
        if plaque:
            raise PatientInputError(f"{scene_path}: {key}: needs patient.lumen_surface.sections: surface")
        return out, None, None
    labels = None
    if plaque:
        check_types(plaque["types"], f"{scene_path}: {key}")
        labels = read_labels(str(path), surface, plaque["array"])
    wall = {}
    if thickness == "from_surface":
        wall["field"] = read_wall_field(str(path), surface, spec["wall_array"])
    elif thickness == "from_outer_surface":
        o = scene_keys.check_map(pat["outer_surface"], "patient.outer_surface", scene_path, PatientInputError)
        wall["outer"] = LumenSections(read_lumen_surface(str((scene_path.parent / o["file"]).resolve()), o["units"]))
    return out, LumenSections(surface, labels=labels, **wall), plaque


def station_sections(cl, sections):
    """Per centerline station of cl, in the loft's frames: the sections' polar lumen radius (n, K),
    wall (n, K) and labels (n, K) (each None where the sections have none), and the clearance radius (n,)."""
    t, n1, n2 = section_frames(cl.points)
    s = cl.arc_length
    got = [section_at(sections, cl.points, t, n1, n2, s, i) for i in range(len(s))]
    rho, wall, labels = (None if got[0][k] is None else np.array([g[k] for g in got]) for k in range(3))
    return rho, wall, labels, np.array([inscribed_radius(r) for r in rho])


def refinement_of(mesh, plc, scene_path):
    """The artery's Refinement from patient.mesh (checked), over the placed balloon's span on the
    lumen centerline and the margin each side; None without patient.mesh.refine."""
    if mesh["refine"] is None:
        return None
    key = "patient.mesh.refine"
    ref = scene_keys.check_map(mesh["refine"], key, scene_path, PatientInputError)
    if ref["size"] >= mesh["size"]:
        raise PatientInputError(
            f"{scene_path}: {key}.size: expected a size below patient.mesh.size ({mesh['size']:g} mm), "
            f"got {ref['size']:g}"
        )
    layers = ref["layers"] or []
    if not all(isinstance(x, str) for x in layers):
        raise PatientInputError(f"{scene_path}: {key}.layers: expected a list of layer names, got {layers!r:.60}")
    return Refinement(
        s_from=plc.s0 - ref["margin"],
        s_to=plc.s1 + ref["margin"],
        size=ref["size"],
        transition=ref["transition"],
        layers=tuple(layers),
    )


def prepare_scene(scene, scene_path, out_dir, log=print):
    """The completed scene (a new dict) with its generated files in out_dir; PatientInputError on bad input."""
    scene_path = Path(scene_path)
    pat = scene_keys.check_map(scene.get("patient"), "patient", scene_path, PatientInputError)
    wall, mesh, spl, ins = (
        scene_keys.check_map(pat[k] or {}, f"patient.{k}", scene_path, PatientInputError)
        for k in ("wall", "mesh", "balloon_spline", "insertion")
    )
    artery = _section(scene, ["artery"], scene_path, "an artery section {layers, blood_pressure, ...}")
    if not isinstance(artery, dict):
        raise PatientInputError(f"{scene_path}: artery: expected a map, got {artery!r}")
    if "mesh" in artery:
        raise PatientInputError(
            f"{scene_path}: artery.mesh: expected none with a `patient:` section "
            f"(the artery is meshed from patient.centerline)"
        )
    dev = device_of(scene, scene_path)

    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)  # a procedure's check prepares into a fresh scratch directory
    csv_path, sections, label_spec = lumen_csv(pat, scene_path, out, log)
    cl = read_centerline_csv(csv_path)
    if wall["thickness"] in ("from_surface", "from_outer_surface") and not pat["lumen_surface"]:
        raise PatientInputError(
            f"{scene_path}: patient.wall.thickness: {wall['thickness']} needs patient.lumen_surface (the wall is "
            "read on the lumen surface's sections); with a centerline CSV use from_centerline or a number"
        )
    if pat["outer_surface"] and wall["thickness"] != "from_outer_surface":
        raise PatientInputError(
            f"{scene_path}: patient.outer_surface: expected patient.wall.thickness: from_outer_surface with it, got "
            f"{wall['thickness']!r}"
        )
    if wall["thickness"] == "from_centerline":
        if pat["lumen_surface"] and not pat["centerline"]:
            raise PatientInputError(
                f"{scene_path}: patient.wall.thickness: expected a number (mm), from_surface or from_outer_surface "
                "with patient.lumen_surface and no centerline CSV"
            )
        if cl.wall is None:
            raise PatientInputError(
                f"{scene_path}: patient.wall.thickness: expected a number (mm), as {csv_path} "
                f"has no `wall` column (or add the column)"
            )
        wall_t = cl.wall
    elif wall["thickness"] in ("from_surface", "from_outer_surface"):
        wall_t = None  # per ray, from the sections (below)
    else:
        wall_t = np.full(len(cl.radius), float(wall["thickness"]))
    # the lumen and wall per station as the mesh will have them: the true sections (n, K) when the
    # surface gives them; the devices must then clear the largest circle inside each section
    # around its centerline point, not the area-equivalent one
    r_lumen, w_lumen, cl_fit, from_labels = cl.radius, wall_t, cl, []
    if sections is not None:
        r_lumen, field, labels, r_clear = station_sections(cl, sections)
        if label_spec:
            key = f"{scene_path}: patient.lumen_surface.plaque"
            from_labels = regions_from_labels(labels, cl.arc_length, label_spec["types"], label_spec["thickness"], key)
        w_lumen = field if field is not None else np.repeat(wall_t[:, None], r_lumen.shape[1], 1)
        if wall_t is None:
            wall_t = w_lumen.mean(axis=1)
        cl_fit = dataclasses.replace(cl, radius=r_clear)
    s_site = stenosis_site(
        cl, None if pat["stenosis"] == "auto" else float(pat["stenosis"]), where=f"{scene_path}: patient.stenosis"
    )
    insertion = ins["mode"] == "auto" and not devices_fit(cl_fit, dev, s_site, margin=spl["clearance"])
    plc = place_device(cl_fit, dev, s_site, zeta=spl["smoothing"], margin=spl["clearance"], insertion=insertion)
    dev_file = out / "device_centerline.txt"
    lumen_file = out / "lumen_centerline.txt"
    spec = WallSpec(
        media_ratio=wall["media_ratio"], adventitia_ratio=wall["adventitia_ratio"], min_intima=wall["min_intima"]
    )
    _, intima, _, _ = layer_radii(r_lumen, w_lumen, spec, str(csv_path))  # per station, or station and ray
    if from_labels:
        log(f"patient: {len(from_labels)} plaque regions from the surface's labels")
    if pat["plaque_mesh"]:
        key = "patient.plaque_mesh"
        pm = scene_keys.check_map(pat["plaque_mesh"], key, scene_path, PatientInputError)
        pm["file"] = str((scene_path.parent / pm["file"]).resolve())
        from_mesh = regions_from_mesh(pm, cl, r_lumen, intima, f"{scene_path}: {key}")
        log(f"patient: {len(from_mesh)} plaque regions from the labels of {Path(pm['file']).name}")
        from_labels = from_labels + from_mesh
    plaque = read_plaque((pat["plaque"] or []) + from_labels, float(cl.arc_length[-1]), scene_path)
    if plaque:
        check_within_intima(plaque, cl.arc_length, intima, scene_path)
    layers = artery.get("layers")
    if not isinstance(layers, dict):
        raise PatientInputError(
            f"{scene_path}: artery.layers: expected a map layer name -> material, got {layers!r:.60}"
        )
    msh = out / "artery.msh"
    done = copy.deepcopy(scene)
    done["artery"]["layers"].update(plaque_materials(plaque, layers, scene_path))
    del done["patient"]
    _absolute_files(done, scene_path.parent)
    done["artery"]["mesh"] = {
        "file": str(msh),
        "inner": "endothelium",
        "outer": "outer",
        "ends": ["end0", "end1"],
        "centerline": {"file": str(lumen_file)},
    }
    done["balloon"]["mesh"]["centerline"] = {"file": str(dev_file)}
    done["balloon"]["mesh"]["start"] = round(plc.balloon_start, 9)
    done["stent"]["generator"]["centerline"] = {"file": str(dev_file)}
    done["stent"]["generator"]["start"] = round(plc.stent_start, 9)
    ins_report = add_insertion(done, plc, dev, ins, scene_path) if insertion else None
    if insertion:
        # the tool stretches the innermost layer most: elements larger than it is thick invert there
        # (measured on the CI lesion, a 0.94 mm lumen in a 1.0 mm wall with a 0.63 mm intima: mesh.size
        # 1.0 stops where the artery contacts switch on, 0.5 runs)
        k = int(np.argmin(np.abs(cl.arc_length - s_site)))
        ti = intima if intima.ndim == 1 else intima.min(axis=1)
        if mesh["size"] > ti[k]:
            log(
                f"patient: warning: patient.mesh.size {mesh['size']:g} mm is larger than the intima at the lesion "
                f"({ti[k]:.3f} mm) that the virtual insertion stretches: elements may invert while it opens the "
                f"lumen; a size below {ti[k]:.2f} mm is safer"
            )
    out.mkdir(parents=True, exist_ok=True)
    write_points(dev_file, plc.points, f"Balloon and stent centerline fitted to {csv_path} (paper §2.4), x y z mm")
    write_points(lumen_file, cl.points, f"Lumen centerline of {csv_path}, x y z mm (fiber frames)")
    shutil.copyfile(csv_path, out / "lumen.csv")  # the input as it was (radii for the report)
    fit = (
        "the crimped devices overlap the wall by up to "
        f"{-min(plc.clearance_balloon, plc.clearance_stent):.3f} mm: a virtual insertion opens the lumen first"
        if insertion
        else f"balloon clears the endothelium by {plc.clearance_balloon:.3f} mm, the crimped stent by "
        f"{plc.clearance_stent:.3f} mm"
    )
    log(
        f"patient: stenosis at {s_site:.2f} mm (lumen diameter {2 * np.interp(s_site, cl.arc_length, cl.radius):.3f} mm"
        f"{f', inscribed {2 * plc.site_radius:.3f} mm' if sections is not None else ''}); {fit}; meshing "
        f"the artery (size {mesh['size']:g} mm)"
    )
    refine = refinement_of(mesh, plc, scene_path)
    if refine:
        log(
            f"patient: elements of {refine.size:g} mm over s = {refine.s_from:.2f} .. {refine.s_to:.2f} mm (the "
            f"balloon and its margins){' in ' + ', '.join(refine.layers) if refine.layers else ''}, "
            f"{mesh['size']:g} mm elsewhere"
        )
    info = build_artery_reproducibly(
        cl.points,
        cl.radius,
        wall_t,
        spec,
        mesh["size"],
        msh,
        binary=mesh["binary"],
        loft_spacing=mesh["loft_spacing"],
        where=str(csv_path),
        log=log,
        plaque=plaque,
        sections=sections,
        refine=refine,
    )
    log(
        f"patient: artery {info['elements']} tet10, {info['nodes']} nodes ({info['dofs']} DOFs), minimal scaled "
        f"Jacobian {info['min_scaled_jacobian']:.3f}"
    )
    worst = info["worst_shape"]
    if worst["quality"] < SLIVER_QUALITY:
        log(
            f"patient: warning: slivers in the artery mesh: the flattest tetrahedron, in {worst['layer']} at "
            f"({', '.join(f'{x:.2f}' for x in worst['at'])}) mm, has a shape quality of {worst['quality']:.2g} "
            f"(1 regular, below {SLIVER_QUALITY} flat; per layer in placement.json, artery_mesh.min_shape_quality): "
            "the wall's Newton may fail there; a smaller patient.mesh.size, or patient.mesh.refine over that layer"
        )
    report = {
        "centerline": str(csv_path),
        "points": int(len(cl.radius)),
        "lumen_length": float(cl.arc_length[-1]),
        "lumen_diameter_range": [float(2 * cl.radius.min()), float(2 * cl.radius.max())],
        "lumen_sections": (
            None
            if sections is None
            else {
                "rays": int(r_lumen.shape[1]),
                "inscribed_diameter_range": [float(2 * cl_fit.radius.min()), float(2 * cl_fit.radius.max())],
                "aspect_max": float(np.max(r_lumen.max(axis=1) / r_lumen.min(axis=1))),
                "wall_range": [float(w_lumen.min()), float(w_lumen.max())],
                "wall_from": sections.wall_from or "patient.wall.thickness",
            }
        ),
        "placement": plc.report(),  # with sections, its lumen_diameter is the inscribed one (what the devices clear)
        "insertion": ins_report,
        "artery_mesh": info,
        "plaque": [
            {
                "layer": r.layer,
                "from_s": r.from_s,
                "to_s": r.to_s,
                "angle": list(r.angle),
                "offset": r.offset,
                "thickness": r.thickness if r.thickness is not None else "intima",
                "material": done["artery"]["layers"][r.layer],
            }
            for r in plaque
        ],
        "device": {
            "balloon_length": dev.balloon_length,
            "balloon_outer_diameter": 2 * dev.balloon_radius,
            "stent_length": dev.stent_length,
            "stent_crimped_outer_diameter": 2 * dev.stent_radius,
        },
    }
    with open(out / "placement.json", "w") as f:
        json.dump(report, f, indent=2)
    return done, report


def main(argv=None):
    import yaml

    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    scene_path = Path(argv[0]).resolve()
    try:
        with open(scene_path) as f:
            scene = yaml.safe_load(f)
        done, _ = prepare_scene(scene, scene_path, argv[1])
    except (PatientInputError, OSError, yaml.YAMLError) as e:
        print(f"prepare: error: {e}", file=sys.stderr)
        return 2
    with open(Path(argv[1]) / "scene.yaml", "w") as f:
        yaml.safe_dump(done, f, sort_keys=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
