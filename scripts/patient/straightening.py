"""The artery's straightening (paper §4.2.3: the stented section straightens and keeps some of it):
the bow of the lumen axis over the stented section, before, at peak and after the procedure.

The lumen axis at three stations (the stent's two ends and its middle, along the lumen centerline's
arc length) is the centroid of the endothelium nodes within 1 mm of the station in the current
configuration; the circle through the three centroids gives the sagitta (distance of the middle
from the chord) and the radius, as the stent's own axis bow (beam_solver/src/axis_bow.cpp).
Reads a patient run directory: geometry/ (lumen centerline, placement.json) and solid/solid.h5."""
import json
from pathlib import Path

import numpy as np

from .centerline_csv import read_centerline_csv
from .errors import PatientInputError
from .placement import project_on_polyline

WINDOW = 1.0  # mm of lumen arc length per station


def bow(end0, middle, end1):
    """Sagitta, radius and chord of the circle through three points (axis_bow.cpp)."""
    a, c = end0 - middle, end1 - middle
    chord = float(np.linalg.norm(end1 - end0))
    cross = float(np.linalg.norm(np.cross(a, c)))
    sagitta = cross / chord if chord > 0 else float(np.linalg.norm(a))
    radius = (
        float(np.linalg.norm(a) * np.linalg.norm(c)) * chord / (2 * cross)
        if cross > 1e-12 * np.linalg.norm(a) * np.linalg.norm(c)
        else float("inf")
    )
    return {"sagitta": sagitta, "radius": radius, "chord": chord}


def artery_axis_bow(run_dir, times, geometry=None):
    """{label: {time, sagitta, radius, chord}} for the reference and the h5 steps nearest to each of
    `times` ({label: t}); None when the run is not a patient run or lacks the files. `geometry`: the
    pipeline's directory (default run_dir/geometry; a continued run's is its first run's)."""
    import h5py

    run = Path(run_dir)
    geo = Path(geometry) if geometry else run / "geometry"
    try:
        plc = json.loads((geo / "placement.json").read_text())
        lumen = read_centerline_csv(geo / "lumen.csv")
    except (OSError, ValueError, PatientInputError):
        return None
    pts, r = lumen.points, lumen.radius
    s_site = plc["placement"]["stenosis"]["arc_length"]
    half = 0.5 * plc["device"]["stent_length"]
    stations = (s_site - half + 0.5 * WINDOW, s_site, s_site + half - 0.5 * WINDOW)
    try:
        f = h5py.File(run / "solid" / "solid.h5", "r")
    except OSError:
        return None
    with f:
        if "/mesh/tet10/connectivity" not in f:
            return None
        X = f["/mesh/coordinates"][:]
        nodes = np.unique(f["/mesh/tet10/connectivity"][:])
        dist, s, k, t = project_on_polyline(pts, X[nodes])
        r_at = r[k] + t * (r[k + 1] - r[k])
        endo = nodes[np.abs(dist - r_at) < 0.05 + 0.05 * r_at]
        s_endo = s[np.abs(dist - r_at) < 0.05 + 0.05 * r_at]
        groups = [endo[np.abs(s_endo - st) <= 0.5 * WINDOW] for st in stations]
        if any(len(g) < 3 for g in groups):
            return None
        step_times = {name: float(f["steps"][name].attrs["time"]) for name in f["steps"]}
        out = {"reference": {"time": None, **bow(*(X[g].mean(axis=0) for g in groups))}}
        for label, t_want in times.items():
            if t_want is None or not step_times:
                continue
            name = min(step_times, key=lambda n: abs(step_times[n] - t_want))
            x = X + f["steps"][name]["displacement"][:]
            out[label] = {"time": step_times[name], **bow(*(x[g].mean(axis=0) for g in groups))}
    return out
