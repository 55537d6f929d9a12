"""How sure a figure is: confidence intervals of SR and SPL, and paired comparisons of two runs.

A success rate over 99 episodes moves by a point per episode, and exploration is chaotic: a
change to any rule reshuffles which long searches succeed, so two runs of the same method that
differ in one rule typically differ in several episodes each way. These functions say how much of
a difference is more than that reshuffling:

* ``wilson_interval``: the Wilson score interval of a success rate (a binomial proportion).
* ``bootstrap_interval``: a percentile bootstrap interval of a mean (SPL, or a paired SPL
  difference), with a seeded generator so that a summary is the same on every machine.
* ``sign_test_p``: the exact two-sided sign test (McNemar's exact test) on the episodes that
  changed outcome between two paired runs: ``up`` turned into successes, ``down`` out of them.
  Under "no effect" each changed episode is as likely to go either way.
* ``paired_comparison``: all of the above for two sets of records of the same episodes.

Pure functions of plain numbers and records; no I/O.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np

from hiconav.eval.taxonomy import Failure

Z95 = 1.959963984540054  # the standard normal's 97.5% quantile
BOOTSTRAP_RESAMPLES = 2000
BOOTSTRAP_SEED = 0


def wilson_interval(successes: int, n: int, z: float = Z95) -> tuple[float, float] | None:
    """The Wilson score interval (lo, hi) of ``successes`` out of ``n`` (95% by default); None for n = 0."""
    if n <= 0:
        return None
    if not 0 <= successes <= n:
        raise ValueError(f"successes must lie in [0, n], got {successes} of {n}")
    p = successes / n
    z2 = z * z
    centre = (p + z2 / (2 * n)) / (1 + z2 / n)
    half = z * math.sqrt(p * (1 - p) / n + z2 / (4 * n * n)) / (1 + z2 / n)
    return max(0.0, centre - half), min(1.0, centre + half)


def bootstrap_interval(values: Sequence[float], level: float = 0.95, resamples: int = BOOTSTRAP_RESAMPLES,
                       seed: int = BOOTSTRAP_SEED) -> tuple[float, float] | None:
    """A percentile bootstrap interval (lo, hi) of the mean of ``values``; None when empty."""
    x = np.asarray(list(values), dtype=np.float64)
    if x.size == 0:
        return None
    if not np.all(np.isfinite(x)):
        raise ValueError("bootstrap_interval takes finite values only")
    rng = np.random.default_rng(seed)
    means = x[rng.integers(0, x.size, size=(int(resamples), x.size))].mean(axis=1)
    tail = (1.0 - level) / 2.0
    lo, hi = np.quantile(means, [tail, 1.0 - tail])
    return float(lo), float(hi)


def sign_test_p(up: int, down: int) -> float:
    """Exact two-sided sign test p-value of ``up`` against ``down`` changed outcomes (1.0 when none)."""
    n = up + down
    if n == 0:
        return 1.0
    k = min(up, down)
    tail = sum(math.comb(n, i) for i in range(k + 1)) / 2.0 ** n
    return min(1.0, 2.0 * tail)


def turned(pairs: Iterable[tuple[Any, Any]]) -> tuple[list[str], list[str]]:
    """The episode ids of (before, after) record pairs that turned into a success (``up``) and out
    of one (``down``): what the sign test counts."""
    up: list[str] = []
    down: list[str] = []
    for a, b in pairs:
        if bool(a.success) != bool(b.success):
            (up if b.success else down).append(b.episode_id)
    return up, down


def _by_id(records: Iterable[Any]) -> dict[str, Any]:
    return {r.episode_id: r for r in records if r.failure != Failure.INVALID_EPISODE.value}


def paired_comparison(before: Iterable[Any], after: Iterable[Any]) -> dict[str, Any]:
    """Two runs' records (``EpisodeRecord``-like: episode_id, success, spl, seed, failure) paired by
    episode id, invalid episodes left out: SR and SPL of each, the episodes that turned into a
    success (``up``) and out of one (``down``), the sign test's p-value on them, and the paired
    SPL difference with its bootstrap interval. ``same_seed``: pairs run with one seed (a
    comparison across seeds measures the seed as well as the change)."""
    a, b = _by_id(before), _by_id(after)
    ids = sorted(set(a) & set(b))
    n = len(ids)
    up, down = turned((a[i], b[i]) for i in ids)
    d_spl = [float(b[i].spl) - float(a[i].spl) for i in ids]

    def side(recs: dict[str, Any]) -> dict[str, Any]:
        wins = sum(bool(recs[i].success) for i in ids)
        ci = wilson_interval(wins, n)
        spl = [float(recs[i].spl) for i in ids]
        return {"sr": wins / n if n else None, "sr_ci95": list(ci) if ci else None,
                "spl": sum(spl) / n if n else None}

    ci = bootstrap_interval(d_spl)
    return {"paired": n, "only_before": len(set(a) - set(b)), "only_after": len(set(b) - set(a)),
            "same_seed": sum(1 for i in ids if getattr(a[i], "seed", None) == getattr(b[i], "seed", None)),
            "before": side(a), "after": side(b), "up": len(up), "down": len(down),
            "sign_test_p": sign_test_p(len(up), len(down)),
            "delta_sr": (len(up) - len(down)) / n if n else None,
            "delta_spl": sum(d_spl) / n if n else None, "delta_spl_ci95": list(ci) if ci else None,
            "up_ids": up, "down_ids": down}


__all__ = ["bootstrap_interval", "paired_comparison", "sign_test_p", "turned", "wilson_interval"]
