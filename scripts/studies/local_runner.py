"""The local runner: a pool of concurrent cases on this machine.

Each case occupies its solid's ranks plus one core for the coupler and the beam (both light); the
pool runs as many cases at once as the cores hold, or --jobs.
"""
import concurrent.futures
import os
import sys

from .cases import run_case


def default_jobs(study, cases):
    slots = max(study.ranks(c) for c in cases) + 1
    return max(1, (os.cpu_count() or 1) // slots)


def run_local(study, cases, out_dir, build_dir, jobs):
    """Runs `cases` (jobs at a time); returns {key: case.json content}."""
    results = {}
    n = len(cases)

    def one(case):
        print(f"[study] case {case.index} ({case.key}) started: {case.params}", file=sys.stderr, flush=True)
        info = run_case(study, case, out_dir, build_dir)
        return case, info

    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        for k, fut in enumerate(concurrent.futures.as_completed([pool.submit(one, c) for c in cases]), 1):
            case, info = fut.result()
            results[case.key] = info
            wall = info.get("wall_s")
            print(
                f"[study] {k}/{n} case {case.index} ({case.key}): {info['state']}"
                + (f" in {wall:.1f} s" if wall is not None else "")
                + (f": {info['message']}" if info.get("message") else ""),
                file=sys.stderr,
                flush=True,
            )
    return results
