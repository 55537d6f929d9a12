"""hiconav.mapping.FrontierTracker on hand-made grids: extraction, size filter, viewpoints, stable ids."""

from __future__ import annotations

import cv2
import numpy as np

from hiconav.mapping import FrontierConfig, FrontierTracker, GridSnapshot, frontier_mask
from hiconav.mapping.occupancy import disk_kernel

from corridors import corridor_grid, snapshot

RES = 0.05


def make_grid(state: np.ndarray, origin=(0.0, 0.0), inflate_cells: float = 3.6) -> GridSnapshot:
    state = state.astype(np.int8)
    occ = (state == 1).astype(np.uint8)
    inflated = cv2.dilate(occ, disk_kernel(inflate_cells)).astype(bool)
    return GridSnapshot(
        state=state,
        inflated=inflated,
        explored=state != -1,
        origin=np.array(origin, float),
        resolution=RES,
        version=1,
        stamp=0.0,
    )


def room_with_doors(doors: list[tuple[int, int]]) -> np.ndarray:
    """60x60 unknown; a walled 40x40 room (rows/cols 10..49) free inside; gaps in its east wall."""
    s = np.full((60, 60), -1, np.int8)
    s[10:50, 10:50] = 1
    s[11:49, 11:49] = 0
    for r0, r1 in doors:
        s[r0:r1, 49] = 0  # opening in the wall: free cells that touch the unknown outside
    return s


def xy_of(grid: GridSnapshot, r: int, c: int) -> np.ndarray:
    return grid.cell_to_world(np.array([r, c]))


def test_frontier_mask_marks_free_cells_next_to_unknown():
    s = np.array([[-1, -1, -1, -1], [-1, 0, 0, 1], [0, 0, 0, 1], [0, 0, 0, 1]], np.int8)
    m = frontier_mask(s)
    expected = np.array(
        [
            [0, 0, 0, 0],
            [0, 1, 1, 0],
            [1, 0, 0, 0],  # (2, 0) is on the grid edge: unknown lies beyond it
            [1, 1, 1, 0],
        ],
        bool,
    )  # so is the whole last row
    np.testing.assert_array_equal(m, expected)


def test_closed_room_has_no_frontier():
    grid = make_grid(room_with_doors([]))
    assert FrontierTracker().update(grid, xy_of(grid, 30, 30)) == []


def test_door_gives_one_frontier_at_the_door_with_a_reachable_viewpoint():
    grid = make_grid(room_with_doors([(25, 35)]))
    fr = FrontierTracker().update(grid, xy_of(grid, 30, 20))
    assert len(fr) == 1
    f = fr[0]
    assert f.size == 10
    np.testing.assert_allclose(f.centroid, xy_of(grid, 29.5, 49), atol=1e-9)
    vp = grid.world_to_cell(f.viewpoint)
    assert grid.state[vp[0], vp[1]] == 0 and not grid.inflated[vp[0], vp[1]]
    assert np.hypot(*(f.viewpoint - f.centroid)) < 0.5  # close to the door
    assert set(map(tuple, f.cells)) == {(r, 49) for r in range(25, 35)}


def test_small_frontiers_are_dropped():
    grid = make_grid(room_with_doors([(15, 17), (30, 40)]))
    fr = FrontierTracker(FrontierConfig(min_size_cells=5)).update(grid, xy_of(grid, 30, 20))
    assert [f.size for f in fr] == [10]
    fr = FrontierTracker(FrontierConfig(min_size_cells=2)).update(grid, xy_of(grid, 30, 20))
    assert sorted(f.size for f in fr) == [2, 10]


def test_frontier_unreachable_from_the_robot_is_dropped():
    s = room_with_doors([(25, 35)])
    s[11:49, 30] = 1  # a wall splits the room; the robot is in the west half, the door in the east
    grid = make_grid(s)
    assert FrontierTracker().update(grid, xy_of(grid, 30, 15)) == []
    kept = FrontierTracker(FrontierConfig(drop_unreachable=False)).update(grid, xy_of(grid, 30, 15))
    assert len(kept) == 1 and np.all(np.isnan(kept[0].viewpoint))
    assert len(FrontierTracker().update(grid, xy_of(grid, 30, 40))) == 1


