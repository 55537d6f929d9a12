"""Which room an object stands in, learnt from training houses: how often each category stands
in each room type.

The offline reasoner infers an object node's room from the objects seen with it
(``grounding.infer_rooms``). Which objects say which room is a fact about the houses, not
something to write by hand: in the ProcTHOR training houses an armchair or a floor lamp stands in
a bedroom about twice as often as in a living room, a sink always in a bathroom, a bin mostly in
a bathroom. This module counts, for every object category, the room types its instances stand in
(the ground-truth room polygons of *training* houses, never of the houses a mission runs in) and
turns the counts into likelihood ratios for a naive-Bayes room posterior:

    log P(room | cues) = const + sum_i w_i * log( P(room | category_i) / P(room) )

with P(room | category) Laplace-smoothed (``ALPHA``), P(room) the share of all objects standing in
that room type, w_i the cue's distance weight, and a uniform prior over the room types (the
object being described gives no cue of its own). Categories seen fewer than ``MIN_COUNT`` times
give no cue.

The counts ship as ``room_prior.json`` beside this module, written by

    hiconav room-prior --houses ../shared/data/procthor/train.jsonl.gz

Pure apart from ``load`` / ``save`` and ``houses_of``.
"""

from __future__ import annotations

import json
import math
from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any

__all__ = ["ALPHA", "DEFAULT_FILE", "MIN_COUNT", "ROOMS", "ROOM_TYPES", "RoomPrior", "learn", "load", "log_ratios"]

#: the room types the map infers, in a fixed order
ROOMS: tuple[str, ...] = ("bedroom", "bathroom", "kitchen", "living_room")
#: ProcTHOR's roomType -> our room label
ROOM_TYPES: dict[str, str] = {"Bedroom": "bedroom", "Bathroom": "bathroom", "Kitchen": "kitchen",
                              "LivingRoom": "living_room"}
#: Laplace smoothing of P(room | category): a category seen only in bedrooms a few times is not certain
ALPHA = 1.0
#: a category seen fewer times than this in the training houses gives no cue
MIN_COUNT = 10
DEFAULT_FILE = Path(__file__).with_name("room_prior.json")


@dataclass(frozen=True)
class RoomPrior:
    """Counts of object instances per (category, room type) in a set of houses, and where from."""

    counts: Mapping[str, Mapping[str, int]]
    source: str = ""

    def room_shares(self) -> dict[str, float]:
        """P(room): the share of all counted objects standing in each room type (smoothed like
        P(room | category), so that a room type no object was counted in is no infinite cue)."""
        tot = Counter({r: 0 for r in ROOMS})
        for c in self.counts.values():
            for r in ROOMS:
                tot[r] += int(c.get(r, 0))
        n = sum(tot.values())
        if n == 0:
            raise ValueError(f"room prior {self.source or '(in memory)'}: no object counted")
        return {r: (tot[r] + ALPHA) / (n + ALPHA * len(ROOMS)) for r in ROOMS}

    def to_json(self) -> dict[str, Any]:
        return {"source": self.source, "rooms": list(ROOMS),
                "counts": {k: {r: int(v.get(r, 0)) for r in ROOMS} for k, v in sorted(self.counts.items())}}


def log_ratios(prior: RoomPrior, min_count: int = MIN_COUNT, alpha: float = ALPHA) -> dict[str, dict[str, float]]:
    """Category -> room -> log(P(room | category) / P(room)): what seeing one instance adds to
    each room's log-odds. Categories counted fewer than ``min_count`` times are left out."""
    shares = prior.room_shares()
    out: dict[str, dict[str, float]] = {}
    for cat, c in prior.counts.items():
        n = sum(int(c.get(r, 0)) for r in ROOMS)
        if n < min_count:
            continue
        out[cat] = {r: math.log((int(c.get(r, 0)) + alpha) / (n + alpha * len(ROOMS))) - math.log(shares[r])
                    for r in ROOMS}
    return out


def learn(houses: Iterable[Any], source: str = "") -> RoomPrior:
    """Count, over ``houses`` (``hiconav.sim`` houses with room polygons), the room type of every
    object (the room whose polygon holds its centre: ``GroundTruth.room_of``, the rule the
    episode generator describes rooms by). Objects in no room of the four types are skipped."""
    from hiconav.sim.task_episodes import GroundTruth  # the sim is needed only to learn

    counts: dict[str, Counter] = {}
    for house in houses:
        gt = GroundTruth(house)
        for k, obj in enumerate(house.objects):
            room = ROOM_TYPES.get(str(gt.room_of(k)))
            if room is not None:
                counts.setdefault(str(obj.category), Counter())[room] += 1
    return RoomPrior({k: dict(v) for k, v in counts.items()}, source)


def save(prior: RoomPrior, path: str | Path) -> None:
    """Write the counts as JSON, one category a line (readable diffs when the counts change)."""
    data = prior.to_json()
    lines = [f"  {json.dumps(k)}: {json.dumps(v)}" for k, v in data["counts"].items()]
    head = f'{{"source": {json.dumps(data["source"])}, "rooms": {json.dumps(data["rooms"])},\n "counts": {{\n'
    Path(path).write_text(head + ",\n".join(lines) + "\n}}\n")


def from_json(data: Any, path: str = "") -> RoomPrior:
    """A ``RoomPrior`` from its JSON form; a clear error naming the file and field otherwise."""
    where = path or "room prior"
    if not isinstance(data, dict) or not isinstance(data.get("counts"), dict):
        raise ValueError(f"{where}: expected an object with a 'counts' object")
    counts: dict[str, dict[str, int]] = {}
    for cat, c in data["counts"].items():
        if not isinstance(c, dict):
            raise ValueError(f"{where}: counts.{cat}: expected an object of room -> count")
        for r, v in c.items():
            if r not in ROOMS:
                raise ValueError(f"{where}: counts.{cat}.{r}: unknown room type (one of {', '.join(ROOMS)})")
            if not isinstance(v, int) or isinstance(v, bool) or v < 0:
                raise ValueError(f"{where}: counts.{cat}.{r}: expected a count >= 0, got {v!r}")
        counts[str(cat)] = {str(r): int(v) for r, v in c.items()}
    return RoomPrior(counts, str(data.get("source", "")))


def read_json(path: str | Path) -> Any:
    """The JSON of a prior file; a ``ValueError`` naming the file and line where it is not JSON."""
    p = Path(path)
    try:
        return json.loads(p.read_text())
    except json.JSONDecodeError as e:
        raise ValueError(f"{p}: line {e.lineno}: not JSON ({e.msg})") from None


def load(path: str | Path = DEFAULT_FILE) -> RoomPrior:
    return from_json(read_json(path), str(Path(path)))


@lru_cache(maxsize=1)
def default_log_ratios() -> dict[str, dict[str, float]]:
    """``log_ratios`` of the shipped counts (read once)."""
    return log_ratios(load(DEFAULT_FILE))


def houses_of(path: str) -> Iterable[Any]:
    """Every house of a ProcTHOR houses file, loaded one by one (``FILE#N``), uncached."""
    from hiconav.sim import load_house
    from hiconav.sim.procthor import split_lines

    resolved = str(Path(path).expanduser().resolve())
    for i in range(len(split_lines(resolved))):
        yield load_house(f"{resolved}#{i}", cache=False)
