"""The virtual insertion tool's schedule: how a lesion narrower than a crimped device is opened
before the device's balloon is inflated (used by the patient pipeline and by procedures).

A rigid capsule along the balloon's axis (`contact.insertion`, solid_solver/README.md) grows from
inside the narrowest lumen to the devices' outer radius plus a clearance during a window without
balloon pressure and pushes the wall out by penalty contact; the stent- and balloon-artery
contacts switch on once it is open; it retracts to 0 by the window's end so that the wall comes to
rest on the devices (as catheter insertion is modelled by Zahedmanesh, Kelly and Lally, J Biomech
43 (2010) 2126, and Mortier et al., Ann Biomed Eng 38 (2010) 88). The fractions of the window
(open at 50 %, contacts on at 55 %, hold to 60 %, retracted at 100 %) are those
configs/stability/severe_stenosis_insertion.yaml runs with. Units: mm, N, MPa, s.
"""
import math

import scene_keys

CURVE = "insertion_tool"  # the load curve the tool's radius follows (a scene may not use the name)
# inside the narrowest lumen: the tool starts at this fraction of its radius (contact from the start
# would push the wall in the first step at full penalty)
START_FRACTION = 0.9
OPEN, CONTACTS_ON, HOLD = 0.5, 0.55, 0.6  # fractions of the window


def crimped_stent_radius(stent):
    """The crimped stent's outer radius (mm) from a scene's `stent:` section: crimped diameter / 2 +
    the strut's contact radius (the generator's declared default diameter where the scene has none)."""
    g, sec = stent.get("generator") or {}, stent.get("section") or {}
    crimped = g.get("crimped_diameter", scene_keys.default("stent.generator.crimped_diameter"))
    return 0.5 * float(crimped) + float(sec.get("contact_radius", sec.get("radius", 0.0)))


def curve_value(points, t):
    """Piecewise-linear value of a load curve [[t, v], ...] at t (held constant outside it)."""
    if t <= points[0][0]:
        return float(points[0][1])
    for (t0, v0), (t1, v1) in zip(points, points[1:]):
        if t <= t1:
            return float(v0) if t1 == t0 else float(v0) + (float(v1) - float(v0)) * (t - t0) / (t1 - t0)
    return float(points[-1][1])


def quiet_until(points, t0):
    """The last time t1 >= t0 such that the curve is 0 on all of [t0, t1] (t0 itself when it is not
    0 at t0); float('inf') when it stays 0."""
    if curve_value(points, t0) != 0.0:
        return t0
    t1 = t0
    for t, v in points:
        if t <= t0:
            continue
        if float(v) != 0.0:
            return t1
        t1 = float(t)
    return math.inf


def add_tool(scene, t0, t1, r0, r_open, penalty, curve=CURVE, t_end=None):
    """Completes `scene` (a dict) with the tool over the window [t0, t1]: the radius curve `curve`
    (r0 at t0, r_open from OPEN to HOLD of the window, 0 at t1 and after, up to t_end),
    contact.insertion along the balloon's axis, and the switch-on time of the stent- and
    balloon-artery contacts: not before the tool is open (a later `from` of the scene is kept).
    Returns the report {tool_radius_curve, penalty, contacts_from}."""
    T = t1 - t0
    pts = [[t0, r0], [t0 + OPEN * T, r_open], [t0 + HOLD * T, r_open], [t1, 0.0]]
    if t_end is not None and t_end > t1:
        pts.append([t_end, 0.0])
    curves = scene.setdefault("load_curves", {})
    curves[curve] = [[round(float(t), 9), round(float(v), 9)] for t, v in pts]
    contact = scene.setdefault("contact", {})
    contact["insertion"] = {"axis": "balloon", "radius": {"value": 1.0, "curve": curve}, "penalty": float(penalty)}
    on = {}
    for key in ("stent_artery", "balloon_artery"):
        c = contact.get(key)
        if isinstance(c, dict):
            c["from"] = max(float(c.get("from", -math.inf)), round(t0 + CONTACTS_ON * T, 9))
            on[key] = c["from"]
    return {"tool_radius_curve": curves[curve], "penalty": float(penalty), "contacts_from": on}
