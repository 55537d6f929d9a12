"""Runs benchmark episodes in parallel (local worker processes or Ray tasks) and records them.

The episode itself is run by an ``EpisodeRunner`` chosen by import path (default
``hiconav.mission:run_episode``, the stepped-clock mission), so that worker processes and Ray
tasks import it by name. The harness owns everything around it: seeds (derived per episode from
the base seed, identical for every preset, so ablations run the same episodes), error capture
(bad input and crashes become records, never abort the run), the failure category (from
``taxonomy.classify``), appending to ``episodes.jsonl`` as results arrive, resume, the progress
bar, and the final summary and report.

This module must not implement navigation. Ray is optional and imported lazily.
"""

from __future__ import annotations

import functools
import importlib
import math
import multiprocessing
import os
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Self

from hiconav.errors import ConfigError, DataError, FrameError, HiconavError
from hiconav.eval.config import DEFAULT_RUNNER, EvalConfig
from hiconav.eval.presets import overrides_for, resolve_presets
from hiconav.eval.records import EpisodeRecord, RecordWriter, canonicalise, done_keys, read_records
from hiconav.eval.sources import EpisodeSpec, derive_seed
from hiconav.eval.taxonomy import classify

#: The per-episode runner: (episode, dotted config overrides, seed) -> record. It must be
#: deterministic given its arguments (stepped clock); wall-time fields are exempt.
EpisodeRunner = Callable[[EpisodeSpec, dict[str, Any], int], EpisodeRecord]

EPISODES_FILE = "episodes.jsonl"


@dataclass(frozen=True)
class Task:
    """One (preset, episode) to run: small and picklable."""

    spec: EpisodeSpec
    preset: str
    overrides: dict[str, Any] = field(default_factory=dict)
    seed: int = 0
    runner: str = DEFAULT_RUNNER
    stuck_window: int = 50

    @property
    def key(self) -> tuple[str, str]:
        return (self.preset, self.spec.episode_id)


@functools.lru_cache(maxsize=16)
def resolve_runner(path: str) -> EpisodeRunner:
    """Import ``module:function`` (cached per process); ``ConfigError`` if it cannot."""
    module_name, sep, attr = path.partition(":")
    if not sep or not module_name or not attr:
        raise ConfigError(f"runner {path!r} is not an import path 'module:function'", field="runner")
    try:
        runner = getattr(importlib.import_module(module_name), attr)
    except (ImportError, AttributeError) as exc:
        raise ConfigError(f"cannot import episode runner {path!r}: {exc}", field="runner") from exc
    if not callable(runner):
        raise ConfigError(f"episode runner {path!r} is not callable", field="runner")
    return runner


def run_task(task: Task) -> EpisodeRecord:
    """Run one task in this process and return its complete record (never raises for bad
    input or runner crashes: those become ``invalid_episode`` / ``error`` records)."""
    spec = task.spec
    start = time.perf_counter()
    record: EpisodeRecord
    if spec.error:
        record = _error_record(spec, spec.error, "data")
    else:
        try:
            record = resolve_runner(task.runner)(spec, dict(task.overrides), task.seed)
            if not isinstance(record, EpisodeRecord):
                raise TypeError(f"runner {task.runner} returned {type(record).__name__}, not EpisodeRecord")
        except (DataError, FrameError) as exc:  # bad input: an invalid episode
            record = _error_record(spec, f"{type(exc).__name__}: {exc}", "data")
        except HiconavError as exc:  # e.g. a ConfigError for an unknown override: an error
            record = _error_record(spec, f"{type(exc).__name__}: {exc}", "config")
        except Exception as exc:  # noqa: BLE001 - a crash in one episode must not end the run
            where = traceback.extract_tb(exc.__traceback__)[-1] if exc.__traceback__ else None
            at = f" at {Path(where.filename).name}:{where.lineno}" if where else ""
            record = _error_record(spec, f"{type(exc).__name__}: {exc}{at}", "runtime")
    wall = time.perf_counter() - start
    record = replace(record, episode_id=spec.episode_id, house=record.house or spec.house,
                     target=record.target or spec.target, preset=task.preset, seed=task.seed,
                     geodesic_distance=record.geodesic_distance or spec.geodesic_distance,
                     wall_time_s=record.wall_time_s or wall)
    task_name = getattr(spec, "task", "objectnav")
    if task_name != "objectnav":  # ObjectNav records stay as they were; other tasks say which
        record = replace(record, extra={**record.extra, "task": task_name})
    failure = classify(record.to_json(), stuck_window=task.stuck_window).value
    return replace(record, failure=failure)


