"""Same records: the fixed behaviour check of issue #28 (thin behaviours, behaviour unchanged).

Runs the full method on a fixed set, 30 ProcTHOR val episodes (the first 10 houses, 3 each) and
30 Gibson episodes (the first report floors, 8 each), stepped clock, seed 0, and prints one
digest per set of its ``episodes.jsonl`` records without their wall-clock fields
(``EpisodeRecord.deterministic_view``). With ``--against DIR`` (an earlier run's ``--out``) it
compares record for record and names the first field that differs; it exits 1 on a difference.

    python benchmarks/same_records.py --out out/same_after --against out/same_before
"""

from __future__ import annotations

import argparse
import hashlib
import json
import shutil
import subprocess
import sys
from pathlib import Path

from hiconav.data import data_root
from hiconav.eval.records import WALL_FIELDS

SETS = {
    "procthor_val30": ["--houses", "{root}/procthor/val.jsonl.gz", "--episodes-per-house", "3", "--limit", "30"],
    "gibson_report30": ["--maps", "{root}/gibson/train_info.pbz2", "--scenes", "report",
                        "--episodes-per-house", "8", "--limit", "30"],
}


def records(path: Path) -> list[dict]:
    """The run's records, wall-clock fields removed, in episode order."""
    out = []
    for line in path.read_text().splitlines():
        if line.strip():
            data = json.loads(line)
            for name in WALL_FIELDS:
                data.pop(name, None)
            out.append(data)
    return sorted(out, key=lambda r: str(r.get("episode_id")))


def digest(recs: list[dict]) -> str:
    return hashlib.sha256("\n".join(json.dumps(r, sort_keys=True) for r in recs).encode()).hexdigest()[:16]


def first_difference(a: dict, b: dict, path: str = "") -> str | None:
    """The dotted path of the first field where ``a`` and ``b`` differ, or None."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if key not in a or key not in b:
                return f"{path}{key} (only in {'after' if key not in a else 'before'})"
            found = first_difference(a[key], b[key], f"{path}{key}.")
            if found:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list):
        for i, (x, y) in enumerate(zip(a, b)):
            found = first_difference(x, y, f"{path}[{i}].")
            if found:
                return found
        return None if len(a) == len(b) else f"{path} (lengths {len(a)} / {len(b)})"
    return None if a == b else f"{path.rstrip('.')}: {a!r} -> {b!r}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/same_records", help="folder for the runs")
    parser.add_argument("--against", default=None, help="an earlier --out to compare with")
    parser.add_argument("--workers", default="2")
    parser.add_argument("--sets", default=",".join(SETS), help="comma-separated: " + ", ".join(SETS))
    args = parser.parse_args()
    root = data_root()
    exe = Path(sys.executable).with_name("hiconav")
    status = 0
    for name in args.sets.split(","):
        out = Path(args.out) / name
        cmd = [str(exe), "eval", *[a.format(root=root) for a in SETS[name]], "--seed", "0", "--preset", "full",
               "--workers", args.workers, "--out", str(out)]
        shutil.rmtree(out, ignore_errors=True)
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
        files = sorted(out.rglob("episodes.jsonl"))
        recs = [r for f in files for r in records(f)]
        line = {"set": name, "episodes": len(recs), "digest": digest(recs)}
        if args.against:
            base = [r for f in sorted((Path(args.against) / name).rglob("episodes.jsonl")) for r in records(f)]
            diffs = []
            for a, b in zip(base, recs):
                found = first_difference(a, b)
                if found:
                    diffs.append(f"{a.get('episode_id')}: {found}")
            if len(base) != len(recs):
                diffs.append(f"{len(base)} records before, {len(recs)} after")
            line.update(identical=not diffs, differing=len(diffs), first=diffs[:3])
            status |= int(bool(diffs))
        print(json.dumps(line))
    return status


if __name__ == "__main__":
    sys.exit(main())
