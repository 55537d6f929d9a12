"""``hiconav episodes``: write a task episode file (objectnav, ovon or textnav; JSON Lines) for
the houses of a ProcTHOR houses file. Registered in ``hiconav/cli.py`` as ("episodes",
"hiconav.sim.episodes_cli", "episodes").

The episodes are drawn by ``hiconav.sim.task_episodes``; this module only turns options into
calls, runs houses in worker processes and reports what it wrote. A house with nothing to draw
for the task is reported and skipped, never aborting the run.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import typer

from hiconav.errors import ConfigError, DataError


def house_episodes(houses_file: str, index: int, task: str, n: int, seed: int) -> tuple[list[dict[str, Any]], str | None]:
    """The episodes (as JSON dicts) of line ``index`` of ``houses_file``, or ([], why not)."""
    from hiconav.data import data_root
    from hiconav.sim.procthor import load_procthor_line
    from hiconav.sim.task_episodes import generate_task_episodes

    try:
        house = load_procthor_line(Path(houses_file), index, data_root())
        return [ep.to_json() for ep in generate_task_episodes(house, index, task, n, seed)], None
    except ImportError:
        raise
    except Exception as exc:  # noqa: BLE001 - one house without episodes never aborts the run
        return [], f"{type(exc).__name__}: {exc}"


def episodes(
    houses: Path = typer.Option(..., "--houses", help="ProcTHOR houses FILE.jsonl(.gz); an episode's 'house' is its 0-based line."),
    task: str = typer.Option(..., "--task", help="objectnav, ovon or textnav."),
    per_house: int = typer.Option(1, "--per-house", min=1, help="Episodes per house."),
    seed: int = typer.Option(0, "--seed", help="Base seed (each house and task gets its own)."),
    out: Path = typer.Option(..., "--out", help="Episode file to write (JSON Lines)."),
    first: int | None = typer.Option(None, "--first", min=1, help="Only the first N houses of the file."),
    workers: int = typer.Option(1, "--workers", min=1, help="Worker processes (houses in parallel; same file)."),
) -> None:
    """Write objectnav, ovon or textnav episodes for every house of a ProcTHOR houses file."""
    from hiconav.sim.procthor import split_lines
    from hiconav.sim.task_episodes import TASKS

    if task not in TASKS:
        raise ConfigError(f"unknown task {task!r}; known: {', '.join(TASKS)}", field="--task")
    if not houses.is_file():
        raise DataError(f"file not found: {houses}", file=str(houses), field="--houses")
    count = len(split_lines(str(houses.resolve())))
    if count == 0:
        raise DataError("houses file holds no house", file=str(houses), field="--houses")
    indices = list(range(min(count, first or count)))
    args = (str(houses.resolve()), task, per_house, seed)
    if workers <= 1 or len(indices) <= 1:
        results = [house_episodes(args[0], i, *args[1:]) for i in indices]
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        methods = multiprocessing.get_all_start_methods()
        context = multiprocessing.get_context("forkserver" if "forkserver" in methods else "spawn")
        with ProcessPoolExecutor(max_workers=min(workers, len(indices)), mp_context=context) as pool:
            n = len(indices)
            results = list(pool.map(house_episodes, [args[0]] * n, indices, [task] * n, [per_house] * n,
                                    [seed] * n))
    out.parent.mkdir(parents=True, exist_ok=True)
    written = 0
    skipped: list[tuple[int, str]] = []
    with out.open("w", encoding="utf-8") as fh:
        for index, (lines, error) in zip(indices, results, strict=True):
            if error is not None:
                skipped.append((index, error))
            for line in lines:
                fh.write(json.dumps(line) + "\n")
                written += 1
    for index, error in skipped:
        typer.echo(f"house {index}: no {task} episode: {error}", err=True)
    typer.echo(json.dumps({"task": task, "houses": len(indices), "houses_with_episodes": len(indices) - len(skipped),
                           "episodes": written, "out": str(out)}))
    if written == 0:
        raise DataError(f"no house of the file has a {task} episode", file=str(houses), field="--houses")
