"""A procedure of phases in one scene: predilatation, stenting, post-dilatation (or any sequence).

A scene with a `procedure:` list runs one phase after the other on one time axis, each phase a
run of the launcher in <run>/<k>-<name>/. The artery carries over from phase to phase (its
displacement and viscous history: `solid.initial_state` with parts [artery] from the previous
phase's solid/state.h5), the stent from the phase that deploys it on (its positions, rotations and
plastic strains: `stent.initial_state`); each phase brings its own balloon (`balloon:` of the phase,
else the scene's), which starts crimped and is gone in the next phase.

    procedure:
      - {name: predilatation, end: 2.0, steps: 40, balloon: {...}}          # no stent yet
      - {name: stenting, end: 4.0, steps: 60, stent: true}                   # the scene's stent and balloon
      - {name: postdilatation, end: 6.0, steps: 40, balloon: {...}}         # the stent stays

The first phase starts at time.start; each later one where the one before ended. Load curves are in
that one time axis. `time:` keeps its other keys (min_step, max_cuts, adaptive); its `end` and
`steps` are per phase. Devices are placed where the scene places them (on the vessel axis; in a
patient scene the pipeline places the stent and the scene's balloon at the stenosis and each phase's
balloon on the same device centerline); in a patient procedure each phase after the first places
its devices on the lumen the phase before left (deformed_placement), the stent as deployed once it
is; in a generated tube they stay on its axis (a concentric dilatation does not move it).

A phase whose crimped devices (its balloon; the stent in the phase that deploys it) are wider than
the lumen under them plus `procedure[k].insertion.clearance` opens the lumen first with the virtual
insertion tool (insertion_tool.py, `mode: auto`, the default): the lumen is the one the phase
starts from (the end of the phase before; for the first phase the reference mesh's, measured by
the solid alone in <run>/0-lumen/), and the tool works while the phase's balloon pressure is still
0 at its start (the pressure curve must leave that time: an error naming the curve otherwise).

After the last phase (or a failed one) <run>/procedure.json holds per phase: status, wall time,
steps, and the quantities interventional studies report (minimal lumen diameter and area at the
phase's peak balloon pressure and at its end, lumen gain against the lumen before the procedure,
acute recoil, stent diameter, malapposed fraction, per-layer stress maxima at peak and end), and
lumen_profiles.png the lumen diameter along the vessel before the procedure and after each phase.
"""
import copy
import json
import math
import re
import subprocess
import sys
import tempfile
import time as clock
from pathlib import Path

import yaml

import insertion_tool
import scene_keys

ROOT = Path(__file__).resolve().parent.parent
LAUNCH = ROOT / "scripts" / "launch.py"
PHASE_KEYS = tuple(scene_keys.children("procedure[0]"))
NAME = re.compile(r"[A-Za-z0-9_-]{1,40}")
STENT_CONTACTS = ("stent_balloon", "stent_artery")


class ProcedureError(Exception):
    """Bad input of the procedure: the message names the file and the key."""


def _number(v):
    return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)


