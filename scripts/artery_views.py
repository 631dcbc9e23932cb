"""Pictures of the artery without ParaView: the wall cut open along its axis and seen from inside,
coloured by the first principal Cauchy stress, in the deformed configuration, with the stent.

The far half of the artery's boundary (the endothelium and, behind it, the outer surface) is drawn
in an orthographic view along the cut plane's normal, far faces first (painter's order), so the
endothelium of the far half faces the viewer. Cut plane: through the centroid of the artery's
reference nodes, containing their principal axis (the vessel's length) and their least-spread
direction (so a planar curve is cut in its own plane). A node's stress is the largest of the
recovered nodal values of the layers it belongs to (stress_p1_nodal_<layer> of solid.h5); a face's
is the mean of its corners'. The colour scale is clipped at the 99th percentile of the faces shown,
as the peaks at the struts' edges are single nodes. The stent: the beam's segments in the far half.
Units: mm, MPa. matplotlib (Agg) only."""
import numpy as np

# corner faces of each element type, local node numbers (outward or not: only their sets matter)
FACES = {
    "hex8": ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)),
    "tet4": ((0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)),
    "tet10": ((0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)),
}


def boundary_faces(conn, etype):
    """The corner faces that belong to one element only (the boundary of the element set)."""
    local = FACES[etype]
    faces = np.concatenate([conn[:, f] for f in local])
    keys = np.sort(faces, axis=1)
    _, first, count = np.unique(keys, axis=0, return_index=True, return_counts=True)
    return faces[first[count == 1]]


def cut_frame(X):
    """(centre, axis, cut normal) of the node cloud X: its centroid, its principal axis (along the
    vessel) and its direction of least spread (the normal of a curved vessel's plane)."""
    c = X.mean(axis=0)
    _, _, vt = np.linalg.svd(X - c, full_matrices=False)
    return c, vt[0], vt[2]


def _steps_by_time(h5, times):
    keys = sorted(h5["/steps"].keys(), key=int)
    ts = np.array([h5[f"/steps/{k}"].attrs["time"] for k in keys])
    return [keys[int(np.argmin(np.abs(ts - t)))] for t in times]


def render(run, views, artery_blocks, out_names):
    """One PNG per (title, time) of `views` into run/<out_name>; returns the names written."""
    import h5py
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection, PolyCollection

    written = []
    with h5py.File(run / "solid" / "solid.h5", "r") as f:
        X = f["/mesh/coordinates"][:]
        etypes = [k for k in f["/mesh"].keys() if k in FACES]
        faces = []
        for et in etypes:
            block = f[f"/mesh/{et}/block_id"][:]
            conn = f[f"/mesh/{et}/connectivity"][:]
            on = np.isin(block, list(artery_blocks))
            if on.any():
                faces.extend(list(boundary_faces(conn[on][:, : (8 if et == "hex8" else 4)], et)))
        if not faces or "/steps" not in f or not len(f["/steps"]):  # no artery, or no step written (a stop at step 1)
            return written
        nodes = np.unique(np.concatenate([np.asarray(fc) for fc in faces]))
        c, axis, normal = cut_frame(X[nodes])
        side = np.cross(normal, axis)
        far = [fc for fc in faces if (X[list(fc)].mean(axis=0) - c) @ normal < 0.0]
        keys = _steps_by_time(f, [t for _, t in views])
        beam = _beam_segments(run, [t for _, t in views])
        for (title, t), key, segs, name in zip(views, keys, beam, out_names):
            g = f[f"/steps/{key}"]
            x = X + g["displacement"][:]
            sig = np.full(len(X), -np.inf)
            for name_l in artery_blocks.values():
                d = f"stress_p1_nodal_{name_l}"
                if d in g:
                    v = g[d][:]
                    sig = np.where(np.isfinite(v), np.maximum(sig, v), sig)
            poly = [x[list(fc)] for fc in far]
            val = np.array([np.mean(sig[list(fc)]) for fc in far])
            depth = np.array([(p.mean(axis=0) - c) @ normal for p in poly])
            order = np.argsort(depth)  # far faces first
            xy = [np.column_stack([(p - c) @ axis, (p - c) @ side]) for p in poly]
            ok = np.isfinite(val)
            hi = float(np.percentile(val[ok], 99)) if ok.any() else 1.0
            lo = float(min(0.0, np.min(val[ok]))) if ok.any() else 0.0
            fig, ax = plt.subplots(figsize=(10, 4))
            pc = PolyCollection([xy[i] for i in order], cmap="viridis", edgecolors="none", antialiaseds=False)
            pc.set_array(np.clip(val[order], lo, hi))
            pc.set_clim(lo, hi)
            ax.add_collection(pc)
            if segs is not None:
                mid = 0.5 * (segs[:, 0] + segs[:, 1])
                keep = (mid - c) @ normal < 0.0
                s2 = [np.column_stack([(s - c) @ axis, (s - c) @ side]) for s in segs[keep]]
                ax.add_collection(LineCollection(s2, colors="k", linewidths=0.6))
            ax.autoscale_view()
            ax.set_aspect("equal")
            ax.set_xlabel("along the vessel (mm)")
            ax.set_ylabel("across (mm)")
            ax.set_title(f"{title}, t = {f[f'/steps/{key}'].attrs['time']:.3g} s: artery cut open, seen from inside")
            cb = fig.colorbar(pc, ax=ax, shrink=0.8)
            cb.set_label(f"first principal stress (MPa)\nclipped at its 99th percentile, {hi:.3g}")
            fig.tight_layout()
            fig.savefig(run / name, dpi=120)
            plt.close(fig)
            written.append(name)
    return written


def _beam_segments(run, times):
    """The stent's segments (n, 2, 3) at the beam output nearest each time, or None per time."""
    import h5py

    path = run / "beam" / "beam.h5"
    if not path.is_file():
        return [None] * len(times)
    with h5py.File(path, "r") as b:
        keys = [k for k in b.keys() if k.startswith("step_")]
        if not keys or "/mesh/connectivity" not in b:
            return [None] * len(times)
        conn = b["/mesh/connectivity"][:]
        ts = np.array([b[k].attrs["time"] for k in keys])
        out = []
        for t in times:
            p = b[keys[int(np.argmin(np.abs(ts - t)))]]["positions"][:]
            out.append(p[conn])
        return out
