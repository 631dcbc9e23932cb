"""Device placement in a patient's lumen (paper §2.4).

- Stenosis site: the narrowest lumen station (smallest r), unless the scene names its arc length.
- Balloon end points on the lumen centerline at ± half the balloon length around the site.
- Balloon centerline: per coordinate a cubic smoothing spline y = spl(s) through the lumen centerline
  points between the end points (s = lumen arc length), with as many knots as the smoothing condition
  of paper eq. (3) needs:  | Σ_i (w_i (y_i − spl(s_i)))² − ζ | < ε_ζ ζ,  ζ = 4 mm², ε_ζ = 1e-3.
  That is exactly FITPACK's curfit stopping rule (Dierckx 1993, §5.2; tolerance 0.001), which
  scipy.interpolate.UnivariateSpline calls, as the paper did. When even the least-squares cubic
  without interior knots has a residual below ζ (a smooth lumen), that cubic is the smoothest
  spline and the condition holds as Σ < ζ; the report says which case applies.
- Weights: all 1 at first; where the device (the crimped stent over its length, the balloon
  elsewhere) would come closer to the endothelium than the required margin, the weights of the
  lumen points there are doubled and the spline refitted, which pulls it toward the lumen centerline
  (paper: "an array of adapted weights w ... ensures no overlap").
- A lesion narrower than a crimped device (`insertion=True`, the caller's choice): the devices are
  placed all the same, on a spline kept inside the lumen (its axis at least half the narrowest lumen
  radius under the balloon from the endothelium), and a virtual insertion tool opens the lumen before
  the inflation (prepare.py); the clearances reported are then negative where a device overlaps
  the wall, and `axis_clearance` is the smallest distance of the axis from the endothelium (the
  tool's starting radius must lie below it).
- The clearance is measured against the lumen as a tube: for a point q of the device axis, the
  nearest point of the lumen centerline polyline and the lumen radius r interpolated there;
  clearance = r − |q − nearest| − R_device.
"""
import math
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import UnivariateSpline

from .centerline_csv import arc_length
from .errors import PatientInputError

FITPACK_TOL = 1e-3  # curfit's fixed tolerance: ε_ζ of eq. (3)
ENDPOINT_WEIGHT = 10.0  # the balloon ends lie on the lumen centerline (paper §2.4)


@dataclass
class Device:
    balloon_length: float  # mm
    balloon_radius: float  # outer radius, mm
    stent_length: float  # mm
    stent_radius: float  # crimped outer radius (centerline radius + strut radius), mm


@dataclass
class Placement:
    s_site: float  # lumen arc length of the stenosis site
    site_point: np.ndarray
    site_radius: float
    s0: float
    s1: float  # lumen arc lengths of the balloon end points
    points: np.ndarray  # device centerline polyline (extended beyond the balloon ends)
    sigma_site: float  # its arc length at the site
    balloon_start: float  # arc length on the device centerline where the balloon starts
    stent_start: float
    clearance_balloon: float  # min clearance of the balloon surface from the endothelium, mm
    clearance_stent: float
    clearance_where: dict = field(default_factory=dict)
    axis_clearance: float = float("nan")  # min distance of the device axis from the endothelium, mm
    insertion: bool = False  # devices placed into a lesion narrower than themselves
    spline: list = field(default_factory=list)  # per coordinate: knots, residual, condition
    weight_rounds: int = 0
    max_weight: float = 1.0

    def report(self):
        return {
            "stenosis": {
                "arc_length": self.s_site,
                "point": self.site_point.tolist(),
                "lumen_diameter": 2 * self.site_radius,
            },
            "balloon_ends_lumen_arc_length": [self.s0, self.s1],
            "device_centerline_length": float(arc_length(self.points)[-1]),
            "balloon_start": self.balloon_start,
            "stent_start": self.stent_start,
            "clearance": {
                "balloon": self.clearance_balloon,
                "stent": self.clearance_stent,
                "axis": self.axis_clearance,
                **self.clearance_where,
            },
            "insertion": self.insertion,
            "spline": self.spline,
            "weight_rounds": self.weight_rounds,
            "max_weight": self.max_weight,
        }


def lumen_at(points, radius, s_lumen, s):
    """Point and radius of the lumen centerline at arc length s (linear between stations)."""
    p = np.array([np.interp(s, s_lumen, points[:, c]) for c in range(3)])
    return p, float(np.interp(s, s_lumen, radius))


def project_on_polyline(points, q):
    """Closest point of a polyline for each query point q (m, 3): distance, arc length of the foot,
    segment index and parameter in [0, 1] along it (vectorized over segments; centerlines have at
    most a few thousand)."""
    a, b = points[:-1], points[1:]
    d = b - a
    L2 = np.einsum("ij,ij->i", d, d)
    t = np.clip(np.einsum("mij,ij->mi", q[:, None, :] - a[None], d) / L2[None], 0.0, 1.0)
    foot = a[None] + t[..., None] * d[None]
    dist = np.linalg.norm(q[:, None, :] - foot, axis=2)
    k = np.argmin(dist, axis=1)
    m = np.arange(len(q))
    return dist[m, k], arc_length(points)[k] + t[m, k] * np.sqrt(L2[k]), k, t[m, k]


