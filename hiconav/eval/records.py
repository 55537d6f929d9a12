"""Per-episode result records and the ``episodes.jsonl`` file that holds them.

One ``EpisodeRecord`` per (preset, episode). The writer appends one JSON line per finished
episode and flushes it at once, so a run that is killed loses at most the line being written;
the reader skips such a truncated last line and the writer cuts it off before appending again
(this is what makes ``hiconav eval`` resumable). ``canonicalise`` rewrites the file sorted by a
stable key so that runs with different worker counts give byte-identical files modulo the
wall-time fields (``WALL_FIELDS``).

This module must not import the simulator or the mission: records are plain data.
"""

from __future__ import annotations

import json
import math
import numbers
import os
from collections.abc import Iterable, Iterator
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any, Self

from hiconav.errors import DataError

#: Fields measured on the wall clock: they differ between runs and are ignored when comparing.
WALL_FIELDS: tuple[str, ...] = ("wall_time_s", "layer_time_s")


@dataclass
class EpisodeRecord:
    """The outcome of one episode under one preset.

    Trace fields used by the failure taxonomy (``hiconav.eval.taxonomy``): ``termination``
    ("stop" | "no_frontier" | "step_limit" | "stuck" | "error"), ``steps``, ``max_steps`` and
    ``last_progress_step`` (the last step at which the robot made progress; see
    ``taxonomy.last_progress_step``). ``failure`` is filled in by the harness when empty.

    Timing: ``task_time_s`` is stepped (simulated) time and deterministic; ``wall_time_s`` and
    ``layer_time_s`` (seconds of wall time spent in each layer, summed over the episode) are
    measured; ``layer_frames`` counts the frames (ticks) each layer processed, so seconds per
    frame = ``layer_time_s[l] / layer_frames[l]``.
    """

    episode_id: str
    house: str
    target: str
    preset: str = "full"
    seed: int = 0
    success: bool = False
    spl: float = 0.0
    dts: float = math.inf
    steps: int = 0
    max_steps: int = 500
    path_length: float = 0.0
    geodesic_distance: float = 0.0
    termination: str = "error"
    last_progress_step: int | None = None
    failure: str = ""
    task_time_s: float = 0.0
    wall_time_s: float = 0.0
    layer_time_s: dict[str, float] = field(default_factory=dict)
    layer_frames: dict[str, int] = field(default_factory=dict)
    vlm_calls: int = 0
    detector: str = ""
    reasoner: str = ""
    error: str | None = None
    error_kind: str | None = None  # "data" (bad input) | "config" | "runtime" (a crash in the runner)
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def key(self) -> tuple[str, str]:
        """Resume key: a (preset, episode id) pair is run once per output folder."""
        return (self.preset, self.episode_id)

    def to_json(self) -> dict[str, Any]:
        """The JSON dict. JSON has no infinity or NaN: every non-finite number (an unreachable
        goal's infinite distance, a NaN from a broken run) is written as null, and its path and
        what it was are listed in ``nonfinite`` ({"geodesic_distance": "inf"}), so that reading
        the record back restores it. A DTS of null alone means an unknown distance to success."""
        data = asdict(self)
        reasons: dict[str, str] = {}
        data = _finite(data, "", reasons)
        reasons.pop("dts", None)  # null DTS is the documented "unknown", no reason needed
        if reasons:
            data["nonfinite"] = reasons
        return data

    @staticmethod
    def from_json(data: dict[str, Any], *, file: str | None = None, line: int | None = None) -> EpisodeRecord:
        known = {f.name for f in fields(EpisodeRecord)}
        missing = [name for name in ("episode_id", "house", "target") if name not in data]
        if missing:
            raise DataError(f"episode record lacks {', '.join(missing)}", file=file, line=line)
        nonfinite = data.get("nonfinite") if isinstance(data.get("nonfinite"), dict) else {}
        kwargs = {k: (_restore(nonfinite[k]) if k in nonfinite and v is None else v)
                  for k, v in data.items() if k in known}
        extra = dict(kwargs.pop("extra", None) or {})
        extra.update({k: v for k, v in data.items() if k not in known and k != "nonfinite"})
        if kwargs.get("dts") is None:
            kwargs["dts"] = math.inf
        return EpisodeRecord(**kwargs, extra=extra)

    @staticmethod
    def from_metrics(metrics: Any, *, termination: str, max_steps: int, **fields_: Any) -> EpisodeRecord:
        """From a ``hiconav.sim.metrics.EpisodeMetrics`` (duck-typed: episode_id, house, target,
        success, spl, dts, steps, path_length, shortest); other fields by keyword, e.g.
        ``last_progress_step``, ``task_time_s``, ``layer_time_s``, ``vlm_calls``, ``detector``."""
        extra = dict(fields_.pop("extra", None) or {})
        extra.setdefault("collisions", int(getattr(metrics, "collisions", 0)))
        if getattr(metrics, "shortest_to_success", None) is not None:
            extra.setdefault("shortest_to_success", float(metrics.shortest_to_success))  # SPL's l
        return EpisodeRecord(episode_id=str(metrics.episode_id), house=str(metrics.house),
                             target=str(metrics.target), success=bool(metrics.success),
                             spl=float(metrics.spl), dts=float(metrics.dts), steps=int(metrics.steps),
                             max_steps=int(max_steps), path_length=float(metrics.path_length),
                             geodesic_distance=float(metrics.shortest), termination=termination,
                             extra=extra, **fields_)

    def deterministic_view(self) -> dict[str, Any]:
        """The JSON dict without the wall-clock fields (what must match across runs)."""
        data = self.to_json()
        for name in WALL_FIELDS:
            data.pop(name, None)
        return data


