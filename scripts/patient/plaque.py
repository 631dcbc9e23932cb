"""Plaque in the intima (`patient.plaque`): regions of the intima with their own material, each an
angular sector over a stretch of the lumen centerline, from `offset` below the lumen outward through
`thickness` (or to the intima's outer surface). The angle turns about the centerline tangent, from
the rotation-minimizing normal that the lofted wall sections start from
(artery_mesh.rotation_minimizing_normals): at the first station the global x axis projected into the
section's plane (y when the centerline starts along x), carried along the centerline without twist;
[0, 360] is all around. Each region becomes the mesh's volume group `plaque_<type>` and the scene's
`artery.layers.plaque_<type>`: the scene's own material when it gives one, else the type's from
plaque_types.yaml. Units: mm, degrees, MPa."""
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scene_keys

from .errors import PatientInputError

TYPES_FILE = Path(__file__).with_name("plaque_types.yaml")
# a plaque no thicker than the intima less this leaves an element's worth of intima outside it
MIN_INTIMA_LEFT = 0.02  # mm


@dataclass
class PlaqueRegion:
    layer: str  # the mesh's volume group and the artery.layers key: plaque_<type>
    from_s: float  # mm along the lumen centerline
    to_s: float
    angle: tuple  # degrees [from, to], to - from in (0, 360]
    thickness: float  # mm from offset; None: to the intima's outer surface
    offset: float = 0.0  # mm below the lumen where it starts

    @property
    def full_circle(self):
        return self.angle[1] - self.angle[0] >= 360.0 - 1e-9


def plaque_types():
    """{type: {E, nu}} from plaque_types.yaml (the one declaration of their parameters; their sources
    are the comments there)."""
    import yaml

    with open(TYPES_FILE) as f:
        return yaml.safe_load(f)


def arcs_overlap(a, b):
    """Do the angular intervals a = [a0, a1] and b (degrees) share more than a boundary?"""
    if a[1] - a[0] >= 360.0 or b[1] - b[0] >= 360.0:
        return True
    for shift in (-360.0, 0.0, 360.0):
        if b[0] + shift < a[1] and a[0] < b[1] + shift:
            return True
    return False


def _depths_overlap(a, b):
    """Do the regions' depth ranges below the lumen overlap (None: to the intima's outer surface)?"""
    a_end = math.inf if a.thickness is None else a.offset + a.thickness
    b_end = math.inf if b.thickness is None else b.offset + b.thickness
    return a.offset < b_end and b.offset < a_end


def read_plaque(entries, length, scene_path):
    """The checked regions of `patient.plaque` on a centerline `length` mm long; PatientInputError
    naming the entry and what was expected."""
    if not entries:
        return []
    if not isinstance(entries, list):
        raise PatientInputError(f"{scene_path}: patient.plaque: expected a list of regions, got {entries!r:.60}")
    regions = []
    for k, e in enumerate(entries):
        key = f"patient.plaque[{k}]"
        v = scene_keys.check_map(e, key, scene_path, PatientInputError)
        if not re.fullmatch(r"[a-z][a-z0-9_]*", v["type"]):
            raise PatientInputError(
                f"{scene_path}: {key}.type: expected a name of lower-case letters, digits and _, got {v['type']!r}"
            )
        if not v["from_s"] < v["to_s"] <= length + 1e-9:
            raise PatientInputError(
                f"{scene_path}: {key}: expected 0 <= from_s < to_s <= {length:.4g} mm (the lumen centerline's "
                f"length), got from_s {v['from_s']:g}, to_s {v['to_s']:g}"
            )
        a = v["angle"]
        if len(a) != 2 or not (math.isfinite(a[0]) and a[0] < a[1] <= a[0] + 360.0):
            raise PatientInputError(
                f"{scene_path}: {key}.angle: expected [from, to] degrees with from < to <= from + 360, got {a!r}"
            )
        regions.append(
            PlaqueRegion(
                f"plaque_{v['type']}", float(v["from_s"]), float(v["to_s"]), tuple(a), v["thickness"], v["offset"]
            )
        )
        for j, o in enumerate(regions[:-1]):
            r = regions[-1]
            if r.from_s < o.to_s and o.from_s < r.to_s and arcs_overlap(r.angle, o.angle) and _depths_overlap(r, o):
                raise PatientInputError(
                    f"{scene_path}: {key}: expected regions that do not overlap, got one that overlaps "
                    f"patient.plaque[{j}] (s {o.from_s:g} to {o.to_s:g} mm, angle {list(o.angle)})"
                )
    return regions


def plaque_materials(regions, layers, scene_path):
    """The materials to add to artery.layers: the type's for each plaque layer the scene leaves out;
    a type without parameters in either place is refused."""
    types = plaque_types()
    add = {}
    for k, r in enumerate(regions):
        if r.layer in layers or r.layer in add:
            continue
        t = r.layer[len("plaque_") :]
        if t not in types:
            raise PatientInputError(
                f"{scene_path}: patient.plaque[{k}].type: expected one of {', '.join(types)}, or a material "
                f"given as artery.layers.{r.layer}; got {t!r}, which has neither"
            )
        add[r.layer] = {"E": types[t]["E"], "nu": types[t]["nu"]}
    return add


def check_within_intima(regions, s, intima, scene_path):
    """Each region's thickness leaves at least MIN_INTIMA_LEFT of intima outside it, at every
    station s (mm) of its stretch; `intima` the intima's thickness per station (n,), or per station
    and ray (n, K) with ray k at 360 k / K degrees, of which the rays in the region's sector count."""
    intima_all = np.asarray(intima, dtype=float)
    for k, r in enumerate(regions):
        depth = r.offset + (r.thickness or 0.0)
        if depth == 0.0:
            continue
        intima = intima_all
        if intima_all.ndim == 2:
            rays = 360.0 * np.arange(intima_all.shape[1]) / intima_all.shape[1]
            off = np.mod(rays - r.angle[0], 360.0)
            inside = off <= r.angle[1] - r.angle[0] + 1e-9
            if not inside.any():  # a sector narrower than the rays' spacing: its nearest ray
                inside = off == off[np.argmin(np.minimum(off, 360.0 - off))]
            intima = intima_all[:, inside].min(axis=1)
        on = (s >= r.from_s) & (s <= r.to_s)
        ends = np.interp([r.from_s, r.to_s], s, intima)
        thin = np.concatenate([intima[on], ends])
        at = np.concatenate([s[on], [r.from_s, r.to_s]])
        i = int(np.argmin(thin))
        if depth > thin[i] - MIN_INTIMA_LEFT:
            what = "offset + thickness" if r.thickness is not None else "offset"
            raise PatientInputError(
                f"{scene_path}: patient.plaque[{k}]: expected {what} at most the intima less "
                f"{MIN_INTIMA_LEFT} mm ({thin[i] - MIN_INTIMA_LEFT:.3f} mm at s = {at[i]:.2f} mm), got "
                f"{depth:g} mm: the plaque would reach outside the intima (leave thickness out for a region "
                f"to the intima's outer surface)"
            )