def _error_record(spec: EpisodeSpec, message: str, kind: str) -> EpisodeRecord:
    return EpisodeRecord(episode_id=spec.episode_id, house=spec.house, target=spec.target,
                         geodesic_distance=spec.geodesic_distance, termination="error",
                         dts=math.inf, error=message, error_kind=kind)


def make_tasks(specs: Sequence[EpisodeSpec], config: EvalConfig) -> list[Task]:
    """Every (preset, episode) pair, presets outermost; seeds depend on the episode only."""
    presets = resolve_presets(list(config.presets))
    return [Task(spec=spec, preset=preset, overrides=overrides_for(preset, config.overrides),
                 seed=derive_seed(config.seed, spec.episode_id), runner=config.runner,
                 stuck_window=config.stuck_window)
            for preset in presets for spec in specs]


# ---------------------------------------------------------------------------------------- backends

OnResult = Callable[[EpisodeRecord], None]


def run_in_process(tasks: Iterable[Task], on_result: OnResult) -> None:
    """Run tasks one after another in this process (``--workers 0``: debugging, profiling)."""
    for task in tasks:
        on_result(run_task(task))


# Thread settings for each worker process (the pool already uses every core); a value the user
# set in the environment wins. LP_NUM_THREADS=0 makes Mesa's llvmpipe rasterise in the calling
# thread: with every core busy, its render threads only contend with the worker's own numpy work
# (a 500-step episode took 11.7 s with them, 10.1 s without, alone on 2 cores).
WORKER_THREAD_ENV = {"OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
                     "NUMBA_NUM_THREADS": "1", "LP_NUM_THREADS": "0"}


def _init_worker() -> None:
    """Apply ``WORKER_THREAD_ENV`` (unless set) before the worker imports torch or numba or
    creates its OpenGL context, which read these variables once."""
    for name, value in WORKER_THREAD_ENV.items():
        os.environ.setdefault(name, value)


def run_local(tasks: Sequence[Task], on_result: OnResult, *, workers: int,
              start_method: str = "forkserver") -> None:
    """Run tasks in ``workers`` processes (a forkserver or spawn context: no forked threads);
    ``on_result`` is called in this process as each finishes. Ctrl-C cancels pending tasks."""
    if not tasks:
        return
    if start_method not in multiprocessing.get_all_start_methods():
        start_method = "spawn"
    context = multiprocessing.get_context(start_method)
    if start_method == "forkserver":
        context.set_forkserver_preload(["hiconav.eval.runner"])
    pool = ProcessPoolExecutor(max_workers=max(1, min(workers, len(tasks))), mp_context=context,
                               initializer=_init_worker)
    try:
        # Keep at most 2 tasks per worker in flight so that Ctrl-C stops quickly.
        queue = list(reversed(tasks))
        pending: set[Future[EpisodeRecord]] = set()
        while queue or pending:
            while queue and len(pending) < 2 * max(1, workers):
                pending.add(pool.submit(run_task, queue.pop()))
            done, pending = wait(pending, return_when=FIRST_COMPLETED)
            for future in done:
                on_result(future.result())
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def run_ray(tasks: Sequence[Task], on_result: OnResult, *, address: str | None = None,
            num_cpus: int | None = None) -> None:
    """Run tasks as Ray tasks (one CPU each) on the cluster at ``address``, or on a local Ray
    instance when None (or on the instance this process already joined). Results are identical
    to the local backend: the same ``run_task`` runs in the Ray worker."""
    try:
        import ray
    except ImportError as exc:
        raise ConfigError("the ray backend needs Ray: pip install 'hiconav[ray]'", field="--backend") from exc
    if not tasks:
        return
    started = False
    if not ray.is_initialized():
        kwargs: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
        if address:
            kwargs["address"] = address
        else:
            kwargs["num_cpus"] = num_cpus
        try:
            ray.init(**kwargs)
        except Exception as exc:
            raise ConfigError(f"cannot start or join Ray at {address or 'local'}: {exc}", field="--address") from exc
        started = True
    try:
        remote = ray.remote(num_cpus=1, max_retries=1)(run_task)
        pending = [remote.remote(task) for task in tasks]
        while pending:
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                on_result(ray.get(ref))
    finally:
        if started:
            ray.shutdown()


