#!/usr/bin/env python3
"""Bow of a curved balloon's axis over a run: does the balloon, the driver of the stent, straighten
as a whole or only in its halves? (paper §3.2: the device "straightens when the balloon inflates").

  bench/balloon_axis_bow.py RUN_DIR [--offset 0.75]

Reads RUN_DIR/solid/solid.h5 (every stored step) and the scene's balloon centerline. The balloon's
nodes are grouped into stations by their reference arc length along that centerline; the centroid
of a station's current positions is a point of the deformed axis (the centroid of a ring follows a
tube that moves or bends). Printed per stored step: the radius of the circle through the stations
at `offset` mm inside each end and at the middle (whole device; the stent's end rings sit 0.75 mm
inside an 18 mm balloon), and through end, quarter and middle for each half. A straight axis has an
infinite radius. Units: mm.
"""
import argparse
import json
import os
import sys

import h5py
import numpy as np
import yaml


def circle_radius(a, b, c):
    """Radius of the circle through three points (inf if collinear)."""
    ab, bc, ca = np.linalg.norm(b - a), np.linalg.norm(c - b), np.linalg.norm(a - c)
    area2 = np.linalg.norm(np.cross(b - a, c - a))
    return float("inf") if area2 < 1e-12 * ab * bc else ab * bc * ca / (2.0 * area2)


def arc_length_of(points, line):
    """Arc length along the polyline `line` of the closest point to each of `points`."""
    seg = line[1:] - line[:-1]
    seg_len = np.linalg.norm(seg, axis=1)
    s0 = np.concatenate([[0.0], np.cumsum(seg_len)])
    best = np.full(len(points), np.inf)
    s = np.zeros(len(points))
    for k in range(len(seg)):
        t = np.clip(((points - line[k]) @ seg[k]) / seg_len[k] ** 2, 0.0, 1.0)
        d = np.linalg.norm(points - (line[k] + t[:, None] * seg[k]), axis=1)
        closer = d < best
        best[closer], s[closer] = d[closer], s0[k] + t[closer] * seg_len[k]
    return s


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run_dir")
    ap.add_argument("--offset", type=float, default=0.75, help="end stations, mm inside each balloon end")
    args = ap.parse_args()
    scene_path = os.path.join(args.run_dir, "scene.yaml")
    scene = yaml.safe_load(open(scene_path))
    cl = (scene.get("balloon", {}).get("mesh", {}) or {}).get("centerline")
    if not isinstance(cl, dict) or "file" not in cl:
        sys.exit(f"balloon_axis_bow: {scene_path}: balloon.mesh.centerline: expected {{file: ...}} (a curved balloon)")
    # the launcher's scene.yaml keeps the user's relative paths; they resolve against configs/
    path = cl["file"]
    for base in (
        os.path.dirname(scene_path),
        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "configs"),
    ):
        if os.path.isfile(os.path.join(base, path)):
            path = os.path.join(base, path)
            break
    line = np.loadtxt(path)
    with h5py.File(os.path.join(args.run_dir, "solid", "solid.h5"), "r") as f:
        X = f["mesh/coordinates"][:]
        blocks = {
            b["id"]: b["name"] for b in json.load(open(os.path.join(args.run_dir, "solid", "summary.json")))["blocks"]
        }
        nodes = set()
        for typ in f["mesh"]:
            if isinstance(f["mesh"][typ], h5py.Group) and "block_id" in f["mesh"][typ]:
                conn, bid = f["mesh"][typ]["connectivity"][:], f["mesh"][typ]["block_id"][:]
                for b, name in blocks.items():
                    if name == "balloon":
                        nodes.update(conn[bid == b].ravel().tolist())
        nodes = np.array(sorted(nodes))
        s = arc_length_of(X[nodes], line)
        lo, hi = s.min(), s.max()
        stations = {
            "end0": lo + args.offset,
            "q0": lo + 0.25 * (hi - lo),
            "mid": 0.5 * (lo + hi),
            "q1": lo + 0.75 * (hi - lo),
            "end1": hi - args.offset,
        }
        width = 0.3
        groups = {k: nodes[np.abs(s - v) < width] for k, v in stations.items()}
        print(
            f"# {args.run_dir}: balloon arc length {hi - lo:.2f} mm, stations "
            + ", ".join(f"{k} {v - lo:.2f}" for k, v in stations.items())
        )
        print(f"{'time':>8} {'whole R':>9} {'half 0 R':>9} {'half 1 R':>9} {'chord':>8}")
        steps = sorted(f["steps"], key=int)
        for k in steps:
            g = f["steps"][k]
            x = X + g["displacement"][:]
            c = {n: x[idx].mean(axis=0) for n, idx in groups.items()}
            t = float(g.attrs["time"])
            print(
                f"{t:8.3f} {circle_radius(c['end0'], c['mid'], c['end1']):9.2f} "
                f"{circle_radius(c['end0'], c['q0'], c['mid']):9.2f} "
                f"{circle_radius(c['mid'], c['q1'], c['end1']):9.2f} "
                f"{np.linalg.norm(c['end1'] - c['end0']):8.3f}"
            )


if __name__ == "__main__":
    main()