def phases(scene, path):
    """The phases of `procedure:` with their time windows: [{name, start, end, steps, balloon, stent}].
    Raises ProcedureError naming the key."""
    proc = scene.get("procedure")
    if not isinstance(proc, list) or not proc:
        raise ProcedureError(f"{path}: procedure: expected a non-empty list of phases, got {proc!r:.60}")
    if "artery" not in scene:
        raise ProcedureError(
            f"{path}: procedure: expected an `artery:` section (the procedure carries the artery "
            "from phase to phase), got none"
        )
    t = scene.get("time") or {}
    if not isinstance(t, dict):
        raise ProcedureError(f"{path}: time: expected a map, got {t!r:.60}")
    for k in ("end", "steps"):
        if k in t:
            raise ProcedureError(
                f"{path}: time.{k}: expected it per phase (procedure[k].{k}) in a procedure, " "got it in `time:`"
            )
    start = t.get("start", 0.0)
    if not _number(start):
        raise ProcedureError(f"{path}: time.start: expected a number, got {start!r:.60}")
    out, names, stent_on = [], set(), False
    for k, ph in enumerate(proc):
        key = f"procedure[{k}]"
        if not isinstance(ph, dict):
            raise ProcedureError(f"{path}: {key}: expected a map {{name, end, steps, balloon, stent}}, got {ph!r:.60}")
        for x in ph:
            if x not in PHASE_KEYS:
                raise ProcedureError(f"{path}: {key}.{x}: expected one of {', '.join(PHASE_KEYS)}, got an unknown key")
        name = ph.get("name")
        if not isinstance(name, str) or not NAME.fullmatch(name):
            raise ProcedureError(f"{path}: {key}.name: expected 1 to 40 of A-Z a-z 0-9 _ -, got {name!r:.60}")
        if name in names:
            raise ProcedureError(f"{path}: {key}.name: expected a name not used by an earlier phase, got {name!r}")
        names.add(name)
        end = ph.get("end")
        if not _number(end) or not end > start:
            raise ProcedureError(
                f"{path}: {key}.end: expected a time after the phase's start {start} s (phases "
                f"follow each other without overlap or gap), got {end!r:.60}"
            )
        steps = ph.get("steps")
        if not isinstance(steps, int) or isinstance(steps, bool) or not 1 <= steps <= 100000:
            raise ProcedureError(
                f"{path}: {key}.steps: expected a number of load steps from 1 to 100000, " f"got {steps!r:.60}"
            )
        stent = ph.get("stent", stent_on)
        if not isinstance(stent, bool):
            raise ProcedureError(f"{path}: {key}.stent: expected true or false, got {stent!r:.60}")
        if stent_on and not stent:
            raise ProcedureError(f"{path}: {key}.stent: expected true (the stent stays once deployed), got false")
        if stent and "stent" not in scene:
            raise ProcedureError(f"{path}: {key}.stent: expected a `stent:` section in the scene to deploy, got none")
        balloon = ph.get("balloon", scene.get("balloon"))
        if balloon is not None and not isinstance(balloon, dict):
            raise ProcedureError(f"{path}: {key}.balloon: expected a balloon section (a map), got {balloon!r:.60}")
        ext = balloon_extent(balloon, scene["artery"]) if balloon is not None else None
        half = 0.5 * float(scene["artery"]["mesh"].get("length", 0.0)) if ext else 0.0
        if ext and (ext[0] < -half - 1e-9 or ext[1] > half + 1e-9):
            where = f"{key}.balloon.mesh" if "balloon" in ph else "balloon.mesh"
            raise ProcedureError(
                f"{path}: {where}: expected a balloon within the artery (axially {-half:g} to {half:g} mm "
                f"from its centre), got {ext[0]:g} to {ext[1]:g} mm"
            )
        insertion = scene_keys.check_map(
            ph.get("insertion", {}), f"{key}.insertion", path, ProcedureError
        )  # declared defaults: mode auto
        out.append(
            {
                "name": name,
                "start": float(start),
                "end": float(end),
                "steps": steps,
                "balloon": balloon,
                "stent": stent,
                "new_stent": stent and not stent_on,
                "insertion": insertion,
            }
        )
        start, stent_on = end, stent
    return out


def complete(scene, path, out_dir, log=print):
    """A patient procedure (`patient:` with `procedure:`): the scene completed by the patient pipeline
    into out_dir (the artery meshed from the lumen centerline, the stent and the scene's balloon placed
    at the stenosis, the virtual insertion where the lesion is narrower than the devices), and each
    phase's own balloon placed on the same device centerline, centred where the scene's balloon is.
    Returns (scene, placement): for a patient procedure what later phases are placed with on the
    deformed lumen ({s_site, stent_length, stent_radius, zeta, margin}), else None with the scene
    unchanged. Raises ProcedureError naming the key."""
    if insertion_tool.CURVE in (scene.get("load_curves") or {}):
        raise ProcedureError(
            f"{path}: load_curves.{insertion_tool.CURVE}: expected no curve of this name (the procedure "
            "writes the virtual insertion tool's radius under it)"
        )
    if "patient" not in scene:
        return scene, None
    sys.path.insert(0, str(ROOT / "scripts"))
    import numpy as np
    from patient.centerline_csv import arc_length
    from patient.errors import PatientInputError
    from patient.prepare import prepare_scene

    try:
        done, report = prepare_scene(
            _first_tool_in_patient(scene, path), path, out_dir, log=lambda m: log(f"procedure: {m}")
        )
    except PatientInputError as e:
        raise ProcedureError(str(e))
    done["procedure"] = copy.deepcopy(scene["procedure"])
    base = done["balloon"]["mesh"]
    length = float(arc_length(np.loadtxt(base["centerline"]["file"]))[-1])  # the file the pipeline wrote
    centre = base["start"] + 0.5 * float(base["length"])
    for k, ph in enumerate(done["procedure"]):
        m = ph.get("balloon", {}).get("mesh") if isinstance(ph, dict) and isinstance(ph.get("balloon"), dict) else None
        if not isinstance(m, dict):
            continue
        key = f"procedure[{k}].balloon.mesh"
        for x in ("center", "centerline", "start", "file"):
            if x in m:
                raise ProcedureError(
                    f"{path}: {key}.{x}: expected none with a `patient:` section (the phase's balloon "
                    "is placed on the device centerline at the stenosis)"
                )
        L = m.get("length")
        if not _number(L) or L <= 0:
            raise ProcedureError(f"{path}: {key}.length: expected a positive length (mm), got {L!r:.60}")
        start = centre - 0.5 * L
        if start < -1e-9 or start + L > length + 1e-9:
            raise ProcedureError(
                f"{path}: {key}.length: expected a balloon that fits on the device centerline "
                f"({length:.2f} mm) centred on the scene's balloon at {centre:.2f} mm, got {L} mm"
            )
        m["centerline"] = copy.deepcopy(base["centerline"])
        m["start"] = round(max(start, 0.0), 9)
    spline = (scene["patient"].get("balloon_spline") or {}) if isinstance(scene["patient"], dict) else {}
    placement = {
        "s_site": report["placement"]["stenosis"]["arc_length"],
        "stent_length": report["device"]["stent_length"],
        "stent_radius": 0.5 * report["device"]["stent_crimped_outer_diameter"],
        "zeta": spline.get("smoothing", scene_keys.default("patient.balloon_spline.smoothing")),
        "margin": spline.get("clearance", scene_keys.default("patient.balloon_spline.clearance")),
        # the scene's balloon's centre in the lumen stations (arc length along the lumen centerline),
        # where the first phase's balloon is centred too
        "balloon_centre_station": 0.5 * sum(report["placement"]["balloon_ends_lumen_arc_length"]),
    }
    return done, placement


