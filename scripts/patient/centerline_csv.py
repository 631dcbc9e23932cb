"""Reading a lumen centerline with lumen radii: a CSV file with a header naming the columns
x, y, z, r (mm) and optionally `wall` (total wall thickness, mm), one station per row, ordered along
the vessel. `#` starts a comment line. This is what SimVascular's centerline tools and most
segmentation pipelines export (after renaming the columns)."""
import csv
import functools
import math
import os
from dataclasses import dataclass

import numpy as np

from .errors import PatientInputError

MAX_BYTES = 64 * 2**20  # a centerline is a few thousand rows; refuse anything that is not one
MAX_POINTS = 200_000
REQUIRED = ("x", "y", "z", "r")
OPTIONAL = ("wall",)


@dataclass
class LumenCenterline:
    path: str
    points: np.ndarray  # (n, 3) mm
    radius: np.ndarray  # (n,) lumen radius, mm
    wall: np.ndarray | None  # (n,) total wall thickness, mm (None: not in the file)

    @functools.cached_property
    def arc_length(self):
        return arc_length(self.points)


def arc_length(points):
    """Cumulative arc length of a polyline (n, 3), starting at 0."""
    return np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])


def read_centerline_csv(path):
    """The centerline, or PatientInputError naming the file, the line and the problem."""
    try:
        size = os.path.getsize(path)
    except OSError as e:
        raise PatientInputError(f"{path}: cannot read the centerline file: {e.strerror}") from None
    if not os.path.isfile(path):
        raise PatientInputError(f"{path}: expected a centerline CSV file, got a directory or special file")
    if size > MAX_BYTES:
        raise PatientInputError(
            f"{path}: expected a centerline CSV of at most {MAX_BYTES // 2**20} MiB, got {size} bytes"
        )
    try:
        with open(path, newline="", encoding="utf-8") as f:
            lines = [(i + 1, ln) for i, ln in enumerate(f) if ln.strip() and not ln.lstrip().startswith("#")]
    except UnicodeDecodeError:
        raise PatientInputError(f"{path}: expected a text CSV file (UTF-8), got binary data") from None
    if not lines:
        raise PatientInputError(f"{path}: expected a header line x,y,z,r and at least 4 rows, got no data")
    header_line, header = lines[0]
    cols = [c.strip().lower() for c in next(csv.reader([header]))]
    for c in REQUIRED:
        if c not in cols:
            raise PatientInputError(
                f"{path}:{header_line}: expected a header with the columns x,y,z,r "
                f"(and optionally wall), got {','.join(cols)} (no column '{c}')"
            )
    unknown = [c for c in cols if c not in REQUIRED + OPTIONAL]
    if unknown:
        raise PatientInputError(
            f"{path}:{header_line}: unknown column '{unknown[0]}', expected x,y,z,r and optionally wall"
        )
    if len(set(cols)) != len(cols):
        raise PatientInputError(f"{path}:{header_line}: a column is named twice ({','.join(cols)})")
    rows = lines[1:]
    if len(rows) > MAX_POINTS:
        raise PatientInputError(f"{path}: expected at most {MAX_POINTS} centerline points, got {len(rows)}")
    data = np.empty((len(rows), len(cols)))
    for k, (line_no, text) in enumerate(rows):
        fields = next(csv.reader([text]))
        if len(fields) != len(cols):
            raise PatientInputError(
                f"{path}:{line_no}: expected {len(cols)} values ({','.join(cols)}), got {len(fields)}"
            )
        for j, v in enumerate(fields):
            try:
                x = float(v)
            except ValueError:
                raise PatientInputError(
                    f"{path}:{line_no}: column {cols[j]}: expected a number, got {v.strip()!r}"
                ) from None
            if not math.isfinite(x):
                raise PatientInputError(
                    f"{path}:{line_no}: column {cols[j]}: expected a finite number, got {v.strip()}"
                )
            data[k, j] = x
    col = {c: data[:, j] for j, c in enumerate(cols)}
    pts = np.column_stack([col["x"], col["y"], col["z"]])
    return checked_centerline(path, pts, col["r"], col.get("wall"), lambda k: f"{path}:{rows[k][0]}: ")


def checked_centerline(path, pts, r, wall, where):
    """The centerline (n, 3) with its radius and wall (None: not given), or PatientInputError:
    at least 4 points, positive radii and walls, distinct consecutive points, no turn beyond 90°.
    `where(k)` names point k in a message (a CSV's line, a VTP's point id)."""
    if len(pts) < 4:
        raise PatientInputError(
            f"{path}: expected at least 4 centerline points (a cubic spline needs them), got {len(pts)}"
        )
    for k in range(len(pts)):
        if not r[k] > 0:
            raise PatientInputError(f"{where(k)}radius: expected a positive lumen radius (mm), got {r[k]:g}")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    scale = max(float(np.ptp(pts, axis=0).max()), 1e-300)
    for k in np.nonzero(seg <= 1e-9 * scale)[0]:
        raise PatientInputError(
            f"{where(k + 1)}expected distinct consecutive points, got the point before repeated "
            f"({pts[k, 0]:g}, {pts[k, 1]:g}, {pts[k, 2]:g})"
        )
    # a centerline that doubles back is not a vessel: consecutive segments turning by more than 90°
    if len(seg) >= 2:
        t = np.diff(pts, axis=0) / seg[:, None]
        cosang = np.einsum("ij,ij->i", t[:-1], t[1:])
        for k in np.nonzero(cosang < 0)[0]:
            raise PatientInputError(
                f"{where(k + 1)}expected a centerline without reversals, got a turn of "
                f"{math.degrees(math.acos(max(-1.0, cosang[k]))):.0f}° at this point"
            )
    if wall is not None:
        for k in range(len(pts)):
            if not wall[k] > 0:
                raise PatientInputError(f"{where(k)}wall: expected a positive wall thickness (mm), got {wall[k]:g}")
    return LumenCenterline(path=str(path), points=pts, radius=np.asarray(r), wall=wall)


def write_centerline_csv(path, points, radius, wall=None, comment=""):
    """The inverse of read_centerline_csv (used by the patient-like generator and the tests)."""
    with open(path, "w", newline="") as f:
        for ln in comment.splitlines():
            f.write(f"# {ln}\n")
        w = csv.writer(f)
        w.writerow(["x", "y", "z", "r"] + (["wall"] if wall is not None else []))
        for i, p in enumerate(points):
            row = [f"{p[0]:.6f}", f"{p[1]:.6f}", f"{p[2]:.6f}", f"{radius[i]:.6f}"]
            if wall is not None:
                row.append(f"{wall[i]:.6f}")
            w.writerow(row)


def write_points(path, pts, comment):
    """A polyline as text, one `x y z` (mm) per line after '#' comment lines (the centerline files
    the solvers read)."""
    with open(path, "w") as f:
        for ln in comment.splitlines():
            f.write(f"# {ln}\n")
        for p in pts:
            f.write(f"{p[0]:.9f} {p[1]:.9f} {p[2]:.9f}\n")