def _finite(value: Any, path: str, reasons: dict[str, str]) -> Any:
    """``value`` with every non-finite float replaced by None (its path noted in ``reasons``)."""
    if isinstance(value, numbers.Real) and not isinstance(value, numbers.Integral):
        number = float(value)
        if not math.isfinite(number):
            reasons[path] = "nan" if math.isnan(number) else ("inf" if number > 0 else "-inf")
            return None
        return value
    if isinstance(value, dict):
        return {k: _finite(v, f"{path}.{k}" if path else str(k), reasons) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v, f"{path}[{i}]", reasons) for i, v in enumerate(value)]
    return value


def _restore(reason: Any) -> float:
    return {"inf": math.inf, "-inf": -math.inf}.get(str(reason), math.nan)


def dumps(record: EpisodeRecord) -> str:
    """One JSON line (sorted keys, no NaN/inf)."""
    return json.dumps(record.to_json(), sort_keys=True, allow_nan=False, default=_json_default)


def _json_default(obj: Any) -> Any:
    # numpy scalars and tuples from runners
    if hasattr(obj, "item"):
        return obj.item()
    if isinstance(obj, (set, frozenset)):
        return sorted(obj)
    raise TypeError(f"cannot write {type(obj).__name__} to episodes.jsonl")


def iter_records(path: str | Path) -> Iterator[EpisodeRecord]:
    """Records of ``path`` in file order; a truncated (unterminated, unparsable) last line is
    skipped, any other bad line raises ``DataError`` naming the file and line."""
    path = Path(path)
    if not path.exists():
        return
    with path.open("r", encoding="utf-8") as fh:
        lines = fh.readlines()
    for number, text in enumerate(lines, start=1):
        if not text.strip():
            continue
        try:
            data = json.loads(text)
        except json.JSONDecodeError as exc:
            if number == len(lines) and not text.endswith("\n"):
                return  # a write interrupted by a kill: the episode is simply run again
            raise DataError(f"not a JSON line ({exc.msg})", file=str(path), line=number) from exc
        if not isinstance(data, dict):
            raise DataError("expected a JSON object per line", file=str(path), line=number)
        yield EpisodeRecord.from_json(data, file=str(path), line=number)


def read_records(path: str | Path) -> list[EpisodeRecord]:
    return list(iter_records(path))


def done_keys(path: str | Path) -> set[tuple[str, str]]:
    """(preset, episode id) of every complete record in ``path`` (for resume)."""
    return {record.key for record in iter_records(path)}


class RecordWriter:
    """Appends records to a jsonl file, one flushed line each (crash-safe up to one line)."""

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        _cut_partial_line(self.path)
        self._fh = self.path.open("a", encoding="utf-8")

    def write(self, record: EpisodeRecord) -> None:
        self._fh.write(dumps(record) + "\n")
        self._fh.flush()

    def close(self) -> None:
        if not self._fh.closed:
            self._fh.close()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _cut_partial_line(path: Path) -> None:
    """Drop an unterminated last line (left by a killed run) so appends start on a fresh line."""
    if not path.exists() or path.stat().st_size == 0:
        return
    with path.open("rb+") as fh:
        data = fh.read()
        if data.endswith(b"\n"):
            return
        fh.truncate(data.rfind(b"\n") + 1)


def canonicalise(path: str | Path, order: Iterable[tuple[str, str]] | None = None) -> list[EpisodeRecord]:
    """Rewrite ``path`` atomically in a stable order: by position in ``order`` (preset,
    episode id) when given, else sorted by key. Duplicate keys keep their first record."""
    path = Path(path)
    records = read_records(path)
    rank = {key: i for i, key in enumerate(order)} if order is not None else {}
    unique: dict[tuple[str, str], EpisodeRecord] = {}
    for record in records:
        unique.setdefault(record.key, record)
    ordered = sorted(unique.values(), key=lambda r: (rank.get(r.key, len(rank)), r.key))
    tmp = path.with_suffix(path.suffix + ".tmp")
    with tmp.open("w", encoding="utf-8") as fh:
        for record in ordered:
            fh.write(dumps(record) + "\n")
    os.replace(tmp, path)
    return ordered
