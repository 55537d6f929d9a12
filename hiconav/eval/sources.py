"""Episode sources for ``hiconav eval``: ProcTHOR houses with generated episodes, Gibson floors
with Habitat ObjectNav episode files (or generated episodes), as small picklable ``EpisodeSpec``s.

An ``EpisodeSpec`` carries the house spec string (``"procthor:val/3"``, ``"gibson:Allensville/0"``)
and the episode's fields, never the house itself, so that it crosses process and Ray boundaries
cheaply; each worker loads a house once and keeps it (``load_house_cached``).

Bad input never aborts a run: a house that cannot be loaded becomes one spec with ``error`` set,
which the harness records as an ``invalid_episode``. Missing input files are reported at once
(``DataError`` naming the file and option).

This module must not run episodes. The simulator (``hiconav.sim``) is imported lazily.
"""

from __future__ import annotations

import functools
import gzip
import json
import math
import zlib
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from hiconav.errors import DataError, HiconavError


@dataclass(frozen=True)
class EpisodeSpec:
    """One episode to run: the house spec string and the episode's fields (a few hundred bytes).

    start: (x, y, yaw) world metres / radians. ``episode_id`` is unique within a source;
    ``source_id`` is the simulator's own id of the episode. ``error`` marks bad input found
    while building the source (the episode is recorded as invalid, not run).
    """

    episode_id: str
    house: str
    target: str
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)
    goal_instance_ids: tuple[int, ...] = ()
    geodesic_distance: float = 0.0
    instruction: str = ""
    source_id: str = ""
    error: str | None = None
    task: str = "objectnav"  # objectnav | ovon | textnav (hiconav.sim.task_episodes)

    @staticmethod
    def from_episode(episode: Any, *, episode_id: str | None = None) -> EpisodeSpec:
        """From a ``hiconav.sim.episodes.Episode``."""
        start = episode.start
        return EpisodeSpec(
            episode_id=episode_id or str(episode.episode_id),
            house=str(episode.house),
            target=str(episode.target),
            start=(float(start.x), float(start.y), float(start.yaw)),
            goal_instance_ids=tuple(int(i) for i in episode.goal_instance_ids),
            geodesic_distance=float(episode.geodesic_distance),
            instruction=str(getattr(episode, "instruction", "") or ""),
            source_id=str(episode.episode_id),
            task=str(getattr(episode, "task", "objectnav") or "objectnav"),
        )

    def to_episode(self) -> Any:
        """The ``hiconav.sim.episodes.Episode`` of this spec (imports the simulator)."""
        from hiconav.sim.episodes import Episode
        from hiconav.types import Pose2D

        return Episode(
            episode_id=self.source_id or self.episode_id,
            house=self.house,
            start=Pose2D(*self.start),
            target=self.target,
            goal_instance_ids=tuple(self.goal_instance_ids),
            geodesic_distance=self.geodesic_distance,
            instruction=self.instruction,
            task=self.task,
        )

    def load_house(self) -> Any:
        """The house of this episode, loaded once per process (see ``load_house_cached``)."""
        return load_house_cached(self.house)

    def to_json(self) -> dict[str, Any]:
        data = {"episode_id": self.episode_id, "house": self.house, "target": self.target,
                "start": list(self.start), "goal_instance_ids": list(self.goal_instance_ids),
                "geodesic_distance": self.geodesic_distance, "instruction": self.instruction,
                "source_id": self.source_id, "error": self.error}
        if self.task != "objectnav":  # ObjectNav specs are written as they always were
            data["task"] = self.task
        return data

    @staticmethod
    def from_json(data: dict[str, Any]) -> EpisodeSpec:
        return EpisodeSpec(episode_id=str(data["episode_id"]), house=str(data["house"]),
                           target=str(data["target"]), start=tuple(float(v) for v in data["start"]),
                           goal_instance_ids=tuple(int(i) for i in data.get("goal_instance_ids", ())),
                           geodesic_distance=float(data.get("geodesic_distance", 0.0)),
                           instruction=str(data.get("instruction", "")),
                           source_id=str(data.get("source_id", "")), error=data.get("error"),
                           task=str(data.get("task", "objectnav")))


@functools.lru_cache(maxsize=8)
def load_house_cached(spec: str) -> Any:
    """``hiconav.sim.load_house(spec)``, memoised per process (each worker loads a house once).
    Specs of houses in data files anywhere on disk: ``FILE.jsonl.gz#N``, ``FILE.pbz2#Scene/floor``."""
    from hiconav.sim import load_house

    return load_house(spec)


