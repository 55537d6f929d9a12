"""Benchmark metrics from episode records: SR, SPL, DTS, failure taxonomy, timing, ablation deltas.

Definitions (paper, section "Evaluation Metrics", the SR / SPL equation):
- SR  = N_success / N_total.
- SPL = 1/N_total * sum_i S_i * l_i^s / max(l_i^s, l_i^a)   (l^s geodesic shortest path, l^a path
  actually travelled). Records carry their own ``spl``; ``spl_value`` recomputes it.
- DTS = mean distance to success: geodesic distance from the final position to the success
  region (max(0, d_goal - success distance)), as in Habitat; episodes with unknown DTS are left
  out of its mean and counted in ``dts_unknown``.
N_total counts every episode except ``invalid_episode`` ones (bad input: reported and counted in
``episodes`` and ``failures``, but the navigator never ran). Runner crashes (``error``) count
as failures.

This module must not run episodes or draw plots.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from hiconav.eval.presets import PRESETS
from hiconav.eval.records import EpisodeRecord
from hiconav.eval.stats import bootstrap_interval, sign_test_p, turned, wilson_interval
from hiconav.eval.taxonomy import CATEGORIES, Failure


def spl_value(success: bool, shortest: float, actual: float) -> float:
    """S * l_s / max(l_s, l_a) for one episode (paper's SPL equation); 0 for a failure.

    A zero-length shortest path with success counts 1 (already at the goal)."""
    if not success:
        return 0.0
    denominator = max(shortest, actual)
    return 1.0 if denominator <= 0 else float(shortest / denominator)


def semexp_code_spl(success: bool, shortest_to_success: float, success_distance: float, actual: float) -> float:
    """SPL as SemExp's and L3MVN's ``objectgoal_env.py`` compute it for the Gibson maps:
    ``min(S * starting_distance / path_length, 1)`` with ``starting_distance`` the fast-marching
    distance from the start to the success region *plus* the success distance (their
    ``object_boundary``). Published Gibson tables use it; our SPL (``spl_value``) keeps Habitat's
    l^s, the distance to the region alone, and reads lower on the same episodes."""
    if not success:
        return 0.0
    return min(1.0, (float(shortest_to_success) + float(success_distance)) / max(float(actual), 1e-5))


def _mean(values: Sequence[float]) -> float | None:
    return float(sum(values) / len(values)) if values else None


def goal_view(record: EpisodeRecord) -> dict[str, Any] | None:
    """A record's ``extra["goal_in_view"]`` (steps, path_m, to_success_m), or None: no goal was in
    view, or the record predates the field."""
    view = record.extra.get("goal_in_view") if isinstance(record.extra, dict) else None
    return view if isinstance(view, dict) and view.get("path_m") is not None else None


def path_split(records: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """Where the path of the successes went: before a goal was first in view within the depth
    range (``extra["goal_in_view"]``, the simulator's ground truth) and after, against SPL's
    shortest paths; and the failures whose goal never came in view. Records without the field
    (older runs, robots) are left out (``successes_measured``)."""
    wins = [r for r in records if r.success and "goal_in_view" in r.extra]
    seen = [r for r in wins if goal_view(r) is not None]
    fails = [r for r in records if not r.success and "goal_in_view" in r.extra]
    before = float(sum(goal_view(r)["path_m"] for r in seen))
    driven = float(sum(r.path_length for r in seen))
    known = [r for r in seen if goal_view(r).get("to_success_m") is not None]
    return {
        "successes_measured": len(wins),
        "driven_m": driven,
        "shortest_m": float(sum(float(r.extra.get("shortest_to_success", 0.0)) for r in seen)),
        "before_view_m": before,
        "before_view_share": before / driven if driven > 0 else None,
        # after the view: driven from there, and the shortest path from there to the success region
        "after_view_m": float(sum(r.path_length - goal_view(r)["path_m"] for r in known)),
        "after_view_shortest_m": float(sum(goal_view(r)["to_success_m"] for r in known)),
        "failures_measured": len(fails),
        "failures_never_in_view": sum(1 for r in fails if r.extra["goal_in_view"] is None),
        "excess": excess_split(records),
    }


def excess_split(records: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """The path the successes drove beyond SPL's shortest paths, by the behaviour whose goal each
    step served (``extra["excess_path"]``, ``metrics.excess_by_source``: ground truth), most
    first, with each behaviour's share; ``inside_m``: of it, driven inside the success region.
    Records without the field (older runs, robots) are left out (``successes_measured``)."""
    wins = [r for r in records if r.success and isinstance(r.extra, dict)
            and isinstance(r.extra.get("excess_path"), dict)]
    by: dict[str, float] = {}
    for r in wins:
        for name, metres in (r.extra["excess_path"].get("by_behaviour") or {}).items():
            by[str(name)] = by.get(str(name), 0.0) + float(metres)
    whole = sum(by.values())
    return {"successes_measured": len(wins), "excess_m": whole,
            "inside_m": float(sum(float(r.extra["excess_path"].get("inside_m", 0.0)) for r in wins)),
            "by_behaviour": {name: {"m": m, "share": m / whole if whole > 0 else None}
                             for name, m in sorted(by.items(), key=lambda kv: (-kv[1], kv[0]))}}


def action_split(records: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """How the actions of the episodes that count their turns (``extra["turns"]``, the simulator's
    count of discrete turns in place) divide: every action, the turns among them and their share.
    A turn costs a step of the budget (500 in Habitat's ObjectNav) and no path; records without the
    field (older runs, robots) are left out (``episodes_measured``)."""
    counted = [r for r in records if isinstance(r.extra, dict) and isinstance(r.extra.get("turns"), int)]
    actions = int(sum(int(r.steps) for r in counted))
    turns = int(sum(int(r.extra["turns"]) for r in counted))
    return {"episodes_measured": len(counted), "actions": actions, "turns": turns,
            "turn_share": turns / actions if actions > 0 else None,
            "by_behaviour": behaviour_split(counted)}


def behaviour_split(records: Sequence[EpisodeRecord]) -> dict[str, dict[str, Any]]:
    """The actions commanded per behaviour whose goal they served (``extra["actions_by_behaviour"]``,
    the control layer's tally), most first: each behaviour's actions, turns in place among them,
    and its share of all the actions so counted. Records without the field are left out."""
    totals: dict[str, dict[str, int]] = {}
    for r in records:
        per = r.extra.get("actions_by_behaviour") if isinstance(r.extra, dict) else None
        if not isinstance(per, dict):
            continue
        for name, tally in per.items():
            if not isinstance(tally, dict):
                continue
            t = totals.setdefault(str(name), {"actions": 0, "turns": 0})
            t["actions"] += int(sum(int(v) for v in tally.values() if isinstance(v, int)))
            t["turns"] += int(tally.get("turns", 0) or 0)
    whole = sum(t["actions"] for t in totals.values())
    return {name: {**t, "share": t["actions"] / whole if whole else None}
            for name, t in sorted(totals.items(), key=lambda kv: (-kv[1]["actions"], kv[0]))}


def summarize_group(records: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """Metrics of one set of records (one preset)."""
    valid = [r for r in records if r.failure != Failure.INVALID_EPISODE.value]
    dts_known = [float(r.dts) for r in valid if r.dts is not None and math.isfinite(r.dts)]
    counts = Counter(r.failure for r in records)
    failures = {c: counts.get(c, 0) for c in CATEGORIES}
    failures.update({c: n for c, n in counts.items() if c not in failures})  # unknown labels stay visible
    layer_seconds: dict[str, float] = {}
    layer_frames: dict[str, int] = {}
    for r in valid:
        for layer, seconds in r.layer_time_s.items():
            layer_seconds[layer] = layer_seconds.get(layer, 0.0) + float(seconds)
        for layer, frames in r.layer_frames.items():
            layer_frames[layer] = layer_frames.get(layer, 0) + int(frames)
    layers = {layer: {"seconds": layer_seconds[layer], "frames": layer_frames.get(layer, 0),
                      "seconds_per_frame": (layer_seconds[layer] / layer_frames[layer])
                      if layer_frames.get(layer) else None}
              for layer in sorted(layer_seconds)}
    task_time = sum(r.task_time_s for r in valid)
    path_length = sum(r.path_length for r in valid)
    timing = {
        "task_time_s_mean": _mean([r.task_time_s for r in valid]),
        "wall_time_s_mean": _mean([r.wall_time_s for r in records]),
        "wall_time_s_total": float(sum(r.wall_time_s for r in records)),
        "steps_mean": _mean([float(r.steps) for r in valid]),
        "step_speed_m_per_s": path_length / task_time if task_time > 0 else None,
        "vlm_calls_mean": _mean([float(r.vlm_calls) for r in valid]),
        "layers": layers,
    }
    by_target: dict[str, dict[str, Any]] = {}
    path = path_split(valid)
    for target in sorted({r.target for r in valid}):
        group = [r for r in valid if r.target == target]
        by_target[target] = {"episodes": len(group),
                             "success_rate": _mean([float(r.success) for r in group]),
                             "spl": _mean([float(r.spl) for r in group])}
    semexp = [float(r.extra["spl_semexp"]) for r in valid
              if isinstance(r.extra, dict) and r.extra.get("spl_semexp") is not None]
    sr_ci = wilson_interval(sum(bool(r.success) for r in valid), len(valid))
    spl_ci = bootstrap_interval([float(r.spl) for r in valid])
    return {
        "episodes": len(records),
        "valid_episodes": len(valid),
        "success_rate": _mean([float(r.success) for r in valid]),
        "success_rate_ci95": list(sr_ci) if sr_ci else None,  # Wilson score interval
        "spl": _mean([float(r.spl) for r in valid]),
        "spl_ci95": list(spl_ci) if spl_ci else None,  # percentile bootstrap, seeded
        # SemExp's own code's SPL (``semexp_code_spl``) over the episodes on SemExp-rule maps
        # (Gibson): for comparison with published tables only, never the SPL above
        "spl_semexp_code": _mean(semexp),
        "spl_semexp_code_episodes": len(semexp),
        "dts": _mean(dts_known),
        "dts_unknown": len(valid) - len(dts_known),
        "failures": failures,
        "failure_rates": {c: (n / len(records) if records else 0.0) for c, n in failures.items()},
        "timing": timing,
        "path": path,
        "actions": action_split(valid),
        "by_target": by_target,
        "detectors": sorted({r.detector for r in valid if r.detector}),
        "reasoners": sorted({r.reasoner for r in valid if r.reasoner}),
    }


def preset_order(records: Sequence[EpisodeRecord]) -> list[str]:
    """Presets present in ``records``: known presets in their table order, then the others."""
    present = {r.preset for r in records}
    return [p for p in PRESETS if p in present] + sorted(present - set(PRESETS))


def ablation_deltas(records: Sequence[EpisodeRecord], reference: str = "full") -> dict[str, dict[str, Any]]:
    """Each preset's SR / SPL minus the reference preset's, on the episodes both ran (paired)."""
    valid = [r for r in records if r.failure != Failure.INVALID_EPISODE.value]
    ref = {r.episode_id: r for r in valid if r.preset == reference}
    out: dict[str, dict[str, Any]] = {}
    for preset in preset_order(valid):
        if preset == reference:
            continue
        pairs = [(ref[r.episode_id], r) for r in valid if r.preset == preset and r.episode_id in ref]
        if not pairs:
            continue
        n = len(pairs)
        up, down = (len(ids) for ids in turned(pairs))
        out[preset] = {
            "paired_episodes": n,
            "success_rate": sum(float(b.success) for _, b in pairs) / n,
            "spl": sum(b.spl for _, b in pairs) / n,
            "reference_success_rate": sum(float(a.success) for a, _ in pairs) / n,
            "reference_spl": sum(a.spl for a, _ in pairs) / n,
            "delta_success_rate": sum(float(b.success) - float(a.success) for a, b in pairs) / n,
            "delta_spl": sum(b.spl - a.spl for a, b in pairs) / n,
            # episodes that turned into a success / out of one against the reference, and the
            # exact sign test on them (``hiconav.eval.stats``): is the SR difference more than chance?
            "up": up, "down": down, "sign_test_p": sign_test_p(up, down),
        }
    return out


def summarize(records: Sequence[EpisodeRecord]) -> dict[str, Any]:
    """summary.json: the main preset's metrics at the top level ("full" if present, else the
    first), every preset's under ``presets``, and paired ablation deltas under ``ablations``."""
    order = preset_order(records)
    presets = {p: summarize_group([r for r in records if r.preset == p]) for p in order}
    main = "full" if "full" in presets else (order[0] if order else None)
    top = presets[main] if main is not None else summarize_group([])
    return {"preset": main, **top, "presets": presets,
            "ablations": ablation_deltas(records, main) if main is not None else {}}


def write_summary(path: str | Path, summary: dict[str, Any]) -> None:
    Path(path).write_text(json.dumps(summary, indent=2, sort_keys=False, allow_nan=False) + "\n",
                          encoding="utf-8")
