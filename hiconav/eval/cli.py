"""``hiconav eval``: run a benchmark (episodes x presets) and write episodes.jsonl, summary.json,
report.md and plots into ``--out``. Registered in ``hiconav/cli.py`` as ("eval",
"hiconav.eval.cli", "eval").

Heavy imports (simulator, matplotlib, Ray) happen inside the command. This module must not hold
benchmark logic beyond turning options into a source and an ``EvalConfig``.
"""

from __future__ import annotations

import json
import os
import shlex
import sys
from collections import Counter
from pathlib import Path
from typing import Any

import typer

from hiconav.errors import ConfigError, DataError


def _parse_sets(items: list[str]) -> dict[str, Any]:
    from hiconav.settings import parse_set_options

    return parse_set_options(items)


def _overrides(config_file: Path | None, items: list[str]) -> dict[str, Any]:
    from hiconav.settings import load_settings_file

    return {**(load_settings_file(config_file) if config_file else {}), **_parse_sets(items)}


SOURCE_FILE = "source.json"
SPECS_FILE = "specs.jsonl"


def _saved_source(out: Path) -> dict[str, Any] | None:
    """The source options an earlier run saved into ``out`` (``source.json``), or None."""
    try:
        return json.loads((out / SOURCE_FILE).read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError):
        return None


def _cached_specs(out: Path, saved: dict[str, Any] | None, source: dict[str, Any]) -> list[Any] | None:
    """The episode specs saved by an earlier run into ``out`` from the same source options
    (``saved``: its ``source.json``), so a resumed run does not generate episodes again; or None."""
    from hiconav.eval.sources import read_specs

    if saved != source or not (out / SPECS_FILE).exists():
        return None
    return read_specs(out / SPECS_FILE)


def _check_resumable(out: Path, saved: dict[str, Any] | None, source: dict[str, Any]) -> None:
    """Refuse an output folder whose results come from other source options (``saved``: its
    ``source.json``): resuming skips episodes by id, so the old records would stand for episodes
    that are no longer the same (another seed or input, or the episode rules of an older
    version). A different ``--limit`` only takes more or fewer episodes of the same list."""
    from hiconav.eval.runner import EPISODES_FILE

    if saved is None:
        return
    records = out / EPISODES_FILE
    changed = sorted(k for k in set(saved) | set(source) if k != "limit" and saved.get(k) != source.get(k))
    if not changed or not records.exists() or records.stat().st_size == 0:
        return
    raise DataError(f"{out} holds results for other episode options ({', '.join(changed)}: "
                    f"{[saved.get(k) for k in changed]} there, {[source.get(k) for k in changed]} now); "
                    "use another --out, or delete the folder", field="--out")


def _save_specs(out: Path, source: dict[str, Any], specs: list[Any]) -> None:
    from hiconav.eval.sources import write_specs

    out.mkdir(parents=True, exist_ok=True)
    write_specs(out / SPECS_FILE, specs)
    (out / SOURCE_FILE).write_text(json.dumps(source, indent=2) + "\n", encoding="utf-8")


def _reasons(errors: list[str | None]) -> dict[str, int]:
    """{short reason: count} of the invalid episodes' errors (``sources.invalid_reason``), sorted."""
    from hiconav.eval.sources import invalid_reason

    return dict(sorted(Counter(invalid_reason(e) for e in errors if e).items()))


def _none_valid(episodes: int, reasons: dict[str, int], hint: str = "") -> DataError:
    listed = ", ".join(f"{k}: {v}" for k, v in reasons.items()) or "none"
    return DataError(f"no episode of the input is valid ({episodes} episodes: {listed}){hint}",
                     field="--houses/--maps")