def test_long_frontiers_are_split():
    s = np.full((100, 100), -1, np.int8)
    s[20:80, 10:60] = 0  # a big free block: its border is one long ring of frontier cells
    grid = make_grid(s)
    fr = FrontierTracker(FrontierConfig(max_size_cells=50)).update(grid, xy_of(grid, 50, 30))
    assert len(fr) >= 4 and all(f.size <= 50 for f in fr)
    assert sum(f.size for f in fr) == int(frontier_mask(s).sum())


def test_ids_are_stable_across_updates_and_grid_growth():
    tracker = FrontierTracker(FrontierConfig(min_size_cells=3))
    grid = make_grid(room_with_doors([(14, 20), (30, 40)]))
    first = {f.size: f.id for f in tracker.update(grid, xy_of(grid, 30, 20))}
    assert len(first) == 2
    again = {f.size: f.id for f in tracker.update(grid, xy_of(grid, 30, 20))}
    assert again == first
    # the grid grows by 7 rows and 5 cols on the low side: cells shift, world positions do not
    s = np.full((67, 65), -1, np.int8)
    s[7:, 5:] = room_with_doors([(14, 20), (30, 40)])
    grown = make_grid(s, origin=(-5 * RES, -7 * RES))
    after = {f.size: f.id for f in tracker.update(grown, xy_of(grown, 37, 25))}
    assert after == first
    # the big door partly explored (shrinks) keeps its id; a new door gets a new id
    s2 = s.copy()
    s2[7 + 30 : 7 + 33, 5 + 49] = 1
    s2[7 + 44 : 7 + 48, 5 + 49] = 0
    later = tracker.update(make_grid(s2, origin=(-5 * RES, -7 * RES)), xy_of(grown, 37, 25))
    ids = {f.size: f.id for f in later}
    assert ids[7] == first[10] and ids[6] == first[6]
    assert ids[4] not in first.values()


def test_frontier_cells_are_free_and_touch_unknown():
    rng = np.random.default_rng(3)
    s = rng.choice(np.array([-1, 0, 0, 0, 1], np.int8), size=(80, 80))
    s = cv2.medianBlur((s + 1).astype(np.uint8), 5).astype(np.int8) - 1
    grid = make_grid(s, inflate_cells=1.0)
    fr = FrontierTracker(FrontierConfig(min_size_cells=1, drop_unreachable=False)).update(
        grid, xy_of(grid, 40, 40)
    )
    m = frontier_mask(s)
    for f in fr:
        assert np.all(m[f.cells[:, 0], f.cells[:, 1]])
    assert sum(f.size for f in fr) == int(m.sum())


def test_frontiers_beyond_a_passage_the_map_closes_by_a_cell_are_the_last_resort():
    """A corridor 6 cells (0.30 m) wide between thick obstacles: the lethal bands of both sides
    close it, one cell thinner it is open. Every frontier lies beyond it, so without the fallback
    the search ends "no frontier left" with floor unseen (Gibson: a passage between a bed and a
    wall, 0.14-0.16 m clear of the mapped cells on either side, robot radius 0.18 m)."""
    grid = corridor_grid(6)
    robot = xy_of(grid, 30, 20)
    tracker = FrontierTracker()
    fr = tracker.update(grid, robot)
    assert fr and tracker.squeezed
    assert all(grid.world_to_cell(f.centroid)[1] >= 90 for f in fr)  # all beyond the corridor
    assert FrontierTracker(FrontierConfig(squeeze_fallback=False)).update(grid, robot) == []


def test_a_squeezed_frontier_waits_while_another_is_reachable():
    s = corridor_grid(6).state.copy()
    s[20:26, 10] = 0  # an opening in the room's west wall toward the unknown outside
    s[20:26, 5:10] = 0
    grid = snapshot(s)
    tracker = FrontierTracker(FrontierConfig(min_size_cells=4))
    fr = tracker.update(grid, xy_of(grid, 30, 20))
    assert fr and not tracker.squeezed
    assert all(grid.world_to_cell(f.centroid)[1] < 40 for f in fr)  # only the room's own opening


def test_a_passage_two_cells_too_narrow_stays_closed():
    tracker = FrontierTracker()
    assert tracker.update(corridor_grid(4), xy_of(corridor_grid(4), 30, 20)) == []
    assert not tracker.squeezed
