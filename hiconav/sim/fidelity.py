"""Fidelity of the Gibson simulator to Habitat: official reference paths measured on our maps.

A reference path (``reference_paths.jsonl``: scene, Habitat start and goal positions, and the
geodesic distance Habitat's own pathfinder measured on the scene's navmesh) is *valid* here when
both ends map to traversable cells of their floor (the floor whose ``floor_height`` matches the
start's height) and a path joins them; its *ratio* is our fast-marching distance over Habitat's.

Two masks can carry the distance (``MASKS``):
- ``navmesh``: channel 0 as it is, the cells where the robot's centre may stand. Habitat measured
  its distance on its navmesh, and channel 0 is that navmesh projected to the floor, so this
  compares like with like: it is the fidelity of our traversable space.
- ``semexp``: channel 0 dilated by SemExp's 2-cell disk, the mask SemExp's protocol (and our
  Gibson SPL, DTS and success) measures on. The dilation widens every passage by 0.2 m and lets
  paths cut corners, so these distances run 1-4% below Habitat's by construction.
This module measures; it must not change the simulator.
"""

from __future__ import annotations

import json
import math
import statistics
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from hiconav.errors import DataError


@dataclass(frozen=True)
class PathCheck:
    """One reference path: ``valid`` with ``ours`` / ``habitat`` metres, else ``reason``."""

    scene: str
    floor: int | None
    habitat: float
    ours: float = math.inf
    valid: bool = False
    reason: str = ""

    @property
    def ratio(self) -> float:
        return self.ours / self.habitat if self.valid and self.habitat > 0 else math.nan


def read_reference_paths(path: str | Path) -> list[dict[str, Any]]:
    """The JSON objects of a reference-path file, one a line (``DataError`` naming the line)."""
    path = Path(path)
    out = []
    try:
        lines = path.read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read reference paths: {exc}", file=str(path)) from exc
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            rec = json.loads(line)
            out.append({"scene": str(rec["scene"]),
                        "start_position": [float(v) for v in rec["start_position"]],
                        "goal_position": [float(v) for v in rec["goal_position"]],
                        "habitat_geodesic_distance": float(rec["habitat_geodesic_distance"])})
        except (json.JSONDecodeError, KeyError, TypeError, ValueError) as exc:
            raise DataError(f"bad reference path: {exc}", file=str(path), line=number) from exc
    return out


MASKS = ("navmesh", "semexp")


def check_path(maps_file: str | Path, ref: dict[str, Any], radius: float = 0.18,
               mask: str = "navmesh") -> PathCheck:
    """Measure one reference path on the floors of ``maps_file`` through ``mask`` (``MASKS``)."""
    from hiconav.sim import gibson
    from hiconav.sim.fmm import fmm_distance
    from hiconav.sim.geodesic import centre_free, distance_mask

    if mask not in MASKS:
        raise ValueError(f"mask must be one of {MASKS}, not {mask!r}")

    scene, habitat = ref["scene"], float(ref["habitat_geodesic_distance"])
    start, goal = np.asarray(ref["start_position"]), np.asarray(ref["goal_position"])
    try:
        floor = gibson.floor_for_height(maps_file, scene, float(start[1]))
        if floor is None:
            return PathCheck(scene, None, habitat, reason=f"no floor of {scene} at height {start[1]:.2f} m "
                             f"(floors: {gibson.floor_heights(maps_file, scene)})")
        house = gibson.load_gibson_file(maps_file, scene, floor)
    except DataError as exc:
        return PathCheck(scene, None, habitat, reason=str(exc))
    mask = distance_mask(house, radius) if mask == "semexp" else centre_free(house, radius)
    ends = []
    for name, pos in (("start", start), ("goal", goal)):
        rc = house.nav.world_to_cell(gibson.habitat_to_world(pos, house.floor_height)[:2])
        if not house.nav.in_bounds(rc) or not mask[rc[0], rc[1]]:
            return PathCheck(scene, floor, habitat, reason=f"{name} cell {rc.tolist()} is not traversable")
        ends.append(rc)
    src = np.zeros(mask.shape, dtype=bool)
    src[ends[1][0], ends[1][1]] = True
    ours = float(fmm_distance(mask, src, house.nav.resolution)[ends[0][0], ends[0][1]])
    if not math.isfinite(ours):
        return PathCheck(scene, floor, habitat, reason="no traversable path joins start and goal")
    return PathCheck(scene, floor, habitat, ours=ours, valid=True)


def summarise(checks: list[PathCheck]) -> dict[str, Any]:
    """``{"paths", "valid", "ratio_median", "ratio_min", "ratio_max"}`` (ratios of valid paths)."""
    ratios = [c.ratio for c in checks if c.valid]
    return {"paths": len(checks), "valid": len(ratios),
            "ratio_median": round(statistics.median(ratios), 4) if ratios else None,
            "ratio_min": round(min(ratios), 4) if ratios else None,
            "ratio_max": round(max(ratios), 4) if ratios else None}