def eval(
    out: Path = typer.Option(..., "--out", help="Output folder (episodes.jsonl, summary.json, report.md, plots)."),
    houses: Path | None = typer.Option(None, "--houses", help="ProcTHOR houses FILE.jsonl.gz (episodes are generated)."),
    episodes_per_house: int = typer.Option(3, "--episodes-per-house", min=1, help="Generated episodes per house/floor."),
    maps: Path | None = typer.Option(None, "--maps", help="Gibson semantic maps FILE.pbz2."),
    episodes: list[Path] | None = typer.Option(None, "--episodes", help="With --maps: Habitat ObjectNav episode files or folders; with --houses: task episode files FILE.jsonl (objectnav, ovon, textnav; hiconav episodes writes them). Without: generated."),
    seed: int = typer.Option(0, "--seed", help="Base seed (episode generation and per-episode seeds)."),
    limit: int | None = typer.Option(None, "--limit", min=1, help="Run only the first N episodes."),
    workers: int | None = typer.Option(None, "--workers", min=0, help="Worker processes (default: core count; 0 = in this process)."),
    preset: str = typer.Option("full", "--preset", help="Preset name(s), comma separated, or 'ablations' for all."),
    backend: str = typer.Option("local", "--backend", help="local (worker processes) or ray."),
    address: str | None = typer.Option(None, "--address", help="Ray cluster address (ray backend)."),
    runner: str = typer.Option("hiconav.mission:run_episode", "--runner", help="Episode runner import path module:function."),
    set_: list[str] | None = typer.Option(None, "--set", help="Extra settings override KEY=VALUE (dotted key), repeatable."),
    config_file: Path | None = typer.Option(None, "--config", help="Settings YAML applied to every preset; --set wins."),
    stuck_window: int = typer.Option(50, "--stuck-window", min=1, help="Steps without progress that count as stuck."),
    progress: bool = typer.Option(True, "--progress/--no-progress", help="Show the progress bar."),
    scenes: str | None = typer.Option(None, "--scenes", help="Gibson floors: 'tune' (the alphabetically first 13 scenes), 'report' (the other 12) or Scene,Scene."),
    dry_run: bool = typer.Option(False, "--dry-run", help="Validate every episode without running it; print a JSON line of counts."),
) -> None:
    """Run ObjectNav episodes in parallel and write metrics, the failure taxonomy and a report."""
    from hiconav.eval.config import EvalConfig
    from hiconav.eval.presets import resolve_presets
    from hiconav.eval.runner import evaluate
    from hiconav.eval.sources import gibson_source, procthor_source, task_episode_source, validate_spec

    if (houses is None) == (maps is None):
        raise ConfigError("give exactly one input: --houses FILE.jsonl.gz or --maps FILE.pbz2", field="--houses/--maps")
    if scenes and maps is None:
        raise ConfigError("--scenes selects Gibson floors: it goes with --maps", field="--scenes")
    if backend not in ("local", "ray"):
        raise ConfigError(f"unknown backend {backend!r}; known: local, ray", field="--backend")
    if address and backend != "ray":
        raise ConfigError("--address is for --backend ray", field="--address")
    for path, option in ((houses, "--houses"), (maps, "--maps"), *((p, "--episodes") for p in episodes or [])):
        if path is not None and not Path(path).exists():
            raise DataError(f"file not found: {path}", file=str(path), field=option)
    presets = resolve_presets(preset)  # fail on a bad preset before building episodes
    config = EvalConfig(runner=runner, presets=tuple(presets), overrides=_overrides(config_file, set_ or []), seed=seed,
                        workers=workers, backend=backend, address=address, stuck_window=stuck_window,
                        progress=progress)
    n_workers = workers if workers is not None else (os.cpu_count() or 1)
    from hiconav.sim.episodes import EPISODE_RULES

    source = {"houses": str(Path(houses).resolve()) if houses else None,
              "maps": str(Path(maps).resolve()) if maps else None,
              "episodes": [str(Path(p).resolve()) for p in episodes or []],
              "episodes_per_house": episodes_per_house, "seed": seed, "limit": limit,
              "episode_rules": None if episodes else EPISODE_RULES}
    if scenes:
        source["scenes"] = scenes
    def build() -> list[Any]:
        if houses is not None and episodes:
            return task_episode_source(houses, episodes, limit=limit)
        if houses is not None:
            return procthor_source(houses, episodes_per_house, seed=seed, limit=limit, workers=n_workers)
        return gibson_source(maps, episodes, episodes_per_house=episodes_per_house, seed=seed, limit=limit,
                             workers=n_workers, scenes=scenes)

    if dry_run:  # nothing is written: validate and count
        specs = build()
        errors = [validate_spec(spec) for spec in specs]
        for spec, error in zip(specs, errors, strict=True):
            if error:
                typer.echo(f"invalid {spec.episode_id}: {error}")
        invalid = _reasons(errors)
        valid = sum(1 for error in errors if not error)
        typer.echo(json.dumps({"episodes": len(specs), "valid": valid, "invalid": invalid}))
        if valid == 0:
            raise _none_valid(len(specs), invalid)
        return
    saved = _saved_source(Path(out))
    _check_resumable(Path(out), saved, source)
    specs = _cached_specs(Path(out), saved, source)
    if specs is None:
        specs = build()
        _save_specs(Path(out), source, specs)
    if not specs:
        raise DataError("the input holds no episode", field="--houses/--maps")
    if all(spec.error for spec in specs):
        raise _none_valid(len(specs), _reasons([spec.error for spec in specs]), "; run with --dry-run to list them")
    command = "hiconav eval " + " ".join(shlex.quote(a) for a in sys.argv[2:]) if len(sys.argv) > 2 else ""
    summary = evaluate(specs, out, config, run_info={"command": command,
                                                     "source": str(houses or maps), "episodes": len(specs)})
    sr, spl = summary.get("success_rate"), summary.get("spl")
    ci = summary.get("success_rate_ci95")
    typer.echo(f"{summary['episodes']} episodes ({summary['preset']}): "
               f"SR {sr if sr is None else round(sr, 3)}"
               + (f" [95% CI {ci[0]:.3f}, {ci[1]:.3f}]" if ci else "")
               + f"  SPL {spl if spl is None else round(spl, 3)}  -> {Path(out) / 'report.md'}")
