"""A study's table and plots: one row per case (its parameters, state, wall time, message and every
number of its results.json), written as <out>/table.csv (and table.parquet when pyarrow is at hand);
plots of chosen outputs against one parameter, one line per value of the other parameters (e.g. per
patient) in <out>/plots/."""
import csv
import math
import os

from .cases import case_state, results_of


def flatten(doc, prefix=""):
    """The finite numbers of a results.json as {dotted.path: value} (lists and text left out)."""
    out = {}
    for k, v in doc.items():
        path = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(flatten(v, path + "."))
        elif isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
            out[path] = v
    return out


def shown(v):
    """A parameter as a table cell (a patient file by its name)."""
    if isinstance(v, str) and os.path.sep in v:
        return os.path.basename(v)
    return v if isinstance(v, (int, float, str)) else str(v)


def rows_of(study, out_dir):
    rows = []
    for c in study.cases:
        st = case_state(out_dir, c)
        row = {
            "case": c.key,
            "index": c.index,
            "state": st["state"],
            "wall_s": st.get("wall_s"),
            "exit_code": st.get("exit_code"),
            "message": st.get("message", ""),
        }
        row.update({k: shown(v) for k, v in c.params.items()})
        if st["state"] == "done":
            row.update(flatten(results_of(out_dir, c)))
        rows.append(row)
    return rows


def columns_of(study, rows):
    fixed = ["case", "index", "state", "wall_s", "exit_code"] + study.parameter_names() + study.outputs
    rest = sorted({k for r in rows for k in r} - set(fixed) - {"message"})
    return fixed + rest + ["message"]


def write_table(study, out_dir):
    """Writes table.csv (and table.parquet if pyarrow imports); returns (rows, columns, written paths)."""
    rows = rows_of(study, out_dir)
    cols = columns_of(study, rows)
    path = os.path.join(out_dir, "table.csv")
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols, restval="")
        w.writeheader()
        for r in rows:
            w.writerow({k: ("" if r.get(k) is None else r.get(k)) for k in cols})
    written = [path]
    try:
        import pyarrow
        import pyarrow.parquet
    except ImportError:
        pyarrow = None
    if pyarrow is not None:
        table = pyarrow.Table.from_pylist([{k: r.get(k) for k in cols} for r in rows])
        pq = os.path.join(out_dir, "table.parquet")
        pyarrow.parquet.write_table(table, pq)
        written.append(pq)
    return rows, cols, written


def plot(study, rows, out_dir):
    """One PNG per output of plot.y against plot.x, one line per combination of the other parameters."""
    if not study.plot:
        return []
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = study.plot["x"]
    others = [p for p in study.parameter_names() if p != x]
    done = [r for r in rows if r["state"] == "done" and isinstance(r.get(x), (int, float))]
    os.makedirs(os.path.join(out_dir, "plots"), exist_ok=True)
    paths = []
    for y in study.plot["y"]:
        fig, ax = plt.subplots(figsize=(5.5, 4))
        groups = {}
        for r in done:
            if isinstance(r.get(y), (int, float)):
                groups.setdefault(tuple(r.get(p) for p in others), []).append((r[x], r[y]))
        for g, pts in sorted(groups.items(), key=lambda kv: str(kv[0])):
            pts.sort()
            label = ", ".join(f"{p}={v}" for p, v in zip(others, g)) or None
            ax.plot([p[0] for p in pts], [p[1] for p in pts], "o-", label=label)
        ax.set_xlabel(x)
        ax.set_ylabel(y)
        ax.set_title(f"{study.name}: {len(done)} of {len(rows)} cases done")
        if any(others) and groups:
            ax.legend(fontsize=7)
        ax.grid(alpha=0.3)
        fig.tight_layout()
        p = os.path.join(out_dir, "plots", f"{y.replace('/', '_')}.png")
        fig.savefig(p, dpi=120)
        plt.close(fig)
        paths.append(p)
    return paths