def nearest_on_polyline(points, radius, q):
    """Distance of each query point to the polyline and the radius interpolated at its foot."""
    dist, _, k, t = project_on_polyline(points, q)
    return dist, radius[k] + t * (radius[k + 1] - radius[k])


def stenosis_site(cl, s_given=None, where="patient.stenosis"):
    s = cl.arc_length
    if s_given is None:
        i = int(np.argmin(cl.radius))
        return float(s[i])
    if not (0.0 <= s_given <= s[-1]):
        raise PatientInputError(
            f"{where}: expected an arc length within the centerline (0 .. {s[-1]:.3f} mm), " f"got {s_given:g}"
        )
    return float(s_given)


def narrowest_under(cl, dev, s_site):
    """{"stent": r, "balloon": r}: the narrowest lumen radius under each device placed at s_site (mm)."""
    s = cl.arc_length
    out = {}
    for name, half in (("stent", 0.5 * dev.stent_length), ("balloon", 0.5 * dev.balloon_length)):
        under = (s >= s_site - half) & (s <= s_site + half)
        out[name] = float(cl.radius[under].min()) if under.any() else lumen_at(cl.points, cl.radius, s, s_site)[1]
    return out


def devices_fit(cl, dev, s_site, margin=0.0):
    """Whether both crimped devices fit in the lumen under them with the margin (mm)."""
    rmin = narrowest_under(cl, dev, s_site)
    return rmin["stent"] >= dev.stent_radius + margin and rmin["balloon"] >= dev.balloon_radius + margin


