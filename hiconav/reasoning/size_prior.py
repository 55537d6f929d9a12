"""How large an object of each category is, learnt from training houses: the footprint a memory
box seen in part may still grow to.

A memory node's box is built from the depth points the robot saw of its object. Seen edge-on or
in part, the box of a counter can be 0.02 m thick and the box of a dining table end 0.3 m deep: a
relation read on such a box ("the painting next to the counter": the counter's box stops 2.4 m
from the painting, the counter itself 0.5 m) says nothing certain yet. How large objects are is a
fact about the houses, not something to write by hand: this module takes, for every object
category, the median long and short sides of its instances' footprints in the ProcTHOR
*training* houses (never the houses a mission runs in), and ``grounding`` reads a relation that
fails on a related object's box narrower than its kind's short side, but would hold on the box
grown to it, as unknown rather than failed (``grounding.could_hold``).

The sizes ship as ``size_prior.json`` beside this module, written by

    hiconav size-prior --houses ../shared/data/procthor/train.jsonl.gz

Pure apart from ``load`` / ``save``.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.reasoning.room_prior import read_json

__all__ = ["DEFAULT_FILE", "MIN_COUNT", "SizePrior", "default_sizes", "learn", "load", "save"]

#: a category with fewer instances than this in the training houses has no size
MIN_COUNT = 5
DEFAULT_FILE = Path(__file__).with_name("size_prior.json")


@dataclass(frozen=True)
class SizePrior:
    """Category -> (long side, short side) of its footprint in metres (medians over instances),
    with the number of instances each was taken over, and where from."""

    sizes: Mapping[str, tuple[float, float]]
    counts: Mapping[str, int]
    source: str = ""

    def to_json(self) -> dict[str, Any]:
        return {"source": self.source,
                "sizes": {k: {"long": round(float(v[0]), 3), "short": round(float(v[1]), 3),
                              "n": int(self.counts.get(k, 0))} for k, v in sorted(self.sizes.items())}}


def learn(houses: Iterable[Any], source: str = "", min_count: int = MIN_COUNT) -> SizePrior:
    """The median long and short footprint sides of every category's instances over ``houses``
    (``hiconav.sim`` houses); instances whose size is a fallback (``default_size``) are skipped,
    and so are categories with fewer than ``min_count`` instances."""
    sides: dict[str, list[tuple[float, float]]] = {}
    for house in houses:
        for obj in house.objects:
            if getattr(obj, "default_size", False):
                continue
            sx, sy = float(obj.size[0]), float(obj.size[1])
            sides.setdefault(str(obj.category), []).append((max(sx, sy), min(sx, sy)))
    sizes: dict[str, tuple[float, float]] = {}
    counts: dict[str, int] = {}
    for cat, v in sides.items():
        if len(v) < min_count:
            continue
        a = np.asarray(v, dtype=np.float64)
        sizes[cat] = (float(np.median(a[:, 0])), float(np.median(a[:, 1])))
        counts[cat] = len(v)
    return SizePrior(sizes, counts, source)


def save(prior: SizePrior, path: str | Path) -> None:
    """Write the sizes as JSON, one category a line (readable diffs when they change)."""
    data = prior.to_json()
    lines = [f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in data["sizes"].items()]
    Path(path).write_text(f'{{"source": {json.dumps(data["source"])},\n "sizes": {{\n' + ",\n".join(lines) + "\n}}\n")


def from_json(data: Any, path: str = "") -> SizePrior:
    """A ``SizePrior`` from its JSON form; a clear error naming the file and field otherwise."""
    where = path or "size prior"
    if not isinstance(data, dict) or not isinstance(data.get("sizes"), dict):
        raise ValueError(f"{where}: expected an object with a 'sizes' object")
    sizes: dict[str, tuple[float, float]] = {}
    counts: dict[str, int] = {}
    for cat, v in data["sizes"].items():
        if not isinstance(v, dict):
            raise ValueError(f"{where}: sizes.{cat}: expected an object with 'long' and 'short'")
        pair = []
        for key in ("long", "short"):
            x = v.get(key)
            if not isinstance(x, (int, float)) or isinstance(x, bool) or not np.isfinite(x) or x < 0:
                raise ValueError(f"{where}: sizes.{cat}.{key}: expected a length >= 0 in metres, got {x!r}")
            pair.append(float(x))
        if pair[1] > pair[0]:
            raise ValueError(f"{where}: sizes.{cat}: 'short' ({pair[1]}) is longer than 'long' ({pair[0]})")
        sizes[str(cat)] = (pair[0], pair[1])
        n = v.get("n", 0)
        counts[str(cat)] = int(n) if isinstance(n, int) else 0
    return SizePrior(sizes, counts, str(data.get("source", "")))


def load(path: str | Path = DEFAULT_FILE) -> SizePrior:
    return from_json(read_json(path), str(Path(path)))


@lru_cache(maxsize=1)
def default_sizes() -> Mapping[str, tuple[float, float]]:
    """The shipped sizes (read once)."""
    return dict(load(DEFAULT_FILE).sizes)
