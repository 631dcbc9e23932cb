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
import difflib
import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np

from .artery_mesh import WallSpec, build_artery
from .centerline_csv import read_centerline_csv
from .errors import PatientInputError
from .placement import Device, place_device, stenosis_site

# key: (kind, default); kind is the expected type; None default = required
KEYS = {
    "centerline": ("path", None),
    "stenosis": ("auto_or_number", "auto"),
    "wall": ("map", {}),
    "mesh": ("map", {}),
    "balloon_spline": ("map", {}),
}
WALL_KEYS = {"thickness": ("from_centerline_or_number", "from_centerline"),
             # thickness / outer diameter; see docs/user-guide.md "Patient-specific arteries" for the source
             "media_ratio": ("fraction", 0.06), "adventitia_ratio": ("fraction", 0.065),
             "min_intima": ("positive", 0.05)}
MESH_KEYS = {"size": ("positive", 0.8), "binary": ("bool", True), "loft_spacing": ("positive", 0.5)}
SPLINE_KEYS = {"smoothing": ("positive", 4.0), "clearance": ("non_negative", 0.0)}


def _check_map(value, spec, where, scene_path):
    if not isinstance(value, dict):
        raise PatientInputError(f"{scene_path}: {where}: expected a map of keys ({', '.join(spec)}), got {value!r}")
    out = {}
    for k in value:
        if k not in spec:
            near = difflib.get_close_matches(str(k), list(spec), n=1)
            hint = f"; did you mean `{near[0]}`?" if near else ""
            raise PatientInputError(f"{scene_path}: {where}.{k}: unknown key, expected one of {', '.join(spec)}{hint}")
    for k, (kind, default) in spec.items():
        if k not in value:
            if default is None:
                raise PatientInputError(f"{scene_path}: {where}.{k}: missing, expected {kind.replace('_', ' ')}")
            out[k] = default
            continue
        v = value[k]
        bad = None
        num = isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
        if kind == "positive" and not (num and v > 0):
            bad = "a positive number"
        elif kind == "non_negative" and not (num and v >= 0):
            bad = "a number >= 0"
        elif kind == "fraction" and not (num and 0 < v < 0.5):
            bad = "a ratio between 0 and 0.5"
        elif kind == "bool" and not isinstance(v, bool):
            bad = "true or false"
        elif kind == "path" and not (isinstance(v, str) and v):
            bad = "a file path"
        elif kind == "auto_or_number" and not (v == "auto" or (num and v >= 0)):
            bad = "auto or an arc length >= 0 (mm)"
        elif kind == "from_centerline_or_number" and not (v == "from_centerline" or (num and v > 0)):
            bad = "from_centerline (the CSV's wall column) or a positive thickness (mm)"
        elif kind == "map" and not isinstance(v, dict):
            bad = "a map"
        if bad:
            raise PatientInputError(f"{scene_path}: {where}.{k}: expected {bad}, got {v!r}")
        out[k] = v
    return out


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
    bm = _section(scene, ["balloon", "mesh"], scene_path, "the balloon tube {generator: tube, length, outer_diameter, ...}")
    for k in ("center", "centerline", "start", "file"):
        if k in bm:
            raise PatientInputError(f"{scene_path}: balloon.mesh.{k}: expected none with a `patient:` section "
                                    f"(the balloon is placed on the fitted centerline, paper §2.4)")
    for k in ("length", "outer_diameter"):
        v = bm.get(k)
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0):
            raise PatientInputError(f"{scene_path}: balloon.mesh.{k}: expected a positive number (mm), got {v!r}")
    g = _section(scene, ["stent", "generator"], scene_path, "a stent generator {type: corrugated_rings, ...}")
    for k in ("centerline", "start"):
        if k in g:
            raise PatientInputError(f"{scene_path}: stent.generator.{k}: expected none with a `patient:` section "
                                    f"(the stent is placed at the stenosis on the balloon centerline)")
    # the generator's defaults (beam_solver StentParameters) for keys the scene leaves out
    rings = g.get("rings", 6)
    pitch = g.get("ring_pitch", 1.5)
    height = g.get("strut_height", 1.5)
    crimped = g.get("crimped_diameter", 1.15)
    sec = scene.get("stent", {}).get("section", {}).get("radius", 0.06)
    for k, v in (("rings", rings), ("ring_pitch", pitch), ("strut_height", height), ("crimped_diameter", crimped)):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool) and v > 0):
            raise PatientInputError(f"{scene_path}: stent.generator.{k}: expected a positive number, got {v!r}")
    stent_length = (rings - 1) * pitch + height
    return Device(balloon_length=float(bm["length"]), balloon_radius=0.5 * float(bm["outer_diameter"]),
                  stent_length=float(stent_length), stent_radius=0.5 * float(crimped) + float(sec))


