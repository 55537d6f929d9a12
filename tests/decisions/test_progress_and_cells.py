"""The stall clock and the cell cascade near a candidate (hiconav.decisions.progress / cells)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from hiconav.decisions.cells import camera_of, cell_near, furniture_boxes, in_margin, wall_heights
from hiconav.decisions.progress import StallClock
from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base



from .fakes import Grid as FakeGrid
from .fakes import open_grid


@dataclass(frozen=True)
class _Object:
    id: int
    label: str
    box_min: np.ndarray
    box_max: np.ndarray


def obj(oid: int, label: str, x: float, y: float) -> _Object:
    return _Object(oid, label, np.array([x - 0.3, y - 0.3, 0.0]), np.array([x + 0.3, y + 0.3, 0.8]))


def test_a_robot_that_comes_no_nearer_for_the_limit_is_stalled():
    clock = StallClock()
    assert not clock.stalled(3.0, 0.0, limit_s=6.0)
    assert not clock.stalled(2.9, 5.0, limit_s=6.0)  # 0.1 m nearer is not progress
    assert clock.stalled(2.9, 6.5, limit_s=6.0)


def test_coming_nearer_by_the_progress_step_restarts_the_stall_clock():
    clock = StallClock()
    clock.stalled(3.0, 0.0, limit_s=6.0)
    assert not clock.stalled(2.7, 5.0, limit_s=6.0)  # 0.3 m nearer: progress at t = 5
    assert not clock.stalled(2.7, 10.0, limit_s=6.0)
    assert clock.stalled(2.7, 11.5, limit_s=6.0)


def test_within_near_of_the_goal_the_robot_is_never_stalled():
    """Glancing about a view cell it stands on is the work, not a stall."""
    clock = StallClock()
    for t in range(0, 60, 5):
        assert not clock.stalled(0.2, float(t), limit_s=6.0, near=0.35)


def test_reset_forgets_the_best_distance_of_the_previous_goal():
    clock = StallClock()
    clock.stalled(1.0, 0.0, limit_s=6.0)
    clock.reset()
    assert not clock.stalled(5.0, 100.0, limit_s=6.0)  # a new goal, farther: not stalled at once


def _corridor_room() -> FakeGrid:
    """A 10 m room at 0.1 m whose left part is a 0.4 m corridor (rows 48-51) with margins."""
    grid = open_grid()
    state, inflated = grid.state.copy(), grid.inflated.copy()
    state[:45, :40] = 1
    state[55:, :40] = 1
    inflated[:, :] = state == 1
    inflated[45:48, :40] = inflated[52:55, :40] = True  # the corridor's inflation margin
    inflated[48:52, :40] = True  # only the robot radius clears the corridor itself
    return FakeGrid(state, inflated)


def test_in_margin_tells_a_robot_in_a_passage_only_its_radius_clears():
    grid = _corridor_room()
    assert in_margin(grid, np.array([2.0, 5.0]))
    assert not in_margin(grid, np.array([7.0, 5.0]))
    assert not in_margin(grid, np.array([50.0, 50.0]))  # off the map


def test_cell_near_prefers_a_roomy_cell_and_falls_back_to_a_tight_one():
    grid = open_grid()
    lo, hi = np.array([4.8, 4.8, 0.0]), np.array([5.2, 5.2, 0.5])
    cell = cell_near(grid, lo, hi, np.array([2.0, 5.0]), 0.8, None)
    assert cell is not None and abs(cell[1] - 5.0) < 0.6 and 4.0 <= cell[0] < 4.8  # the near side
    # furniture all round the object: every cell near it lies in the inflation margin, which only
    # the robot's radius clears (not lethal): the tight search still finds one
    crowded = FakeGrid(grid.state.copy(), grid.inflated.copy(), lethal=grid.state == 1)
    crowded.inflated[30:70, 30:70] = True
    tight = cell_near(crowded, lo, hi, np.array([2.0, 5.0]), 0.8, None)
    assert tight is not None and 4.0 <= tight[0] < 4.8
    # and nothing when even the robot centre cannot stand there
    crowded.lethal[30:70, 30:70] = True
    assert cell_near(crowded, lo, hi, np.array([2.0, 5.0]), 0.8, None) is None


def test_cell_near_skips_excluded_cells():
    grid = open_grid()
    lo, hi = np.array([4.8, 4.8, 0.0]), np.array([5.2, 5.2, 0.5])
    first = cell_near(grid, lo, hi, np.array([2.0, 5.0]), 0.8, None)
    second = cell_near(grid, lo, hi, np.array([2.0, 5.0]), 0.8, [first])
    assert second is not None and float(np.hypot(*(second - first))) > 0.3


@dataclass(frozen=True)
class _Anchor:
    id: int
    T_world_cam: np.ndarray
    intrinsics: CameraIntrinsics


@dataclass
class _Memory:
    objects: tuple
    anchors: tuple


def test_the_camera_is_the_newest_anchors_and_furniture_is_every_other_object():
    K = CameraIntrinsics(fx=300.0, fy=300.0, cx=160.0, cy=120.0, width=320, height=240)
    old = _Anchor(1, camera_pose_from_base(Pose2D(0.0, 0.0, 0.0), 0.5), K)
    new = _Anchor(2, camera_pose_from_base(Pose2D(1.0, 0.0, 0.0), 0.88), K)
    memory = _Memory((obj(1, "bed", 3.0, 3.0), obj(2, "chair", 5.0, 5.0)), (new, old))
    height, vfov = camera_of(memory)
    assert abs(height - 0.88) < 1e-9 and abs(vfov - 2 * np.arctan2(120.0, 300.0)) < 1e-12
    assert [tuple(lo[:2]) for lo, _ in furniture_boxes(memory, 1)] == [tuple(obj(2, "chair", 5.0, 5.0).box_min[:2])]
    assert wall_heights(memory, 1.2) == (height, 1.2)
    assert camera_of(_Memory((), ())) is None and wall_heights(_Memory((), ()), 1.0) is None