def place_device(cl, dev, s_site, zeta=4.0, margin=0.0, max_rounds=40, sample=0.05, extension=None, insertion=False):
    """Balloon centerline and device positions (see the module comment). PatientInputError when the
    balloon does not fit on the centerline or the devices cannot clear the endothelium (with
    `insertion`: when the axis cannot be kept inside the lumen)."""
    s = cl.arc_length
    L = s[-1]
    src = cl.path
    s0, s1 = s_site - 0.5 * dev.balloon_length, s_site + 0.5 * dev.balloon_length
    if s0 < 0.0 or s1 > L:
        raise PatientInputError(
            f"{src}: the balloon ({dev.balloon_length:g} mm) centred at the stenosis (arc length {s_site:.2f} mm) "
            f"reaches beyond the centerline (0 .. {L:.2f} mm): expected a centerline reaching at least "
            f"{0.5 * dev.balloon_length:g} mm on each side of the site, or a shorter balloon"
        )
    if dev.stent_length > dev.balloon_length:
        raise PatientInputError(
            f"stent: the stent ({dev.stent_length:g} mm) is longer than the balloon "
            f"({dev.balloon_length:g} mm): expected a stent that fits on the balloon"
        )
    # the devices must fit in the lumen at all (the narrowest station under each device), unless a
    # virtual insertion opens the lesion first
    narrowest = narrowest_under(cl, dev, s_site)
    for name, R in (("stent", dev.stent_radius), ("balloon", dev.balloon_radius)):
        rmin = narrowest[name]
        if rmin < R + margin and not insertion:
            raise PatientInputError(
                f"{src}: the crimped {name} (outer diameter {2 * R:.3f} mm) does not fit in the lumen "
                f"(narrowest diameter {2 * rmin:.3f} mm under the {name}"
                f"{f', margin {margin:g} mm' if margin else ''}): "
                f"expected a lumen wider than the device, a smaller {name}, or the virtual insertion "
                f"(patient.insertion.mode: auto)"
            )

    inside = (s > s0) & (s < s1)
    p0, _ = lumen_at(cl.points, cl.radius, s, s0)
    p1, _ = lumen_at(cl.points, cl.radius, s, s1)
    x = np.concatenate([[s0], s[inside], [s1]])
    y = np.vstack([p0, cl.points[inside], p1])
    if len(x) < 4:
        raise PatientInputError(
            f"{src}: expected at least 2 centerline points within the balloon "
            f"(arc length {s0:.2f} .. {s1:.2f} mm) for the cubic spline, got {len(x) - 2}"
        )
    w = np.ones(len(x))
    w[0] = w[-1] = ENDPOINT_WEIGHT
    xs = np.linspace(s0, s1, max(int(math.ceil((s1 - s0) / sample)) + 1, 8))
    stent_zone = np.abs(xs - s_site) <= 0.5 * dev.stent_length
    R_dev = np.where(stent_zone, max(dev.stent_radius, dev.balloon_radius), dev.balloon_radius)
    if insertion:  # only the axis must stay inside the lumen, well clear of the narrowest wall
        R_dev = np.zeros_like(xs)
        margin = 0.5 * narrowest["balloon"]

    rounds = 0
    while True:
        splines = [UnivariateSpline(x, y[:, c], w=w, k=3, s=zeta) for c in range(3)]
        q = np.column_stack([sp(xs) for sp in splines])
        dist, r = nearest_on_polyline(cl.points, cl.radius, q)
        clear = r - dist - R_dev
        if clear.min() >= margin:
            break
        if rounds == max_rounds:
            k = int(np.argmin(clear))
            raise PatientInputError(
                f"{src}: cannot place the balloon centerline without "
                + (
                    "its axis coming within " + format(margin, ".3f") + " mm of"
                    if insertion
                    else "the devices overlapping"
                )
                + " the endothelium "
                f"(after {rounds} rounds of weight adaptation, {-clear[k] + margin:.3f} mm too close at lumen "
                f"arc length "
                f"{xs[k]:.2f} mm, lumen diameter {2 * r[k]:.3f} mm there): expected a wider lumen or smaller devices"
            )
        # double the weights of the lumen points near the stations that come too close
        bad = xs[clear < margin]
        near = np.min(np.abs(x[:, None] - bad[None, :]), axis=1) <= max(2 * sample, 0.5)
        w[near] *= 2.0
        rounds += 1

    spline_info = []
    for c, sp in enumerate(splines):
        fp = float(sp.get_residual())
        n_int = len(sp.get_knots()) - 2
        cond = abs(fp - zeta) < FITPACK_TOL * zeta
        spline_info.append(
            {
                "coordinate": "xyz"[c],
                "interior_knots": n_int,
                "residual": fp,
                "zeta": zeta,
                "eq3_equality": bool(cond),
                "case": "eq. (3) holds"
                if cond
                else ("least-squares cubic, residual below zeta" if fp < zeta and n_int == 0 else "eq. (3) not met"),
            }
        )
        if not cond and not (fp < zeta and n_int == 0):
            raise PatientInputError(
                f"{src}: the smoothing spline ({'xyz'[c]}) did not meet eq. (3): "
                f"residual {fp:.4g} against zeta {zeta:g} (FITPACK gave up; too few points?)"
            )

    # the device centerline: the spline between the balloon ends, extended along the end tangents so
    # that the balloon (as long as the lumen arc, the spline is shorter) and the springs fit on it
    ext = 0.1 * dev.balloon_length + 0.5 if extension is None else extension
    pts = q
    t0 = pts[1] - pts[0]
    t1 = pts[-1] - pts[-2]
    t0 /= np.linalg.norm(t0)
    t1 /= np.linalg.norm(t1)
    n_ext = max(int(math.ceil(ext / sample)), 1)
    h = ext / n_ext
    head = np.array([pts[0] - t0 * h * k for k in range(n_ext, 0, -1)])
    tail = np.array([pts[-1] + t1 * h * k for k in range(1, n_ext + 1)])
    full = np.vstack([head, pts, tail])
    sig = arc_length(full)
    # the site on the device centerline: its arc length at the spline parameter s_site
    sig_site = float(np.interp(s_site, xs, sig[n_ext : n_ext + len(xs)]))
    b_start = sig_site - 0.5 * dev.balloon_length
    st_start = sig_site - 0.5 * dev.stent_length
    if b_start < 0 or sig_site + 0.5 * dev.balloon_length > sig[-1]:
        raise PatientInputError(f"{src}: internal placement error: the balloon does not fit on its own centerline")
    # reported: the balloon everywhere (its radius), the stent where it is, each with its location
    cb = r - dist - dev.balloon_radius
    kb = int(np.argmin(cb))
    cs = np.where(stent_zone, r - dist - dev.stent_radius, np.inf)
    ks = int(np.argmin(cs))
    site_point, site_radius = lumen_at(cl.points, cl.radius, s, s_site)
    return Placement(
        s_site=s_site,
        site_point=site_point,
        site_radius=site_radius,
        s0=s0,
        s1=s1,
        points=full,
        sigma_site=sig_site,
        balloon_start=b_start,
        stent_start=st_start,
        clearance_balloon=float(cb[kb]),
        clearance_stent=float(cs[ks]) if stent_zone.any() else float("nan"),
        clearance_where={
            "balloon_min_at_lumen_arc_length": float(xs[kb]),
            "stent_min_at_lumen_arc_length": float(xs[ks]),
        },
        spline=spline_info,
        weight_rounds=rounds,
        max_weight=float(w[1:-1].max()) if len(w) > 2 else 1.0,
        axis_clearance=float((r - dist).min()),
        insertion=bool(insertion),
    )
