"""ObjectNav metrics: success, SPL, DTS and a per-episode record.

Success: the agent calls ``stop`` within ``success_distance`` m (geodesic, to the nearest
goal-instance footprint) within ``max_steps`` actions. SPL = S * l / max(l, p) with p the path
length and l the shortest path that succeeds: the geodesic distance from the start to the
success region (the cells within ``success_distance`` of the goal), as Habitat's ObjectNav
measures it to the goal's view points (Anderson et al. 2018; Batra et al. 2020). Measured to
the goal object itself, l exceeds the shortest successful path by up to the success distance:
an agent that stops on the region's edge scores SPL 1 with a path shorter than "l", and SPL
over-states efficiency most on the shortest episodes. DTS: the
geodesic distance to the success region at the end. Distances to the region are any-angle
(fast marching, ``geodesic``). This module
scores episodes; it must not move the robot.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from hiconav.sim.config import SimConfig
from hiconav.sim.episodes import Episode
from hiconav.sim.geodesic import GoalDistance


def spl(success: bool, shortest: float, path_length: float) -> float:
    """Success weighted by path length: S * l / max(l, p); 0 when not successful."""
    if not success:
        return 0.0
    denom = max(shortest, path_length)
    return 1.0 if denom <= 0.0 else float(shortest / denom)


def dts(final_distance: float, success_distance: float = 1.0) -> float:
    """Distance to success: max(0, geodesic distance to the goal - success_distance)."""
    return max(0.0, float(final_distance) - success_distance)


def excess_by_source(xy: Any, sources: Any, to_success: Any) -> dict[str, Any]:
    """Where a path goes beyond the shortest: for each step from ``xy[i]`` to ``xy[i + 1]`` ((N + 1, 2)
    world m, the robot after each command) served by ``sources[i]`` (N behaviour names, "" read "unnamed"), the
    length driven less the progress made toward the success region, ``to_success(xy)`` (geodesic m,
    0 inside it). Returns ``{"by_behaviour": {name: m}, "inside_m": m driven with the robot inside
    the region both before and after the step (counted in its behaviour too), "unmeasured_m": m of
    steps with an end off the measurable floor (non-finite distance, in no behaviour)}``.

    Over a successful episode the excesses sum to the path less SPL's shortest path (the region
    reached, from the start): a turn in place costs none, a step straight toward the region none, a
    step along a detour its length and one back away from it twice that."""
    pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    names = [str(n) or "unnamed" for n in sources]  # a command no behaviour named, as ControlNode.actions
    if len(pts) != len(names) + 1:
        raise ValueError(f"excess_by_source: {len(pts)} positions for {len(names)} steps (need one more)")
    d = np.array([float(to_success(p)) for p in pts], dtype=np.float64)
    steps = np.hypot(*(pts[1:] - pts[:-1]).T) if len(names) else np.zeros(0)
    by: dict[str, float] = {}
    inside = unmeasured = 0.0
    for i, name in enumerate(names):
        if not (np.isfinite(d[i]) and np.isfinite(d[i + 1])):
            unmeasured += float(steps[i])
            continue
        by[name] = by.get(name, 0.0) + float(steps[i] - (d[i] - d[i + 1]))
        if d[i] <= 0.0 and d[i + 1] <= 0.0:
            inside += float(steps[i])
    return {"by_behaviour": {k: round(v, 3) for k, v in by.items()}, "inside_m": round(inside, 3),
            "unmeasured_m": round(unmeasured, 3)}


@dataclass(frozen=True)
class EpisodeMetrics:
    """The record of one finished episode."""

    episode_id: str
    house: str
    target: str
    success: bool
    spl: float
    dts: float
    final_distance: float
    shortest: float  # geodesic start-goal distance (m)
    path_length: float
    steps: int
    collisions: int
    stopped: bool
    shortest_to_success: float = 0.0  # geodesic start to success-region distance: SPL's l (m)
    # the first frame with a goal instance in view within the depth range (Simulator.watch):
    # actions and path length (m) before it, and the geodesic distance (m) from where the robot
    # stood then to the success region; None when no goal was ever in view
    steps_to_view: int | None = None
    path_to_view: float | None = None
    view_to_success: float | None = None
    turns: int | None = None  # of ``steps``, the discrete turns in place; None: not counted (velocity control)

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def episode_metrics(episode: Episode, *, final_distance: float, path_length: float,
                    steps: int, stopped: bool, shortest_to_success: float, collisions: int = 0,
                    config: SimConfig | None = None,
                    final_to_success: float | None = None,
                    first_in_view: tuple[int, float] | None = None,
                    view_to_success: float | None = None, turns: int | None = None) -> EpisodeMetrics:
    """Score an episode from its end state (hand-made cases in tests use this directly).

    ``shortest_to_success``: the geodesic distance from the start to the success region (SPL's l;
    ``GoalDistance.to_success``); ``final_to_success``: the same from where the robot ended (the
    DTS; when None, ``final_distance - success_distance``, a lower bound of it); ``first_in_view``:
    (steps, path length) when a goal was first in view (``Simulator.first_in_view``), and
    ``view_to_success`` the geodesic distance from there to the success region."""
    cfg = config or SimConfig()
    success = bool(stopped and steps <= cfg.max_steps and
                   final_distance <= cfg.success_distance)
    return EpisodeMetrics(
        episode_id=episode.episode_id, house=episode.house, target=episode.target,
        success=success, spl=spl(success, shortest_to_success, path_length),
        dts=dts(final_distance, cfg.success_distance) if final_to_success is None
        else max(0.0, float(final_to_success)), final_distance=float(final_distance),
        shortest=float(episode.geodesic_distance), path_length=float(path_length),
        steps=int(steps), collisions=int(collisions), stopped=bool(stopped),
        shortest_to_success=float(shortest_to_success),
        steps_to_view=None if first_in_view is None else int(first_in_view[0]),
        path_to_view=None if first_in_view is None else float(first_in_view[1]),
        view_to_success=None if first_in_view is None or view_to_success is None else float(view_to_success),
        turns=None if turns is None else int(turns))


class EpisodeTracker:
    """Scores a running episode from a ``Simulator`` (call ``finish`` when it ends)."""

    def __init__(self, sim: Any, episode: Episode) -> None:
        self.sim = sim
        self.episode = episode
        self.goal = GoalDistance(sim.house, episode, radius=sim.config.robot_radius)
        self.shortest_to_success = self.goal.to_success(episode.start.xy, sim.config.success_distance)
        sim.watch(episode.goal_instance_ids)

    @property
    def done(self) -> bool:
        return bool(self.sim.stopped or self.sim.steps >= self.sim.config.max_steps)

    def finish(self) -> EpisodeMetrics:
        sim = self.sim
        view = sim.first_in_view
        to_view = None if view is None else self.goal.to_success(np.array(view[2:4]), sim.config.success_distance)
        return episode_metrics(self.episode, final_distance=self.goal.distance(sim.pose.xy),
                               path_length=sim.path_length, steps=sim.steps,
                               stopped=sim.stopped, collisions=sim.collisions,
                               shortest_to_success=self.shortest_to_success, config=sim.config,
                               final_to_success=self.goal.to_success(sim.pose.xy, sim.config.success_distance),
                               first_in_view=None if view is None else view[:2], view_to_success=to_view,
                               turns=sim.turns if sim.velocity_steps == 0 else None)