def _first_tool_in_patient(scene, path):
    """The scene without its procedure, for the patient pipeline, whose tool serves the first phase:
    the first phase's own insertion keys go to patient.insertion (they would be ignored otherwise); a
    key set differently in both places is refused."""
    out = {k: v for k, v in scene.items() if k != "procedure"}
    proc = scene.get("procedure")
    first = proc[0] if isinstance(proc, list) and proc else None  # a bad list: named by phases()
    own = first.get("insertion") if isinstance(first, dict) else None
    if not isinstance(own, dict) or not own or not isinstance(scene.get("patient"), dict):
        return out
    scene_keys.check_map(own, "procedure[0].insertion", path, ProcedureError)  # named as written
    pat = scene["patient"].get("insertion") or {}
    if not isinstance(pat, dict):
        return out  # the pipeline's own check names patient.insertion
    for k, v in own.items():
        if k in pat and pat[k] != v:
            raise ProcedureError(
                f"{path}: procedure[0].insertion.{k}: expected none or patient.insertion.{k}'s value ({pat[k]!r}): "
                f"the first phase's virtual insertion is the patient pipeline's; got {v!r}"
            )
    out["patient"] = {**scene["patient"], "insertion": {**pat, **own}}
    return out


def pipeline_tool_start(scene):
    """When the patient pipeline's tool (in the completed scene's contact, on insertion_tool.CURVE)
    opens a patient procedure's lesion: its curve's first time; None without one."""
    points = (scene.get("load_curves") or {}).get(insertion_tool.CURVE)
    ins = (scene.get("contact") or {}).get("insertion")
    if not points or not isinstance(ins, dict) or _own_tool(scene):
        return None
    return float(points[0][0])


def _own_tool(scene):
    """The scene's contact.insertion when it is the user's own (not one the pipeline or the procedure
    wrote under insertion_tool.CURVE), else None."""
    ins = (scene.get("contact") or {}).get("insertion")
    if not isinstance(ins, dict):
        return None
    r = ins.get("radius")
    return None if isinstance(r, dict) and r.get("curve") == insertion_tool.CURVE else ins


def phase_scene(scene, phase, previous=None, tool=None, placed=None):
    """The scene of one phase (a dict): the phase's time window, devices and contacts; `previous` =
    (run dir of the phase before, whether it had the stent): the states it continues from; `tool`:
    the phase's virtual insertion (insertion_plan), if any; `placed`: {balloon, stent: {file, start}}
    device centerlines on the deformed lumen (deformed_placement), if any. The patient pipeline's
    tool belongs to the first phase."""
    s = copy.deepcopy({k: v for k, v in scene.items() if k != "procedure"})
    if previous is not None and isinstance(s.get("contact"), dict) and not _own_tool(s):
        s["contact"].pop("insertion", None)
        (s.get("load_curves") or {}).pop(insertion_tool.CURVE, None)
    s["time"] = {**(scene.get("time") or {}), "start": phase["start"], "end": phase["end"], "steps": phase["steps"]}
    if phase["balloon"] is not None:
        s["balloon"] = copy.deepcopy(phase["balloon"])
    else:
        s.pop("balloon", None)
    if not phase["stent"]:
        s.pop("stent", None)
        if isinstance(s.get("contact"), dict):
            for c in STENT_CONTACTS:
                s["contact"].pop(c, None)
    if previous is not None:
        prev_dir, prev_stent = previous
        s.setdefault("solid", {})["initial_state"] = {
            "file": str(Path(prev_dir) / "solid" / "state.h5"),
            "parts": ["artery"],
        }
        if prev_stent:
            s["stent"]["initial_state"] = {"file": str(Path(prev_dir) / "beam" / "state.h5")}
    for part, key in (("balloon", "mesh"), ("stent", "generator")):
        where = (placed or {}).get(part)
        if where and part in s:
            s[part][key]["centerline"] = {"file": str(where["file"])}
            s[part][key]["start"] = round(float(where["start"]), 9)
    if tool is not None:
        insertion_tool.add_tool(s, tool["t0"], tool["t1"], tool["r0"], tool["r_open"], tool["penalty"])
    return s