def _write_points(path, pts, comment):
    with open(path, "w") as f:
        for ln in comment.splitlines():
            f.write(f"# {ln}\n")
        for p in pts:
            f.write(f"{p[0]:.9f} {p[1]:.9f} {p[2]:.9f}\n")


def prepare_scene(scene, scene_path, out_dir, log=print):
    """The completed scene (a new dict) with its generated files in out_dir; PatientInputError on bad input."""
    scene_path = Path(scene_path)
    pat = _check_map(scene.get("patient"), KEYS, "patient", scene_path)
    wall = _check_map(pat["wall"], WALL_KEYS, "patient.wall", scene_path)
    mesh = _check_map(pat["mesh"], MESH_KEYS, "patient.mesh", scene_path)
    spl = _check_map(pat["balloon_spline"], SPLINE_KEYS, "patient.balloon_spline", scene_path)
    artery = _section(scene, ["artery"], scene_path, "an artery section {layers, blood_pressure, ...}")
    if not isinstance(artery, dict):
        raise PatientInputError(f"{scene_path}: artery: expected a map, got {artery!r}")
    if "mesh" in artery:
        raise PatientInputError(f"{scene_path}: artery.mesh: expected none with a `patient:` section "
                                f"(the artery is meshed from patient.centerline)")
    dev = device_of(scene, scene_path)

    csv_path = (scene_path.parent / pat["centerline"]).resolve()
    cl = read_centerline_csv(csv_path)
    if wall["thickness"] == "from_centerline":
        if cl.wall is None:
            raise PatientInputError(f"{scene_path}: patient.wall.thickness: expected a number (mm), as {csv_path} "
                                    f"has no `wall` column (or add the column)")
        wall_t = cl.wall
    else:
        wall_t = np.full(len(cl.radius), float(wall["thickness"]))
    s_site = stenosis_site(cl, None if pat["stenosis"] == "auto" else float(pat["stenosis"]),
                           where=f"{scene_path}: patient.stenosis")
    plc = place_device(cl, dev, s_site, zeta=spl["smoothing"], margin=spl["clearance"])
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    dev_file = out / "device_centerline.txt"
    lumen_file = out / "lumen_centerline.txt"
    _write_points(dev_file, plc.points, f"Balloon and stent centerline fitted to {csv_path} (paper §2.4), x y z mm")
    _write_points(lumen_file, cl.points, f"Lumen centerline of {csv_path}, x y z mm (fiber frames)")
    shutil.copyfile(csv_path, out / "lumen.csv")  # the input as it was (radii for the report)
    spec = WallSpec(media_ratio=wall["media_ratio"], adventitia_ratio=wall["adventitia_ratio"],
                    min_intima=wall["min_intima"])
    msh = out / "artery.msh"
    log(f"patient: stenosis at {s_site:.2f} mm (lumen diameter {2 * plc.site_radius:.3f} mm); balloon clears the "
        f"endothelium by {plc.clearance_balloon:.3f} mm, the crimped stent by {plc.clearance_stent:.3f} mm; meshing "
        f"the artery (size {mesh['size']:g} mm)")
    info = build_artery(cl.points, cl.radius, wall_t, spec, mesh["size"], msh, binary=mesh["binary"],
                        loft_spacing=mesh["loft_spacing"], where=str(csv_path), log=log)
    log(f"patient: artery {info['elements']} tet10, {info['nodes']} nodes ({info['dofs']} DOFs)")

    done = copy.deepcopy(scene)
    del done["patient"]
    _absolute_files(done, scene_path.parent)
    done["artery"]["mesh"] = {"file": str(msh), "inner": "endothelium", "outer": "outer", "ends": ["end0", "end1"],
                              "centerline": {"file": str(lumen_file)}}
    done["balloon"]["mesh"]["centerline"] = {"file": str(dev_file)}
    done["balloon"]["mesh"]["start"] = round(plc.balloon_start, 9)
    done["stent"]["generator"]["centerline"] = {"file": str(dev_file)}
    done["stent"]["generator"]["start"] = round(plc.stent_start, 9)
    report = {"centerline": str(csv_path), "points": int(len(cl.radius)),
              "lumen_length": float(cl.arc_length[-1]),
              "lumen_diameter_range": [float(2 * cl.radius.min()), float(2 * cl.radius.max())],
              "placement": plc.report(), "artery_mesh": info,
              "device": {"balloon_length": dev.balloon_length, "balloon_outer_diameter": 2 * dev.balloon_radius,
                         "stent_length": dev.stent_length, "stent_crimped_outer_diameter": 2 * dev.stent_radius}}
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
    except PatientInputError as e:
        print(f"prepare: error: {e}", file=sys.stderr)
        return 2
    with open(Path(argv[1]) / "scene.yaml", "w") as f:
        yaml.safe_dump(done, f, sort_keys=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
