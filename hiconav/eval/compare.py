"""Compare two runs of the same episodes, episode by episode.

``python -m hiconav.eval.compare BEFORE AFTER [--preset P] [--preset-after Q]``

BEFORE and AFTER are ``hiconav eval`` output folders (their ``episodes.jsonl``) or records files;
they may be one folder, to compare two of its presets (``--preset full --preset-after
no_reasoning``). Prints every episode whose outcome or step count changed, then SR and SPL of
both with 95% intervals, how many episodes turned into a success and out of one, the exact sign
test on those, and the paired SPL difference with its bootstrap interval
(``hiconav.eval.stats``); the last line is one JSON object:

    {"paired": N, "before": {"sr", "sr_ci95", "spl"}, "after": {...}, "up": U, "down": D,
     "sign_test_p": p, "delta_sr": x, "delta_spl": y, "delta_spl_ci95": [lo, hi], ...}

When both runs' records say where the path went (``extra.goal_in_view``, docs/evaluation.md), a
line before the JSON splits the path of the episodes that succeeded in both at the first frame
with a goal in view, so that a change is seen moving exploration (before) or verification and
the approach (after); the JSON gains ``"path": {"episodes", "before_view_m": [before, after],
"after_view_m": [before, after]}``.

A change whose ``up`` and ``down`` a sign test cannot tell apart (p well above 0.05) has not been
shown to do anything: four up and one down is p = 0.375, however many episodes ran. It reads
files only.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from hiconav.errors import DataError
from hiconav.eval.records import read_records
from hiconav.eval.runner import EPISODES_FILE
from hiconav.eval.stats import paired_comparison
from hiconav.eval.summary import goal_view


def _records(path: Path, preset: str | None) -> list[Any]:
    file = path / EPISODES_FILE if path.is_dir() else path
    if not file.is_file():
        raise DataError("no episode records here (an `hiconav eval` --out folder or its episodes.jsonl)",
                        file=str(path))
    try:
        records = read_records(file)  # a bad line raises DataError naming it
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read episode records: {exc}", file=str(file)) from exc
    presets = sorted({r.preset for r in records})
    if preset is None:
        if len(presets) > 1:
            raise DataError(f"records of several presets ({', '.join(presets)}): name one with --preset",
                            file=str(file))
        return records
    chosen = [r for r in records if r.preset == preset]
    if not chosen:
        raise DataError(f"no records of preset {preset!r} (presets here: {', '.join(presets) or 'none'})",
                        file=str(file), field="--preset")
    return chosen


def _pct(x: float | None) -> str:
    return "-" if x is None else f"{100.0 * x:.1f}"


def _line(r: Any) -> str:
    return f"{r.failure:15s} {r.steps:4d} {float(r.spl):.2f}"


def paired_path_split(by_a: dict[str, Any], by_b: dict[str, Any]) -> dict[str, Any] | None:
    """Path before / after the first frame with a goal in view, summed over the episodes that
    succeeded in both runs with the field in both (``summary.goal_view``); None when none has it."""
    pairs = [(by_a[e], by_b[e]) for e in sorted(set(by_a) & set(by_b))
             if by_a[e].success and by_b[e].success and goal_view(by_a[e]) and goal_view(by_b[e])]
    if not pairs:
        return None
    runs = list(zip(*pairs))  # (A's records, B's records)
    before = [sum(float(goal_view(r)["path_m"]) for r in run) for run in runs]
    after = [sum(float(r.path_length) for r in run) - b for run, b in zip(runs, before)]
    return {"episodes": len(pairs), "before_view_m": before, "after_view_m": after}


def compare(before: Path, after: Path, preset: str | None = None, preset_after: str | None = None
            ) -> tuple[dict[str, Any], list[str]]:
    """The paired comparison of two runs and the printed lines of the episodes that changed."""
    a = _records(before, preset)
    b = _records(after, preset_after if preset_after is not None else preset)
    result = paired_comparison(a, b)
    by_a, by_b = {r.episode_id: r for r in a}, {r.episode_id: r for r in b}
    split = paired_path_split(by_a, by_b)
    if split is not None:
        result["path"] = split
    lines = []
    for eid in sorted(set(by_a) & set(by_b)):
        ra, rb = by_a[eid], by_b[eid]
        if (ra.success, ra.steps, ra.failure) != (rb.success, rb.steps, rb.failure):
            mark = "+" if rb.success and not ra.success else ("-" if ra.success and not rb.success else " ")
            lines.append(f"{mark} {eid:24s} {_line(ra)} -> {_line(rb)}")
    return result, lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path, help="an eval --out folder or episodes.jsonl")
    parser.add_argument("after", type=Path, help="an eval --out folder or episodes.jsonl")
    parser.add_argument("--preset", default=None, help="the preset to read (needed when a file holds several)")
    parser.add_argument("--preset-after", default=None, help="AFTER's preset, when it differs from --preset")
    args = parser.parse_args(argv)
    try:
        result, lines = compare(args.before, args.after, args.preset, args.preset_after)
    except DataError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    for line in lines:
        print(line)
    n = result["paired"]
    b, c = result["before"], result["after"]
    print(f"paired episodes: {n} (only before {result['only_before']}, only after {result['only_after']}; "
          f"same seed {result['same_seed']})")
    if n:
        print(f"before SR {_pct(b['sr'])}% [{_pct(b['sr_ci95'][0])}, {_pct(b['sr_ci95'][1])}]  SPL {_pct(b['spl'])}%")
        print(f"after  SR {_pct(c['sr'])}% [{_pct(c['sr_ci95'][0])}, {_pct(c['sr_ci95'][1])}]  SPL {_pct(c['spl'])}%")
        lo, hi = result["delta_spl_ci95"]
        print(f"up {result['up']}, down {result['down']}: sign test p = {result['sign_test_p']:.3f}; "
              f"dSPL {_pct(result['delta_spl'])} pts [{_pct(lo)}, {_pct(hi)}]")
    if "path" in result:
        p = result["path"]
        print(f"path of the {p['episodes']} successes in both: before a goal in view "
              f"{p['before_view_m'][0]:.1f} -> {p['before_view_m'][1]:.1f} m, after "
              f"{p['after_view_m'][0]:.1f} -> {p['after_view_m'][1]:.1f} m")
    print(json.dumps({k: v for k, v in result.items() if k not in ("up_ids", "down_ids")}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
