"""ObjectNav metrics: success, SPL, DTS and a per-episode record.

Success: the agent calls ``stop`` within ``success_distance`` m (geodesic, to the nearest
goal-instance footprint) within ``max_steps`` actions. SPL = S * l / max(l, p) with l the
shortest geodesic start-goal distance and p the path length (Anderson et al. 2018). DTS: the
geodesic distance to the success region at the end, max(0, d_T - success_distance). This module
scores episodes; it must not move the robot.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

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
    shortest: float
    path_length: float
    steps: int
    collisions: int
    stopped: bool

    def to_json(self) -> dict[str, Any]:
        return asdict(self)


def episode_metrics(episode: Episode, *, final_distance: float, path_length: float,
                    steps: int, stopped: bool, collisions: int = 0,
                    config: SimConfig | None = None) -> EpisodeMetrics:
    """Score an episode from its end state (hand-made cases in tests use this directly)."""
    cfg = config or SimConfig()
    success = bool(stopped and steps <= cfg.max_steps and
                   final_distance <= cfg.success_distance)
    return EpisodeMetrics(
        episode_id=episode.episode_id, house=episode.house, target=episode.target,
        success=success, spl=spl(success, episode.geodesic_distance, path_length),
        dts=dts(final_distance, cfg.success_distance), final_distance=float(final_distance),
        shortest=float(episode.geodesic_distance), path_length=float(path_length),
        steps=int(steps), collisions=int(collisions), stopped=bool(stopped))


class EpisodeTracker:
    """Scores a running episode from a ``Simulator`` (call ``finish`` when it ends)."""

    def __init__(self, sim: Any, episode: Episode) -> None:
        self.sim = sim
        self.episode = episode
        self.goal = GoalDistance(sim.house, episode, radius=sim.config.robot_radius)

    @property
    def done(self) -> bool:
        return bool(self.sim.stopped or self.sim.steps >= self.sim.config.max_steps)

    def finish(self) -> EpisodeMetrics:
        sim = self.sim
        return episode_metrics(self.episode, final_distance=self.goal.distance(sim.pose.xy),
                               path_length=sim.path_length, steps=sim.steps,
                               stopped=sim.stopped, collisions=sim.collisions,
                               config=sim.config)
