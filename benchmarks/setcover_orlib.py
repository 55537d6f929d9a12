"""Benchmark: anchor-pruning ILP solver on Beasley's OR-Library weighted set cover (r = 1).

Solves every instance in <data>/setcover (scp4*, scp5*, scpa*, scpb*) with
``hiconav.memory.setcover.solve_multicover`` (HiGHS via scipy.optimize.milp), prints each
instance's cost against optimal.csv and its wall time, and ends with one JSON line
``{"optimal": K, "instances": N, "max_s": ...}``. Times include the reductions and the solve,
not the file parsing; cpu_s is this process's CPU time (robust to a busy machine). Run: ``python benchmarks/setcover_orlib.py [--time-limit S] [--only scp41]``.
"""

from __future__ import annotations

import argparse
import csv
import json
import re
import sys
import time
from pathlib import Path

from hiconav.data import data_root
from hiconav.memory.setcover import read_orlib, solve_multicover


def _key(name: str) -> tuple[str, int]:
    m = re.match(r"scp([0-9]|[a-z])(\d+)", name)
    return (m.group(1), int(m.group(2))) if m else (name, 0)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=None, help="folder with scp*.txt and optimal.csv")
    ap.add_argument("--time-limit", type=float, default=60.0, help="HiGHS time limit per instance")
    ap.add_argument("--only", nargs="*", default=None, help="instance names to run")
    ap.add_argument("--no-reduce", action="store_true", help="skip the safe reductions")
    args = ap.parse_args(argv)
    folder = args.data or (data_root() / "setcover")
    with open(folder / "optimal.csv") as fh:
        optimal = {row["instance"]: float(row["optimal_cost"]) for row in csv.DictReader(fh)}
    names = sorted(optimal, key=_key)
    if args.only:
        names = [n for n in names if n in args.only]
    n_opt, max_s, rows = 0, 0.0, []
    print(f"{'instance':10s} {'rows':>5s} {'cols':>5s} {'cost':>7s} {'optimal':>7s} "
          f"{'status':>15s} {'time_s':>7s} {'cpu_s':>7s}")
    for name in names:
        inst = read_orlib(folder / f"{name}.txt")
        t0 = time.perf_counter()
        c0 = time.process_time()
        res = solve_multicover(inst.costs, inst.cover, inst.requirements,
                               time_limit=args.time_limit, reduce=not args.no_reduce)
        dt = time.perf_counter() - t0
        cpu = time.process_time() - c0
        hit = abs(res.cost - optimal[name]) < 1e-6
        n_opt += int(hit)
        max_s = max(max_s, dt)
        rows.append((name, dt))
        print(f"{name:10s} {inst.n_rows:5d} {inst.n_columns:5d} {res.cost:7.0f} "
              f"{optimal[name]:7.0f} {res.status:>15s} {dt:7.2f} {cpu:7.2f}{'' if hit else '  MISS'}",
              flush=True)
    print(json.dumps({"optimal": n_opt, "instances": len(names), "max_s": round(max_s, 3)}))
    return 0 if n_opt == len(names) else 1


if __name__ == "__main__":
    sys.exit(main())