def derive_seed(base_seed: int, name: str) -> int:
    """A stable 31-bit seed for ``name`` under ``base_seed`` (same on every machine and run)."""
    return zlib.crc32(f"{int(base_seed)}:{name}".encode()) & 0x7FFFFFFF


def _require_file(path: str | Path, option: str) -> Path:
    path = Path(path).expanduser()
    if not path.exists():
        raise DataError(f"file not found: {path}", file=str(path), field=option)
    return path


def _data_file(kind: str) -> Path | None:
    """The resolved data root's folder for ``kind`` (procthor | gibson), or None."""
    try:
        from hiconav.data import data_root

        return (data_root() / kind).resolve()
    except HiconavError:
        return None


# ---------------------------------------------------------------------------------------- ProcTHOR


def procthor_house_specs(houses_file: str | Path) -> list[str]:
    """House spec strings of every house (line) in a ProcTHOR ``*.jsonl.gz`` file.

    Files of the data root map to ``procthor:<split>/<index>``; a one-house file to its path;
    any other file to ``<path>#<index>`` (a file path spec with the line index).
    """
    path = _require_file(houses_file, "--houses")
    opener = gzip.open if path.suffix == ".gz" else open
    try:
        with opener(path, "rt", encoding="utf-8") as fh:
            count = sum(1 for line in fh if line.strip())
    except (OSError, EOFError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read houses file: {exc}", file=str(path), field="--houses") from exc
    if count == 0:
        raise DataError("houses file holds no house", file=str(path), field="--houses")
    root = _data_file("procthor")
    resolved = path.resolve()
    if root is not None and resolved.parent == root and resolved.name.endswith(".jsonl.gz"):
        split = resolved.name[: -len(".jsonl.gz")]
        return [f"procthor:{split}/{i}" for i in range(count)]
    if count == 1:
        return [str(resolved)]  # a one-house file: the simulator loads it by path
    return [f"{resolved}#{i}" for i in range(count)]


def procthor_source(houses_file: str | Path, episodes_per_house: int, seed: int = 0,
                    limit: int | None = None, *, workers: int = 1) -> list[EpisodeSpec]:
    """Episodes generated on every house of ``houses_file`` (``hiconav.sim.generate_episodes``,
    seeded per house from ``seed``), in house order, the first ``limit`` when given.

    Generation takes up to a few seconds per house (geodesic fields), so with ``workers`` > 1
    houses are generated in parallel worker processes; the result does not depend on it."""
    if episodes_per_house < 1:
        raise DataError("must be at least 1", field="--episodes-per-house")
    specs = procthor_house_specs(houses_file)
    return _take(_generated(specs, episodes_per_house, seed, limit, workers), limit)


def task_episode_source(houses_file: str | Path, episode_files: Sequence[str | Path],
                        limit: int | None = None) -> list[EpisodeSpec]:
    """The episodes of task episode files (``hiconav.sim.task_episodes``: JSON Lines, one
    objectnav / ovon / textnav episode a line) on the houses of ``houses_file``, in file and line
    order, the first ``limit`` when given. A line that cannot be used (bad JSON or field, unknown
    task, house line or object id, a start off the robot's free space, an unreachable goal)
    becomes one spec with ``error`` naming the file, line and field; a missing or unreadable
    file is reported at once."""
    house_specs = procthor_house_specs(houses_file)
    files = [_require_file(path, "--episodes") for path in episode_files]
    for path in files:
        if path.is_dir():
            raise DataError("expected a task episode file (JSON Lines), got a folder", file=str(path),
                            field="--episodes")
    return _take(_task_episodes(files, house_specs), limit)


def _task_episodes(files: Sequence[Path], house_specs: Sequence[str]) -> Iterator[EpisodeSpec]:
    from hiconav.sim.task_episodes import parse_line, resolve

    for path in files:
        opener = gzip.open if path.suffix == ".gz" else open
        try:
            with opener(path, "rt", encoding="utf-8") as fh:
                lines = fh.read().splitlines()
        except (OSError, EOFError, UnicodeDecodeError) as exc:
            raise DataError(f"cannot read task episodes: {exc}", file=str(path), field="--episodes") from exc
        first_line: dict[str, int] = {}
        for number, text in enumerate(lines, start=1):
            if not text.strip():
                continue
            where = f"{path.name}:{number}"
            house_spec, target, episode_id = "", "", where
            try:
                episode = parse_line(text, str(path), number)
                episode_id, target = episode.episode_id, episode.target
                if episode.episode_id in first_line:
                    raise DataError(f"episode_id {episode.episode_id!r} is given twice (first at line "
                                    f"{first_line[episode.episode_id]})", file=str(path), line=number,
                                    field="episode_id")
                first_line[episode.episode_id] = number
                if episode.house >= len(house_specs):
                    raise DataError(f"house {episode.house} is not a line of the houses file (0.."
                                    f"{len(house_specs) - 1})", file=str(path), line=number, field="house")
                house_spec = house_specs[episode.house]
                try:
                    house = load_house_cached(house_spec)
                except Exception as exc:  # noqa: BLE001 - bad input: recorded, never aborts
                    raise DataError(f"cannot load house {house_spec}: {exc}", file=str(path), line=number,
                                    field="house") from exc
                ids, distance = resolve(episode, house, str(path), number)
            except ImportError:
                raise
            except Exception as exc:  # noqa: BLE001 - bad input: recorded as an invalid episode, never aborts
                message = str(exc) if isinstance(exc, HiconavError) else \
                    f"{path}:{number}: {type(exc).__name__}: {exc}"
                yield EpisodeSpec(episode_id=episode_id, house=house_spec or where, target=target, error=message)
                continue
            yield EpisodeSpec(episode_id=episode.episode_id, house=house_spec, target=episode.target,
                              start=episode.start, goal_instance_ids=ids, geodesic_distance=distance,
                              instruction=episode.instruction, source_id=episode.episode_id, task=episode.task)


def generate_for_house(house_spec: str, n: int, seed: int) -> list[EpisodeSpec]:
    """``n`` generated episodes of one house as specs; a house that fails gives one invalid spec."""
    try:
        from hiconav.sim import generate_episodes

        house = load_house_cached(house_spec)
        episodes = generate_episodes(house, n, seed=derive_seed(seed, house_spec))
    except ImportError:
        raise
    except Exception as exc:  # noqa: BLE001 - bad input: recorded as an invalid episode, never aborts
        return [EpisodeSpec(episode_id=f"{house_spec}/invalid", house=house_spec, target="",
                            error=f"cannot load house or generate episodes: {type(exc).__name__}: {exc}")]
    # the house field is the spec we loaded it by (workers reload it by that string)
    return [replace(EpisodeSpec.from_episode(episode, episode_id=f"{house_spec}/{index}"), house=house_spec)
            for index, episode in enumerate(episodes)]


def _generated(house_specs: Sequence[str], n: int, seed: int, limit: int | None = None,
               workers: int = 1) -> Iterator[EpisodeSpec]:
    """Specs of the houses in order, generating only as many houses as ``limit`` needs."""
    needed = len(house_specs) if limit is None else min(len(house_specs), -(-limit // n))
    if workers <= 1 or needed <= 1:
        for house_spec in house_specs:
            yield from generate_for_house(house_spec, n, seed)
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    context = multiprocessing.get_context("forkserver" if "forkserver" in multiprocessing.get_all_start_methods()
                                          else "spawn")
    count = 0
    position = 0
    with ProcessPoolExecutor(max_workers=min(workers, needed), mp_context=context) as pool:
        while position < len(house_specs) and (limit is None or count < limit):
            batch = house_specs[position: position + max(needed - position, 2 * workers)]
            position += len(batch)
            for specs in pool.map(generate_for_house, batch, [n] * len(batch), [seed] * len(batch)):
                count += len(specs)
                yield from specs


def _take(specs: Iterable[EpisodeSpec], limit: int | None) -> list[EpisodeSpec]:
    out: list[EpisodeSpec] = []
    seen: set[str] = set()
    for spec in specs:
        if limit is not None and len(out) >= limit:
            break
        if spec.episode_id in seen:  # keep keys unique for resume
            spec = replace(spec, episode_id=f"{spec.episode_id}#{len(out)}")
        seen.add(spec.episode_id)
        out.append(spec)
    return out


# ------------------------------------------------------------------------------------------ Gibson


#: The held-out protocol: parameters are chosen on the floors of the alphabetically first
#: ``TUNE_SCENES`` scenes of a maps file ("tune"); figures are reported on the others ("report").
TUNE_SCENES = 13


def gibson_house_specs(maps_file: str | Path, scenes: str | None = None) -> list[str]:
    """House spec strings of every (scene, floor) in a Gibson semantic-map ``*.pbz2`` file.

    The data root's file maps to ``gibson:<Scene>/<floor>``; any other to ``<path>#<Scene>/<floor>``.
    ``scenes``: "tune" (the alphabetically first ``TUNE_SCENES`` scenes), "report" (the others),
    or a comma-separated list of scene names; None for all.
    """
    path = _require_file(maps_file, "--maps").resolve()
    specs = list(_gibson_house_specs(path, path.stat().st_mtime_ns))
    if not scenes:
        return specs
    names = sorted({_scene_of(spec) for spec in specs})
    if scenes == "tune":
        wanted = set(names[:TUNE_SCENES])
    elif scenes == "report":
        wanted = set(names[TUNE_SCENES:])
    else:
        wanted = {name.strip() for name in scenes.split(",") if name.strip()}
        unknown = sorted(wanted - set(names))
        if unknown:
            raise DataError(f"unknown scene(s) {', '.join(unknown)}; the maps file has: {', '.join(names)}",
                            file=str(path), field="--scenes")
    return [spec for spec in specs if _scene_of(spec) in wanted]


def _floor_of(house_spec: str) -> str:
    """"Scene/floor" of a Gibson house spec ("gibson:Scene/floor" or "<maps file>#Scene/floor")."""
    return house_spec.rpartition("#")[2].removeprefix("gibson:")


def _scene_of(house_spec: str) -> str:
    return _floor_of(house_spec).split("/")[0]


@functools.lru_cache(maxsize=4)
def _gibson_house_specs(path: Path, _mtime_ns: int) -> tuple[str, ...]:
    from hiconav.sim.gibson import load_info  # the simulator's reader: the file is decompressed once

    try:
        maps = load_info(path)
    except DataError as exc:
        raise DataError(f"cannot read Gibson maps (bz2 pickle): {exc.__cause__ or exc}", file=str(path),
                        field="--maps") from exc
    if not maps:
        raise DataError("expected {scene: {floor: {...}}}", file=str(path), field="--maps")
    root = _data_file("gibson")
    prefix = "gibson:" if root is not None and path.resolve().parent == root else f"{path.resolve()}#"
    return tuple(f"{prefix}{scene}/{floor}" for scene in sorted(maps) for floor in sorted(maps[scene]))


def habitat_episode_files(paths: Sequence[str | Path]) -> list[Path]:
    """Expand folders to their ``*.json.gz`` / ``*.json`` files (sorted); check files exist."""
    files: list[Path] = []
    for item in paths:
        path = _require_file(item, "--episodes")
        if path.is_dir():
            found = sorted({*path.rglob("*.json.gz"), *path.rglob("*.json")})
            if not found:
                raise DataError("folder holds no *.json.gz or *.json episode file", file=str(path),
                                field="--episodes")
            files += found
        else:
            files.append(path)
    return files


def _habitat_groups(path: Path, maps_file: Path | None = None) -> dict[tuple[str, int], list[dict[str, Any]]]:
    """(scene, floor) -> the raw episodes of one Habitat ObjectNav episode file. An episode's
    floor is the floor of ``maps_file`` whose ``floor_height`` matches its start's height
    (``gibson.floor_for_height``; -1 when none does), else its ``floor_id``."""
    opener = gzip.open if path.suffix == ".gz" else open
    try:
        with opener(path, "rt", encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, EOFError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise DataError(f"cannot read Habitat episodes: {exc}", file=str(path), field="--episodes") from exc
    episodes = data.get("episodes") if isinstance(data, dict) else None
    if not isinstance(episodes, list):
        raise DataError("expected an object with an 'episodes' list", file=str(path), field="episodes")
    groups: dict[tuple[str, int], list[dict[str, Any]]] = {}
    if maps_file is not None:
        from hiconav.sim.gibson import floor_for_height, load_info

        mapped = set(load_info(maps_file))
    for i, episode in enumerate(episodes):
        scene = Path(str(episode.get("scene_id", "") if isinstance(episode, dict) else "")).name.split(".")[0]
        if not scene:
            raise DataError("episode without scene_id", file=str(path), field=f"episodes[{i}].scene_id")
        try:
            floor = int(episode.get("floor_id", 0) or 0)
        except (TypeError, ValueError) as exc:
            raise DataError(f"bad floor_id: {exc}", file=str(path), field=f"episodes[{i}].floor_id") from exc
        height = _start_height(episode)
        if maps_file is not None and height is not None and scene in mapped:
            found = floor_for_height(maps_file, scene, height)
            floor = -1 if found is None else found
        groups.setdefault((scene, floor), []).append({"_index": i, **episode})
    return groups


def _start_height(episode: dict[str, Any]) -> float | None:
    try:
        height = float(episode["start_position"][1])
    except (KeyError, TypeError, ValueError, IndexError):
        return None
    return height if math.isfinite(height) else None


def gibson_source(maps_file: str | Path, episodes: Sequence[str | Path] | None = None, *,
                  episodes_per_house: int = 3, seed: int = 0, limit: int | None = None,
                  workers: int = 1, scenes: str | None = None) -> list[EpisodeSpec]:
    """Gibson floors of ``maps_file`` (``scenes``: see ``gibson_house_specs``) with the Habitat
    episodes of ``episodes`` (files or folders, ``hiconav.sim.load_habitat_episodes``), or,
    without episode files, generated episodes."""
    house_specs = gibson_house_specs(maps_file, scenes)
    if not episodes:
        return _take(_generated(house_specs, episodes_per_house, seed, limit, workers), limit)
    by_scene = {_floor_of(spec): spec for spec in house_specs}
    return _take(_habitat(habitat_episode_files(episodes), by_scene, Path(maps_file)), limit)


def _habitat(files: list[Path], by_scene: dict[str, str], maps_file: Path | None = None) -> Iterator[EpisodeSpec]:
    for path in files:
        for (scene, floor), raw in sorted(_habitat_groups(path, maps_file).items()):
            house_spec = by_scene.get(f"{scene}/{floor}")
            stem = f"{path.name}:{scene}/{floor}"
            if house_spec is None:
                scenes = {key.split("/")[0] for key in by_scene}
                why = (f"no floor of {scene} lies at the start's height" if floor < 0 and scene in scenes
                       else f"scene {scene} floor {floor} is not in the maps file")
                for episode in raw:
                    yield EpisodeSpec(episode_id=f"{stem}/{episode.get('episode_id', episode['_index'])}",
                                      house=f"gibson:{scene}/{floor}", target=str(episode.get("object_category", "")),
                                      error=f"{path} episodes[{episode['_index']}]: {why}")
                continue
            yield from _habitat_group(path, raw, house_spec, stem)


def _habitat_group(path: Path, raw: list[dict[str, Any]], house_spec: str, stem: str) -> Iterator[EpisodeSpec]:
    """One (scene, floor) of a file through ``hiconav.sim.load_habitat_episodes``; when the file
    fails as a whole, episode by episode, so that one bad episode is one invalid record."""
    import tempfile

    from hiconav.sim import load_habitat_episodes

    try:
        house = load_house_cached(house_spec)
    except Exception as exc:  # noqa: BLE001 - bad input: recorded, never aborts
        for episode in raw:
            yield EpisodeSpec(episode_id=f"{stem}/{episode.get('episode_id', episode['_index'])}", house=house_spec,
                              target=str(episode.get("object_category", "")), error=f"cannot load house: {exc}")
        return
    try:
        loaded = [load_habitat_episodes(path, house)]
    except Exception:  # noqa: BLE001 - retried per episode below to find the bad ones
        loaded = []
        with tempfile.TemporaryDirectory() as tmp:
            for episode in raw:
                single = Path(tmp) / "episode.json"
                single.write_text(json.dumps({"episodes": [{k: v for k, v in episode.items() if k != "_index"}]}))
                try:
                    loaded.append(load_habitat_episodes(single, house))
                except Exception as exc:  # noqa: BLE001 - bad input: recorded, never aborts
                    name = episode.get("episode_id", episode["_index"])
                    message = str(exc).replace(str(single), f"{path} episodes[{episode['_index']}]")
                    loaded.append([EpisodeSpec(episode_id=f"{stem}/{name}", house=house_spec,
                                               target=str(episode.get("object_category", "")), error=message)])
    for group in loaded:
        for episode in group:
            if isinstance(episode, EpisodeSpec):
                yield episode
            else:
                spec = EpisodeSpec.from_episode(episode, episode_id=f"{stem}/{episode.episode_id}")
                yield replace(spec, house=house_spec)


#: Stable short reasons for invalid episodes (``--dry-run`` counts them), by a phrase of the error.
_REASONS: tuple[tuple[str, str], ...] = (
    ("not on the traversable area", "start off the traversable area"),
    ("on the navmesh the robot moves on", "goal reachable only through SemExp's dilation"),
    ("is reachable from the start", "no goal reachable from the start"),
    ("lies at the start's height", "no floor at the start's height"),
    ("is not in the maps file", "scene not in the maps file"),
    ("outside the", "start outside the map"),
    ("unknown object category", "unknown goal category"),
    ("has no '", "goal category absent from the floor"),
    ("start off the robot's free space", "start off the robot's free space"),
    ("cannot load house", "house cannot be loaded"),
    ("unknown house", "house cannot be loaded"),
    ("is off the robot's free space", "start off the robot's free space"),
    ("unknown ProcTHOR object id", "unknown goal object id"),
    ("not the target", "goal object of another category"),
    ("unknown task", "unknown task"),
    ("is not a line of the houses file", "house not in the houses file"),
    ("is given twice", "episode id given twice"),
    ("malformed JSON", "malformed episode line"),
    ("missing field", "missing or bad field"),
    ("unknown field", "missing or bad field"),
    ("expected ", "missing or bad field"),
)


def invalid_reason(error: str) -> str:
    """The short reason class of an invalid episode's error message."""
    for phrase, reason in _REASONS:
        if phrase in error:
            return reason
    return "other: " + error.split(":")[0][:80]


def validate_spec(spec: EpisodeSpec) -> str | None:
    """Why ``spec`` cannot be run (an error message), or None when it can: the house loads, the
    simulator can place the robot at the start (``Simulator.reset``'s rule: on the robot's free
    space, or snapped to it from nearby), and a goal's success region is reachable from there.
    Loads the house; renders and runs nothing."""
    if spec.error:
        return spec.error
    try:
        import numpy as np

        from hiconav.sim.geodesic import GoalDistance
        from hiconav.sim.simulator import Simulator

        house = load_house_cached(spec.house)
        sim = Simulator(house)  # no renderer until a frame is asked for
        radius, success = sim.config.robot_radius, sim.config.success_distance
        xy = np.asarray(spec.start[:2], dtype=np.float64)
        placed = xy if sim.is_free(xy) else sim.nearest_free(xy)
        if placed is None:
            return f"start {list(spec.start[:2])} is not on the traversable area of {house.name} " \
                   "(start off the robot's free space)"
        goal = GoalDistance(house, instance_ids=spec.goal_instance_ids, radius=radius)
        if not math.isfinite(goal.to_success(xy, success)):
            return f"no '{spec.target}' of {house.name} is reachable from the start {list(spec.start[:2])}"
        if house.success_rule == "semexp" and not _moves_to(sim, placed, goal.success_region(success)):
            return (f"no '{spec.target}' of {house.name} is reachable from the start {list(spec.start[:2])} "
                    "on the navmesh the robot moves on (channel 0): the two join only through SemExp's "
                    "2-cell dilation of it, which its distances are measured on")
    except Exception as exc:  # noqa: BLE001 - bad input: reported, never aborts
        return f"cannot load house or goals: {type(exc).__name__}: {exc}"
    return None


def _moves_to(sim: Any, xy: Any, region: Any) -> bool:
    """True when a robot placed at ``xy`` (a free point: the start as ``Simulator.reset`` snaps it)
    can drive into ``region`` ((H, W) bool success cells) over the simulator's free space: its 8-connected piece
    holds a region cell (the simulator's sub-steps and slides pass a diagonal link of two cells).

    SemExp measures distances on channel 0 dilated by 2 cells, which bridges gaps of the navmesh
    the robot cannot drive through: a start drawn beyond such a gap has a finite distance and no
    way to the goal."""
    import numpy as np

    from hiconav.sim.geodesic import driving_pieces, reaching_pieces

    rc = sim.house.nav.world_to_cell(np.asarray(xy, dtype=np.float64))
    return bool(reaching_pieces(driving_pieces(sim.free), region)[rc[0], rc[1]])


def read_specs(path: str | Path) -> list[EpisodeSpec]:
    """Specs saved by ``write_specs`` (``specs.jsonl`` in an output folder)."""
    path = _require_file(path, "specs")
    out = []
    with path.open("r", encoding="utf-8") as fh:
        for number, line in enumerate(fh, start=1):
            if line.strip():
                try:
                    out.append(EpisodeSpec.from_json(json.loads(line)))
                except (json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
                    raise DataError(f"bad episode spec: {exc}", file=str(path), line=number) from exc
    return out


def write_specs(path: str | Path, specs: Sequence[EpisodeSpec]) -> None:
    with Path(path).open("w", encoding="utf-8") as fh:
        fh.writelines(json.dumps(spec.to_json(), sort_keys=True) + "\n" for spec in specs)
