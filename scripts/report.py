#!/usr/bin/python3
"""Summarize a finished run directory: results table on stdout, results.json, PNG plots.

  python3 scripts/report.py RUN_DIR

Reads what the run produced (beam/summary.json, solid/summary.json, coupling.csv,
coupling_summary.json); parts that a scene did not have are skipped. Units: mm, N, MPa, s.
"""
import csv
import json
import sys
from pathlib import Path

try:  # plots are optional: without matplotlib the table and results.json are still written
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None

# Paper values (DESIGN §4) for the straight free expansion, shown next to ours. The paper's
# dogboning (§3.1, Fig. 5) is the balloon's: distal vs central radius, largest at 10.4 atm.
PAPER = {"diameter_initial": 1.15, "diameter_max": 2.59, "diameter_final": 2.31,
         "recoil": 0.28, "recoil_percent": 10.8, "dogboning_percent": 20.4, "dogboning_atm": 10.4}
ATM = 0.101325  # MPa


def load_json(p):
    try:
        with open(p) as f:
            return json.load(f)
    except (OSError, json.JSONDecodeError):
        return None


def plot(path, x, y, xlabel, ylabel):
    if plt is None:
        print(f"report: matplotlib not available to {sys.executable}; {path.name} not written")
        return
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(x, y, "o-", ms=3)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main(run_dir):
    run = Path(run_dir)
    out = {}
    rows = []
    beam = load_json(run / "beam" / "summary.json")
    solid = load_json(run / "solid" / "summary.json")
    coupling = load_json(run / "coupling_summary.json")
    steps_csv = []
    if (run / "coupling.csv").is_file():
        with open(run / "coupling.csv") as f:
            steps_csv = list(csv.DictReader(f))

    # pressure (atm) at a pseudo-time, from the coupler's per-step CSV
    p_of_t = {round(float(r["time"]), 9): float(r["pressure"]) / ATM for r in steps_csv}

    if beam:
        d = beam["diameter"]
        out["stent"] = d
        rows += [("stent diameter crimped (mm)", d["initial"], PAPER["diameter_initial"]),
                 ("stent diameter max (mm)", d["max"], PAPER["diameter_max"]),
                 ("stent diameter final (mm)", d["final"], PAPER["diameter_final"]),
                 ("elastic recoil (mm)", d["recoil"], PAPER["recoil"]),
                 ("elastic recoil (%)", d["recoil_percent"], PAPER["recoil_percent"])]
        st = beam.get("stent")
        if st:
            out["stent"].update(st)
            rows += [("stent dogboning max (%)", st["dogboning_max_percent"], None),
                     ("  at time (s)", st["time_of_dogboning_max"], None),
                     ("  at pressure (atm)", p_of_t.get(round(st["time_of_dogboning_max"], 9), "-"), None),
                     ("foreshortening at max diameter (%)", st["foreshortening_at_max_diameter_percent"], None),
                     ("foreshortening final (%)", st["foreshortening_final_percent"], None)]
            if st.get("axis_radius_initial") is not None:  # curved device: straightening (paper §3.2)
                rows += [("axis sagitta crimped / max / final (mm)",
                          " / ".join(f"{st[k]:.3f}" for k in ("axis_sagitta_initial", "axis_sagitta_at_max_diameter",
                                                              "axis_sagitta_final")), None),
                         ("axis radius crimped / max / final (mm)",
                          " / ".join(f"{st[k]:.1f}" if st[k] is not None else "inf"
                                     for k in ("axis_radius_initial", "axis_radius_at_max_diameter",
                                               "axis_radius_final")), None)]
    if solid:
        out["solid"] = {k: v for k, v in solid.items() if k != "steps"}
        for k, v in solid.items():
            if isinstance(v, (int, float)) and not isinstance(v, bool):
                rows.append((f"solid {k}", v, None))
        dog = [(s["balloon_outer_diameter"]["dogboning"], s) for s in solid.get("steps", [])
               if "balloon_outer_diameter" in s]
        if dog:
            top, at = max(dog, key=lambda x: x[0])
            press = [v for k, v in at.items() if k.endswith("pressure")]
            out["solid"]["balloon_dogboning_max_percent"] = 100 * top
            out["solid"]["time_of_balloon_dogboning_max"] = at["time"]
            rows += [("balloon dogboning max (%)", 100 * top, PAPER["dogboning_percent"]),
                     ("  at pressure (atm)", press[0] / ATM if press else "-", PAPER["dogboning_atm"])]
    if coupling:
        out["coupling"] = coupling
        rows += [("load steps", coupling["steps"], None),
                 ("coupling iterations mean / max",
                  f'{coupling["coupling_iterations_mean"]:.2f} / {coupling["coupling_iterations_max"]}', None),
                 ("wall time (s)", coupling["wall_time"], None),
                 ("messaging share (%)", 100 * coupling["messaging_share"], None)]

    if rows:
        w = max(len(r[0]) for r in rows)
        print(f"{'quantity'.ljust(w)}  {'this run':>12}  {'paper':>8}")
        for name, ours, paper in rows:
            o = f"{ours:12.4g}" if isinstance(ours, (int, float)) else f"{ours:>12}"
            p = f"{paper:8.4g}" if isinstance(paper, (int, float)) else f"{'':>8}"
            print(f"{name.ljust(w)}  {o}  {p}")
    (run / "results.json").write_text(json.dumps(out, indent=2))

    if beam and beam.get("steps"):
        t = [0.0] + [s["time"] for s in beam["steps"]]
        D = [beam["diameter"]["initial"]] + [s["diameter"] for s in beam["steps"]]
        plot(run / "diameter_vs_time.png", t, D, "pseudo-time t (s)", "stent diameter (mm)")
        if steps_csv:
            pts = [(p_of_t[round(s["time"], 9)], s["diameter"]) for s in beam["steps"]
                   if round(s["time"], 9) in p_of_t]
            if pts:
                plot(run / "diameter_vs_pressure.png", [p for p, _ in pts], [d for _, d in pts],
                     "balloon pressure (atm)", "stent diameter (mm)")
    print(f"report: {run / 'results.json'}" + (" and plots" if beam else ""))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