def deformed_placement(phase, k, summary, step, placement, stent_placed, geometry_dir, where):
    """A patient procedure's phase after the first: its balloon (and the stent, in the phase that
    deploys it) placed on the lumen the phase before left (patient/deformed_placement.py). Returns
    {balloon, stent: {file, start}} (the stent's as deployed once it is), or None where the summary
    has no deformed lumen or the phase no balloon."""
    from patient.deformed_placement import place_on_deformed_lumen
    from patient.errors import PatientInputError
    from patient.placement import Device

    if phase["balloon"] is None:
        return {"stent": stent_placed} if stent_placed else None
    L = float(phase["balloon"]["mesh"]["length"])
    R = 0.5 * float(phase["balloon"]["mesh"]["outer_diameter"])
    # the stent in place from an earlier phase is not placed again: only the balloon's clearance counts
    new = phase["new_stent"]
    dev = Device(
        balloon_length=L,
        balloon_radius=R,
        stent_length=placement["stent_length"] if new else min(placement["stent_length"], L),
        stent_radius=placement["stent_radius"] if new else R,
    )
    f = Path(geometry_dir) / f"device_centerline_{k + 1}-{phase['name']}.txt"
    try:
        placed = place_on_deformed_lumen(
            summary, step, placement["s_site"], dev, placement["zeta"], placement["margin"], f, where
        )
    except PatientInputError as e:
        raise ProcedureError(f"procedure[{k}]: the devices cannot be placed on the deformed lumen: {e}")
    if placed is None:
        return {"stent": stent_placed} if stent_placed else None
    plc, stations = placed
    out = {"balloon": {"file": f, "start": plc.balloon_start, "stations": stations}}
    stent = {"file": f, "start": plc.stent_start} if new else stent_placed
    if stent:
        out["stent"] = stent
    return out


# --- the virtual insertion of a phase whose devices are wider than the lumen --------------------


def device_radius(scene, phase):
    """The outer radius of the phase's crimped devices (mm): its balloon, and the stent where the
    phase deploys it (crimped diameter / 2 + the strut's contact radius)."""
    r = 0.5 * float(phase["balloon"]["mesh"]["outer_diameter"])
    return max(r, insertion_tool.crimped_stent_radius(scene["stent"])) if phase["new_stent"] else r


def _tool_may_serve(scene, phase):
    """Whether a virtual insertion can serve the phase at all: it has a balloon, the scene brings no
    tool of its own, and no stent is in place from an earlier phase (the balloon goes inside it,
    which the tool, pushing the artery only, cannot open)."""
    return phase["balloon"] is not None and not _own_tool(scene) and not (phase["stent"] and not phase["new_stent"])


def pressure_free_until(scene, phase):
    """The last time from the phase's start on during which its balloon's pressure is still 0."""
    p = phase["balloon"].get("pressure")
    if isinstance(p, dict) and isinstance(p.get("curve"), str):
        points = (scene.get("load_curves") or {}).get(p["curve"])
        if points and float(p.get("value", 1.0)) != 0.0:
            return min(insertion_tool.quiet_until(points, phase["start"]), phase["end"])
    return phase["end"] if p in (None, 0, 0.0) else phase["start"]


