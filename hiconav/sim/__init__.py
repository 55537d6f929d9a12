"""The built-in simulator: house model and loaders, RGB-D + instance renderer, agent,
episodes, geodesic distances and ObjectNav metrics.

Public names are imported lazily so that ``import hiconav.sim`` stays cheap (the renderer
pulls moderngl only when a ``Simulator`` is created).
"""

from __future__ import annotations

from typing import Any

_EXPORTS = {
    "load_house": "hiconav.sim.houses",
    "house_names": "hiconav.sim.houses",
    "House": "hiconav.sim.house",
    "SimObject": "hiconav.sim.house",
    "NavGrid": "hiconav.sim.house",
    "Room": "hiconav.sim.house",
    "SimConfig": "hiconav.sim.config",
    "Simulator": "hiconav.sim.simulator",
    "Renderer": "hiconav.sim.renderer",
    "Episode": "hiconav.sim.episodes",
    "generate_episodes": "hiconav.sim.episodes",
    "load_habitat_episodes": "hiconav.sim.episodes",
    "GoalDistance": "hiconav.sim.geodesic",
    "spl": "hiconav.sim.metrics",
    "EpisodeMetrics": "hiconav.sim.metrics",
    "EpisodeTracker": "hiconav.sim.metrics",
}

__all__ = [
    "Episode", "EpisodeMetrics", "EpisodeTracker", "GoalDistance", "House", "NavGrid",
    "Renderer", "Room", "SimConfig", "SimObject", "Simulator", "generate_episodes",
    "house_names", "load_habitat_episodes", "load_house", "spl",
]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'hiconav.sim' has no attribute '{name}'")
    import importlib

    return getattr(importlib.import_module(module), name)
