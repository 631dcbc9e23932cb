"""Plaque regions read from a label array on the lumen surface (`patient.lumen_surface.plaque`): a
per-vertex integer, 0 for none and k for the k-th name of `types`, as segmentation tools write
tissue classes onto a lumen surface. The labels are sampled on the sections' rays at the centerline
stations (lumen_sections.py: the label of the surface vertex nearest each ray's hit); each connected
patch of one label on the (station, ray) grid, closed around the vessel, becomes the sector that
bounds it (half a station and half a ray spacing beyond its outermost samples), i.e. a
`patient.plaque` entry with the same meaning and checks (plaque.py). A patch is thus meshed as the
smallest sector containing it: an irregular patch is rounded up to its bounding sector, and two
patches whose sectors overlap are refused as overlapping regions. Patches of fewer than MIN_SAMPLES
samples (segmentation specks) are dropped. Units: mm, degrees."""
import numpy as np
import scipy.sparse
import scipy.sparse.csgraph

from .errors import PatientInputError

MIN_SAMPLES = 4


def read_labels(surface_path, surface, name):
    """The integer point-data array `name` of the surface file on the merged vertices of `surface`."""
    from .lumen_sections import point_array

    values = point_array(surface_path, surface, name, "plaque labels: 0 none, k the k-th of types")
    if not np.all(values == np.round(values)) or values.min() < 0:
        raise PatientInputError(f"{surface_path}: point data '{name}': expected integer labels >= 0")
    return values.astype(int)


def check_types(types, where):
    """The label names of a labelled plaque input (`where`: its key): a non-empty list of names."""
    if not types or not isinstance(types, list) or not all(isinstance(x, str) for x in types):
        raise PatientInputError(f"{where}.types: expected a list of plaque type names, got {types!r}")


def regions_from_labels(labels, s, types, thickness, where, depth=None, intima=None):
    """patient.plaque entries ({type, from_s, to_s, angle[, offset, thickness]}) of the label grid
    `labels` (n stations at arc lengths s, K rays at 360 k / K degrees); `types` the names of labels
    1, 2, ... With `depth` (n, K, 2: each sample's labelled depth range below the lumen, mm) and the
    intima's thickness (n, K), each region's offset and thickness bound its samples' ranges (to the
    intima's outer surface, no thickness, where a sample's range reaches that ray's); else every region
    starts at the lumen and has `thickness`."""
    labels = np.asarray(labels)
    n, K = labels.shape
    if labels.max() > len(types):
        raise PatientInputError(
            f"{where}.types: expected a name for every label, got {len(types)} names for labels up to {labels.max()}"
        )
    idx = np.arange(n * K).reshape(n, K)
    pairs = []
    for a, b in ((idx[:-1], idx[1:]), (idx, np.roll(idx, -1, axis=1))):  # along s; around, closed
        same = (labels.ravel()[a.ravel()] == labels.ravel()[b.ravel()]) & (labels.ravel()[a.ravel()] > 0)
        pairs.append(np.stack([a.ravel()[same], b.ravel()[same]], -1))
    pairs = np.concatenate(pairs)
    graph = scipy.sparse.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n * K,) * 2)
    _, comp = scipy.sparse.csgraph.connected_components(graph, directed=False)
    ds = np.diff(s)
    step = 360.0 / K
    entries = []
    for c in np.unique(comp[labels.ravel() > 0]):
        cells = np.flatnonzero(comp == c)
        if len(cells) < MIN_SAMPLES:
            continue
        i, k = np.divmod(cells, K)
        lo, hi = i.min(), i.max()
        from_s = max(s[lo] - 0.5 * (ds[lo - 1] if lo > 0 else 0.0), 0.0)
        to_s = min(s[hi] + 0.5 * (ds[hi] if hi < n - 1 else 0.0), s[-1])
        rays = np.unique(k)
        if len(rays) == K:
            angle = [0.0, 360.0]
        else:  # the arc that leaves out the widest gap between the patch's rays
            gaps = np.diff(np.append(rays, rays[0] + K))
            g = int(np.argmax(gaps))
            first = rays[(g + 1) % len(rays)]
            span = K - gaps[g] + 1
            a0 = first * step - 0.5 * step
            a0 -= 360.0 if a0 + span * step > 360.0 else 0.0  # an arc across 0 degrees as [-a, b]
            angle = [a0, a0 + span * step]
        e = {"type": types[labels.ravel()[cells[0]] - 1], "from_s": float(from_s), "to_s": float(to_s)}
        e["angle"] = [float(x) for x in angle]
        if depth is not None:
            lo, hi = depth[i, k, 0].min(), depth[i, k, 1].max()
            if lo > 0.0:
                e["offset"] = float(lo)
            if not np.any(depth[i, k, 1] >= intima[i, k] * (1.0 - 1e-9)):  # reaching it on no ray
                e["thickness"] = float(hi - lo)
        elif thickness is not None:
            e["thickness"] = float(thickness)
        entries.append(e)
    return entries