def insertion_plan(scene, phase, k, lumen, path):
    """The phase's virtual insertion {t0, t1, r0, r_open, penalty, lumen_diameter, device_radius}, or
    None when its devices fit (or it has no balloon, or the scene brings its own tool). `lumen`: the
    minimal lumen diameter (mm) under the phase's balloon at the phase's start. Raises ProcedureError
    when the devices do not fit and the tool cannot work (insertion off, or no pressure-free time)."""
    ins = phase["insertion"]
    if lumen is None or not _tool_may_serve(scene, phase):
        return None
    R = device_radius(scene, phase)
    if 0.5 * lumen >= R + ins["clearance"]:
        return None
    key = f"procedure[{k}]"
    tight = (
        f"the lumen the phase starts from ({lumen:.3f} mm at its narrowest under the balloon) is narrower than its "
        f"crimped devices (outer diameter {2 * R:.3f} mm) plus twice {key}.insertion.clearance "
        f"({ins['clearance']:g} mm)"
    )
    if ins["mode"] == "off":
        raise ProcedureError(f"{path}: {key}.insertion.mode: expected auto (the virtual insertion), got off: {tight}")
    t0, t1 = phase["start"], pressure_free_until(scene, phase)
    dt = (phase["end"] - phase["start"]) / phase["steps"]
    if t1 - t0 < 4 * dt - 1e-12:
        curve = (phase["balloon"].get("pressure") or {}).get("curve", "?")
        raise ProcedureError(
            f"{path}: load_curves.{curve}: expected no balloon pressure for at least 4 load steps "
            f"({4 * dt:g} s) from the start of phase {k + 1} ({phase['name']}, t = {t0:g} s), in which the "
            f"virtual insertion opens the lumen; got {max(t1 - t0, 0.0):g} s: {tight}"
        )
    return {
        "t0": t0,
        "t1": t1,
        "r0": insertion_tool.START_FRACTION * 0.5 * lumen,
        "r_open": R + ins["clearance"],
        "penalty": ins["penalty"],
        "lumen_diameter": lumen,
        "device_radius": R,
    }


def lumen_under(summary, step, scene, phase, extent=None):
    """The minimal lumen diameter (mm) under the phase's balloon at one step of a solid summary
    (extent: the balloon's in the stations, else from the scene; all stations where it is not
    known); None without a lumen."""
    stations = summary.get("lumen_stations") or []
    d = step.get("lumen_diameter") or []
    ext = extent or (balloon_extent(phase["balloon"], scene["artery"]) if phase["balloon"] is not None else None)
    mask = [ext[0] <= z <= ext[1] for z in stations] if ext and len(stations) == len(d) else None
    if mask is not None and not any(mask):
        mask = None
    return _lumen_min(step, mask)


def reference_lumen(scene, phase, run_dir, launch_args):
    """The solid summary of the artery alone at the procedure's start (the reference mesh's lumen):
    one tiny step of the solid, in <run_dir>/0-lumen/."""
    s = phase_scene(scene, phase)
    for k in ("balloon", "stent", "contact", "coupling"):
        s.pop(k, None)
    s["time"] = {**s["time"], "end": phase["start"] + 1e-6 * (phase["end"] - phase["start"]), "steps": 1}
    s.setdefault("solid", {})["ranks"] = 1
    for k in ("damping", "damping_parts"):  # the balloon's pseudo-time damping: no balloon here
        (s["solid"].get("newton") or {}).pop(k, None)
    s["output"] = {**(s.get("output") or {}), "every": 1}
    f = Path(run_dir) / "0-lumen.yaml"
    _write(f, s, "the artery alone at the procedure's start: its lumen decides the first phase's insertion")
    args, skip = [], False
    for a in launch_args:  # one rank whatever the procedure's --ranks
        if skip or a == "--ranks":
            skip = a == "--ranks"
            continue
        args.append(a)
    rc = subprocess.call(
        [sys.executable, str(LAUNCH), str(f), "--run-dir", str(Path(run_dir) / "0-lumen")] + args,
        stdout=subprocess.DEVNULL,
    )
    summary = _load(Path(run_dir) / "0-lumen" / "solid" / "summary.json")
    if rc != 0 or not summary or not summary.get("steps"):
        raise ProcedureError(f"{f}: the artery alone did not start (exit {rc}); see {Path(run_dir) / '0-lumen'}")
    return summary, summary["steps"][0]


def phase_dir(run_dir, k, phase):
    return Path(run_dir) / f"{k + 1}-{phase['name']}"


def _write(path, scene, note):
    path.write_text(f"# {note}\n" + yaml.safe_dump(scene, sort_keys=False))


