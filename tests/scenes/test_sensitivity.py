#!/usr/bin/python3
"""bench/sensitivity.py in CI on a 3-step variant of the straight free expansion (t = 0 .. 0.09 s,
the stent just in contact, D = 1.156 mm): a study with two changes (balloon end springs 100 -> 1000
N/mm^3, stent-balloon penalty 10 -> 20 N/mm^2) gives three finished runs, JSON/CSV and a Markdown
table; the baseline's differences are zero; both changes move D_peak. The stiffer penalty must give
a larger D_peak: the penalty law lets the balloon sink into the struts by force/penalty, so a softer
penalty leaves a wider balloon whose hoop stress takes more of the pressure and less reaches the
stent (measured +0.034 %). The end springs' sign is not argued (measured +0.0025 %, the taper's
shape): only non-zero is asserted. --reuse of the JSON runs nothing again. Bad study files (unknown
key, a change without set, a name twice, a key path the base lacks) exit 2 naming the file and key.
Usage: test_sensitivity.py BIN_DIR
"""
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

sys.path.insert(0, str(Path(__file__).resolve().parent))
from checklist import check, finish  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCRIPT = str(ROOT / "bench" / "sensitivity.py")
CHANGES = [
    {"name": "balloon end springs 1000", "set": {"balloon.end_springs": 1000.0}},
    {"name": "stent-balloon penalty 20", "set": {"contact.stent_balloon.penalty": 20.0}},
]


def sensitivity(*args, timeout=900):
    r = subprocess.run(["/usr/bin/python3", SCRIPT, *map(str, args)], capture_output=True, text=True, timeout=timeout)
    print(r.stdout[-3000:], r.stderr[-1500:], flush=True)
    return r


bin_dir = Path(sys.argv[1]).resolve()
with tempfile.TemporaryDirectory(prefix="sensitivity-") as tmp:
    tmp = Path(tmp)
    s = yaml.safe_load(open(ROOT / "configs" / "straight_free_expansion.yaml"))
    s["time"] = {"end": 0.09, "steps": 3}
    yaml.safe_dump(s, open(tmp / "short.yaml", "w"), sort_keys=False)
    study = tmp / "study.yaml"
    yaml.safe_dump({"base": "short.yaml", "changes": CHANGES}, open(study, "w"), sort_keys=False)
    out = tmp / "out"
    r = sensitivity(study, "--out-dir", out, "--build-dir", bin_dir.parent)
    check(r.returncode == 0, f"sensitivity.py exits 0 (got {r.returncode})")
    doc = json.load(open(out / "sensitivity.json"))
    runs = {x["name"]: x for x in doc["runs"]}
    check(
        [x["name"] for x in doc["runs"]] == ["baseline"] + [c["name"] for c in CHANGES]
        and all(x["status"] == "ok" and "D_peak" in x["outputs"] for x in doc["runs"]),
        "three finished runs with a stent diameter, baseline first",
    )
    check((out / "sensitivity.csv").read_text().count("\n") == 4, "CSV: a header and one row per run")
    check(
        sum(l.startswith("| ") for l in r.stdout.splitlines()) == 4 and "(+" in r.stdout,
        "a Markdown table: a header and a row per run",
    )
    base = runs["baseline"]
    check(
        base["diff_percent"] and all(v == 0.0 for v in base["diff_percent"].values()),
        "the baseline's differences are zero",
    )
    springs = runs[CHANGES[0]["name"]]["diff_percent"].get("D_peak", 0.0)
    check(springs != 0.0, f"stiffer balloon end springs move D_peak ({springs:+.2e} %)")
    penalty = runs[CHANGES[1]["name"]]["diff_percent"].get("D_peak", 0.0)
    check(penalty > 0.0, f"a stiffer stent-balloon penalty gives a larger D_peak ({penalty:+.2e} %)")
    # --reuse: every run from the first call's JSON, nothing run again
    out2 = tmp / "out2"
    t0 = time.time()
    r2 = sensitivity(study, "--out-dir", out2, "--reuse", out / "sensitivity.json", timeout=120)
    wall = time.time() - t0
    check(
        r2.returncode == 0 and not list(out2.glob("run-*")) and wall < 30,
        f"--reuse runs nothing again (rc {r2.returncode}, {wall:.1f} s)",
    )
    if r2.returncode == 0:
        doc2 = json.load(open(out2 / "sensitivity.json"))
        check(
            all(x["reused"] for x in doc2["runs"])
            and [x["outputs"] for x in doc2["runs"]] == [x["outputs"] for x in doc["runs"]],
            "--reuse: every run reused, the same outputs",
        )
    # bad study files: exit 2 before anything runs, the message names the file and the key
    bad = {
        "unknown key": ({"base": "short.yaml", "chnages": CHANGES}, "chnages"),
        "change without set": ({"base": "short.yaml", "changes": [{"name": "x"}]}, "set"),
        "name twice": ({"base": "short.yaml", "changes": [CHANGES[0], CHANGES[0]]}, "name"),
        "no such map": (
            {"base": "short.yaml", "changes": [{"name": "x", "set": {"ballon.end_springs": 1}}]},
            "ballon.end_springs",
        ),
    }
    for what, (content, key) in bad.items():
        path = tmp / f"bad_{what.replace(' ', '_')}.yaml"
        yaml.safe_dump(content, open(path, "w"), sort_keys=False)
        rb = sensitivity(path, "--out-dir", tmp / "bad", timeout=60)
        check(
            rb.returncode == 2 and str(path) in rb.stderr and key in rb.stderr,
            f"bad study ({what}): exit 2 naming the file and '{key}' (rc {rb.returncode}: {rb.stderr.strip()[-200:]})",
        )

finish()
