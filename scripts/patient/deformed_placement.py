"""A procedure's later devices placed in the current, deformed lumen (paper §2.4 on the lumen a
phase leaves behind, not on the lumen as imaged).

The solid writes, per step, the lumen's stations along the reference lumen centerline
(`lumen_stations`), their diameters and their centroids in the current configuration
(`lumen_centroid`, solid/summary.json). The centroids are the deformed lumen centerline, half the
diameters its radii; the stenosis site moves with its station. The device centerline is then fitted
through it as for the first placement (placement.place_device: eq. (3), clearance-driven weights),
with `insertion` allowed (the procedure opens a lumen that is still narrower than the devices with
the virtual insertion tool). Units: mm.
"""
import numpy as np

from .centerline_csv import LumenCenterline, arc_length, write_points
from .placement import place_device


def deformed_lumen(summary, step, where):
    """The deformed lumen centerline (points, radii) of one step of a solid summary; None when the
    summary has no centroids (a run of an older solver) or fewer than 4 stations."""
    stations = summary.get("lumen_stations") or []
    c, d = step.get("lumen_centroid"), step.get("lumen_diameter")
    if not (isinstance(c, list) and isinstance(d, list) and len(c) == len(d) == len(stations) >= 4):
        return None, None
    pts = np.asarray(c, dtype=float)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(pts, axis=0), axis=1) > 1e-9])  # no repeated points
    cl = LumenCenterline(path=where, points=pts[keep], radius=0.5 * np.asarray(d, dtype=float)[keep], wall=None)
    return cl, np.asarray(stations, dtype=float)[keep]


def place_on_deformed_lumen(summary, step, s_site_reference, dev, zeta, margin, out_file, where):
    """The device placement (placement.Placement) on the deformed lumen of `step`, its centerline
    written to out_file (x y z per line), and the balloon's extent in the reference stations; None
    when the summary has no deformed lumen. The site is the reference site's station on the deformed
    centerline."""
    cl, stations = deformed_lumen(summary, step, where)
    if cl is None:
        return None
    s_def = arc_length(cl.points)
    s_site = float(np.interp(s_site_reference, stations, s_def))
    plc = place_device(cl, dev, s_site, zeta=zeta, margin=margin, insertion=True)
    write_points(
        out_file, plc.points, f"Device centerline fitted to the deformed lumen of {where} (paper §2.4), x y z mm"
    )
    return plc, (float(np.interp(plc.s0, s_def, stations)), float(np.interp(plc.s1, s_def, stations)))