def check(scene, path, launch_args, geometry_dir=None):
    """Every phase's scene through `launch.py --check` (without the states, which do not exist yet).
    A patient procedure is completed (meshed and placed) first, into geometry_dir (the run's own
    `geometry/`, so that run() does not mesh it again) or, without it, into a scratch directory.
    Returns the completed (scene, placement) for run()."""
    with tempfile.TemporaryDirectory(prefix="angio-procedure-") as tmp:
        done, placement = complete(scene, path, Path(geometry_dir) if geometry_dir else Path(tmp) / "geometry")
        for k, ph in enumerate(phases(done, path)):
            p = Path(tmp) / f"{k + 1}-{ph['name']}.yaml"
            _write(p, phase_scene(done, ph), f"phase {k + 1} of {path}, as checked")
            r = subprocess.run(
                [sys.executable, str(LAUNCH), str(p), "--check"] + launch_args, capture_output=True, text=True
            )
            if r.returncode != 0:
                msg = (r.stderr.strip() or r.stdout.strip()).splitlines()
                raise ProcedureError(f"{path}: procedure[{k}] ({ph['name']}): {msg[-1] if msg else 'check failed'}")
    return done, placement


# --- results per phase -------------------------------------------------------------------------


def _load(p):
    try:
        return json.loads(Path(p).read_text())
    except (OSError, ValueError):
        return None


def _area(d):
    return math.pi * d * d / 4.0 if _number(d) else None


def _lumen_min(step, mask=None):
    d = step.get("lumen_diameter") or []
    vals = [x for i, x in enumerate(d) if _number(x) and (mask is None or mask[i])]
    return min(vals) if vals else None


def balloon_extent(balloon, artery):
    """Axial extent of a generated (tube) balloon in the lumen stations' coordinate (along the artery's
    tube axis, from its centre), or None for other meshes."""
    try:
        bm, am = balloon["mesh"], artery["mesh"]
        if bm.get("generator") != "tube" or am.get("generator") != "tube" or "centerline" in bm or "centerline" in am:
            return None
        z = float((bm.get("center") or [0, 0, 0])[2]) - float((am.get("center") or [0, 0, 0])[2])
        half = float(bm["length"]) / 2.0
        return (z - half, z + half)
    except (KeyError, TypeError, ValueError, IndexError):
        return None


def treated_segment(scene, phases_, stations, stent_extent, balloon_stations=None):
    """The stations every device of the procedure covers (the union of the balloons' and the stent's
    extents; QCA's "in-segment"), one segment for all phases so that their figures compare; None
    (all stations) where an extent is unknown. balloon_stations: a patient procedure's balloon extents
    in the stations by phase name (its devices lie on a curved centerline, not along the tube axis)."""
    balloon_stations = balloon_stations or {}
    ext = [
        balloon_stations.get(p["name"]) or balloon_extent(p["balloon"], scene["artery"])
        for p in phases_
        if p["balloon"] is not None
    ]
    if stent_extent:
        ext.append(tuple(stent_extent))
    if not stations or not ext or any(e is None for e in ext):
        return None
    lo, hi = min(e[0] for e in ext), max(e[1] for e in ext)
    mask = [lo <= z <= hi for z in stations]
    return mask if any(mask) else None


def reference_area(before, mask):
    """Mean lumen area before the procedure at the proximal and distal reference, the first station
    outside the treated segment on either side (IVUS' reference lumen); None without a segment."""
    d = before.get("lumen_diameter") or []
    if mask is None or not any(mask) or len(d) != len(mask):
        return None
    inside = [i for i, m in enumerate(mask) if m]
    refs = [d[i] for i in (inside[0] - 1, inside[-1] + 1) if 0 <= i < len(d) and _number(d[i])]
    return sum(_area(x) for x in refs) / len(refs) if refs else None