# ---------------------------------------------------------------------------------------- progress


class _Progress:
    """A rich progress bar with ETA and the running SR / SPL of the records seen so far."""

    def __init__(self, total: int, done: int, enabled: bool) -> None:
        self.successes = 0
        self.spl_sum = 0.0
        self.count = 0
        self._bar = None
        if enabled and total:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._bar = Progress(TextColumn("[bold]eval"), BarColumn(), MofNCompleteColumn(),
                                 TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(),
                                 TextColumn("{task.fields[stats]}"), console=Console(stderr=True),
                                 transient=False)
            self._task = self._bar.add_task("eval", total=total, completed=done, stats="")

    def __enter__(self) -> Self:
        if self._bar is not None:
            self._bar.start()
        return self

    def __exit__(self, *exc: object) -> None:
        if self._bar is not None:
            self._bar.stop()

    def update(self, record: EpisodeRecord) -> None:
        if record.failure == "invalid_episode":  # bad input: counted in the bar, not in SR / SPL
            if self._bar is not None:
                self._bar.update(self._task, advance=1)
            return
        self.count += 1
        self.successes += int(record.success)
        self.spl_sum += float(record.spl)
        if self._bar is not None:
            stats = (f"SR {self.successes / self.count:.3f}  SPL {self.spl_sum / self.count:.3f}  "
                     f"last {record.failure}")
            self._bar.update(self._task, advance=1, stats=stats)


# -------------------------------------------------------------------------------------- evaluate


def evaluate(specs: Sequence[EpisodeSpec], out: str | Path, config: EvalConfig | None = None,
             *, run_info: dict[str, Any] | None = None) -> dict[str, Any]:
    """Run every (preset, episode) not yet in ``out/episodes.jsonl``, append each record as it
    finishes, then rewrite the file in canonical order and write summary.json and report.md.

    Returns the summary (``hiconav.eval.summary.summarize``) of every record in the file.
    """
    config = config or EvalConfig()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    path = out / EPISODES_FILE
    tasks = make_tasks(specs, config)
    if config.backend == "local":
        resolve_runner(config.runner)  # a bad --runner fails here, once, not in every episode
    done = done_keys(path)
    todo = [task for task in tasks if task.key not in done]
    workers = config.workers if config.workers is not None else (os.cpu_count() or 1)
    with RecordWriter(path) as writer, _Progress(len(tasks), len(tasks) - len(todo), config.progress) as bar:
        def on_result(record: EpisodeRecord) -> None:
            writer.write(record)
            bar.update(record)

        if config.backend == "ray":
            run_ray(todo, on_result, address=config.address, num_cpus=workers or None)
        elif workers == 0:
            run_in_process(todo, on_result)
        else:
            run_local(todo, on_result, workers=workers, start_method=config.start_method)
    records = canonicalise(path, [task.key for task in tasks])
    from hiconav.eval.summary import summarize, write_summary

    summary = summarize(records)
    if config.report:
        from hiconav.eval.report import write_report

        info = {"runner": config.runner, "seed": config.seed, "backend": config.backend,
                "workers": workers, "presets": list(resolve_presets(list(config.presets))),
                "ran": len(todo), "skipped (resumed)": len(tasks) - len(todo), **(run_info or {})}
        write_summary(out / "summary.json", summary)
        write_report(out, records, summary, run_info=info)
    return summary


def load_records(out: str | Path) -> list[EpisodeRecord]:
    """The records of an output folder (for re-reporting without running)."""
    return read_records(Path(out) / EPISODES_FILE)