def phase_results(pdir, phase, before, stations, mask):
    """Per-phase figures from the phase's solid (and beam) summaries; `before`: the solid summary step
    of the lumen before the procedure; stations: the lumen stations (mm along the vessel); mask: the
    treated stations (None: all)."""
    solid = _load(pdir / "solid" / "summary.json") or {}
    steps = [s for s in solid.get("steps", []) if _number(s.get("time"))]
    out = {"name": phase["name"], "start": phase["start"], "end": phase["end"], "stent": phase["stent"]}
    if not steps:
        return out
    last = steps[-1]
    peak = max(steps, key=lambda s: s.get("balloon_pressure") or 0.0)
    d0 = _lumen_min(before, mask)
    d_peak, d_end = _lumen_min(peak, mask), _lumen_min(last, mask)
    out["lumen"] = {
        "min_diameter_before_procedure": d0,
        "min_diameter_at_peak": d_peak,
        "min_diameter_end": d_end,
        "min_area_end": _area(d_end),
        "gain_since_procedure_start": d_end - d0 if _number(d_end) and _number(d0) else None,
        "acute_recoil": (d_peak - d_end) / d_peak if _number(d_peak) and _number(d_end) and d_peak > 0 else None,
        "peak_time": peak.get("time"),
        "peak_balloon_pressure": peak.get("balloon_pressure"),
    }
    out["stress"] = {
        "at_peak": peak.get("max_principal_stress"),
        "end": last.get("max_principal_stress"),
        "p99_at_peak": peak.get("p99_principal_stress"),
        "p99_end": last.get("p99_principal_stress"),
        "endothelium_nodal_at_peak": peak.get("max_principal_stress_endothelium_nodal"),
        "endothelium_nodal_end": last.get("max_principal_stress_endothelium_nodal"),
    }
    # with the stent: the minimal lumen area inside it (stations within its extent) against the
    # reference lumen area, IVUS' stent expansion (minimal stent area / reference lumen area; the
    # lumen inside the stent is the stent's area where the struts are apposed)
    ext = last.get("stent_stations")
    if phase["stent"] and ext and stations:
        in_stent = [ext[0] <= z <= ext[1] for z in stations]
        d_in = _lumen_min(last, in_stent) if any(in_stent) else None
        ref = reference_area(before, mask)
        out["in_stent"] = {
            "min_lumen_diameter_end": d_in,
            "min_lumen_area_end": _area(d_in),
            "reference_lumen_area": ref,
            "expansion": _area(d_in) / ref if _number(d_in) and ref else None,
        }
    if last.get("apposition"):
        out["apposition_end"] = last["apposition"]
    out["artery_contact_force_end"] = last.get("artery_contact_force")
    beam = _load(pdir / "beam" / "summary.json")
    if beam and isinstance(beam.get("diameter"), dict):
        d = beam["diameter"]
        out["stent_diameter"] = {"max": d.get("max"), "final": d.get("final")}
    out["lumen_profile_end"] = last.get("lumen_diameter")
    return out


def summarize(run_dir, scene, path, ran, tools=None, balloon_stations=None):
    """procedure.json and lumen_profiles.png from the phases that ran: [(k, phase, status, wall)];
    tools: the virtual insertion of a phase by name (insertion_plan); balloon_stations: a patient
    procedure's balloon extents in the lumen stations by phase name."""
    run_dir = Path(run_dir)
    first = _load(phase_dir(run_dir, 0, ran[0][1]) / "solid" / "summary.json") if ran else None
    stations = (first or {}).get("lumen_stations") or []
    if isinstance(stations, int):
        stations = []
    steps0 = [s for s in (first or {}).get("steps", []) if _number(s.get("time"))]
    # before the procedure: the last step before the first balloon pressure (the prestressed lumen);
    # where the first phase opened the lesion with the insertion tool, the lumen before the tool
    tool0 = (tools or {}).get(ran[0][1]["name"]) if ran else None
    t_tool = tool0["t0"] if tool0 else pipeline_tool_start(scene)
    before = steps0[0] if steps0 else {}
    for s in steps0:
        if (s.get("balloon_pressure") or 0.0) > 0.0 or (t_tool is not None and s["time"] > t_tool):
            break
        before = s
    out = {
        "scene": str(path),
        "units": {"length": "mm", "area": "mm^2", "stress": "MPa", "time": "s"},
        "lumen_before_procedure": {
            "time": before.get("time"),
            "profile": before.get("lumen_diameter"),
            "stations": stations,
        },
        "phases": [],
    }
    stent_ext = None
    for k, ph, _, _ in ran:
        if ph["stent"]:
            last = ((_load(phase_dir(run_dir, k, ph) / "solid" / "summary.json") or {}).get("steps") or [{}])[-1]
            stent_ext = last.get("stent_stations") or stent_ext
    mask = treated_segment(scene, [ph for _, ph, _, _ in ran], stations, stent_ext, balloon_stations)
    out["segment"] = (
        "stations covered by the procedure's devices (balloons and stent)"
        if mask
        else "all stations (a device extent is not known)"
    )
    for k, ph, status, wall in ran:
        r = phase_results(phase_dir(run_dir, k, ph), ph, before, stations, mask)
        r.update({"status": status, "wall_seconds": round(wall, 1), "run_dir": str(phase_dir(run_dir, k, ph))})
        if (balloon_stations or {}).get(ph["name"]):
            r["balloon_stations"] = list(balloon_stations[ph["name"]])
        if (tools or {}).get(ph["name"]):
            r["insertion"] = {x: v for x, v in tools[ph["name"]].items() if x != "penalty"}
        out["phases"].append(r)
    (run_dir / "procedure.json").write_text(json.dumps(out, indent=1) + "\n")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        if stations and before.get("lumen_diameter"):
            fig, ax = plt.subplots(figsize=(7, 4))
            ax.plot(stations, before["lumen_diameter"], "k--", label="before the procedure")
            for r in out["phases"]:
                if r.get("lumen_profile_end"):
                    ax.plot(stations, r["lumen_profile_end"], label=f"after {r['name']}")
            ax.set_xlabel("station along the vessel (mm)")
            ax.set_ylabel("lumen diameter (mm)")
            ax.legend()
            fig.tight_layout()
            fig.savefig(run_dir / "lumen_profiles.png", dpi=120)
            plt.close(fig)
    except ImportError:
        pass
    return out


def run(scene, path, run_dir, launch_args, completed=None):
    """Runs the phases one after the other (launch.py per phase); returns the exit code of the first
    failing phase, else 0. completed: what check() returned with geometry_dir = <run_dir>/geometry
    (a patient procedure meshed and placed there), else it is completed here."""
    run_dir = Path(run_dir)
    scene, placement = completed or complete(scene, path, run_dir / "geometry")
    ph = phases(scene, path)  # checked by the caller (check()) before the run directory exists
    ran, previous, code, tools, placed, extents = [], None, 0, {}, None, {}
    for k, phase in enumerate(ph):
        pdir = phase_dir(run_dir, k, phase)
        scene_file = run_dir / f"{k + 1}-{phase['name']}.yaml"
        t0 = clock.time()
        try:
            tool, summary, step = None, None, None
            if previous is not None:
                summary = _load(previous[0] / "solid" / "summary.json") or {}
                step = (summary.get("steps") or [{}])[-1]
                if placement:
                    where = str(previous[0] / "solid" / "summary.json")
                    placed = deformed_placement(
                        phase, k, summary, step, placement, (placed or {}).get("stent"), run_dir / "geometry", where
                    )
            # the pipeline's tool (in the scene's contact) already serves a patient's first phase
            first_has_tool = previous is None and pipeline_tool_start(scene) is not None
            if _tool_may_serve(scene, phase) and not first_has_tool:
                if previous is None:
                    summary, step = reference_lumen(scene, phase, run_dir, launch_args)
                ext = ((placed or {}).get("balloon") or {}).get("stations")
                tool = insertion_plan(scene, phase, k, lumen_under(summary, step, scene, phase, ext), path)
        except ProcedureError as e:
            print(f"procedure: phase {k + 1} ({phase['name']}) not started: {e}", file=sys.stderr)
            ran.append((k, phase, "not started (exit 2)", clock.time() - t0))
            code = 2
            break
        _write(
            scene_file, phase_scene(scene, phase, previous, tool, placed), f"phase {k + 1} ({phase['name']}) of {path}"
        )
        if placement and phase["balloon"] is not None:
            # the balloon's extent in the lumen stations: the first phase's centred on the scene's
            # balloon (complete()), a later phase's where it was placed on the deformed lumen
            L = float(phase["balloon"]["mesh"]["length"])
            c = placement["balloon_centre_station"]
            extents[phase["name"]] = ((placed or {}).get("balloon") or {}).get("stations") or (c - L / 2, c + L / 2)
        note = ", devices on the deformed lumen" if placed and placed.get("balloon") else ""
        if tool is not None:
            tools[phase["name"]] = tool
            note += (
                f", virtual insertion (lumen {tool['lumen_diameter']:.3f} mm, devices {2 * tool['device_radius']:.3f}"
                f" mm: the tool opens to {2 * tool['r_open']:.3f} mm until t = {tool['t1']:g} s)"
            )
        print(
            f"procedure: phase {k + 1}/{len(ph)} {phase['name']}: t = {phase['start']} .. {phase['end']} s, "
            f"{phase['steps']} steps{', stent' if phase['stent'] else ''}{note}",
            flush=True,
        )
        rc = subprocess.call([sys.executable, str(LAUNCH), str(scene_file), "--run-dir", str(pdir)] + launch_args)
        ran.append((k, phase, "ok" if rc == 0 else f"failed (exit {rc})", clock.time() - t0))
        if rc != 0:
            print(f"procedure: phase {phase['name']} failed (exit {rc}); later phases not run", file=sys.stderr)
            code = rc
            break
        previous = (pdir, phase["stent"])
    out = summarize(run_dir, scene, path, ran, tools, extents)
    for r in out["phases"]:
        lum = r.get("lumen") or {}
        fmt = lambda v: f"{v:.3f}" if _number(v) else "-"  # noqa: E731
        print(
            f"procedure: {r['name']:16s} {r['status']:10s} min lumen {fmt(lum.get('min_diameter_at_peak'))} mm at "
            f"peak, {fmt(lum.get('min_diameter_end'))} mm at end (gain {fmt(lum.get('gain_since_procedure_start'))} "
            f"mm, recoil {fmt(lum.get('acute_recoil'))}), {r['wall_seconds']} s"
        )
    print(f"procedure: {run_dir / 'procedure.json'}")
    return code
