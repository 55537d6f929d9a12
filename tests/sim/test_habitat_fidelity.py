"""Gibson as Habitat defines it (issue #26): the centre's free space, any-angle distances, SemExp's
success rule, data files anywhere, and runs that record bad episodes instead of crashing."""

from __future__ import annotations

import bz2
import gzip
import json
import math
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
from scipy import ndimage
import pytest

from hiconav.sim.fmm import disk, fmm_distance
from hiconav.sim.geodesic import GoalDistance, centre_free, distance_mask
from hiconav.sim.gibson import floor_for_height, load_info, render_obstacles
from hiconav.sim.houses import load_house
from hiconav.sim.simulator import Simulator

# ------------------------------------------------------------------------- fast marching


def test_fast_marching_follows_the_straight_line_in_open_space():
    open_grid = np.ones((60, 60), dtype=bool)
    src = np.zeros_like(open_grid)
    src[5, 5] = True
    d = fmm_distance(open_grid, src, 0.05)
    assert d[5, 5] == 0.0
    # 8-connected Dijkstra gives 40 + 10 (sqrt 2 - 1) = 44.1 cells here; the line is 41.2
    assert d[15, 45] == pytest.approx(0.05 * math.hypot(10, 40), rel=0.01)


def test_fast_marching_bends_round_walls_and_never_crosses_them():
    grid = np.ones((40, 40), dtype=bool)
    grid[0:35, 20] = False  # a wall with a gap at the bottom rows 35..39
    src = np.zeros_like(grid)
    src[2, 10] = True
    d = fmm_distance(grid, src, 1.0)
    round_the_end = 2 * math.hypot(33, 10)  # down to the wall's end and back up
    assert round_the_end <= d[2, 30] <= 1.04 * round_the_end
    assert math.isinf(fmm_distance(grid & (np.arange(40)[:, None] < 35), src, 1.0)[2, 30])


def test_cells_no_path_reaches_are_infinite_and_no_source_means_all_infinite():
    grid = np.ones((10, 10), dtype=bool)
    grid[:, 5] = False
    src = np.zeros_like(grid)
    src[0, 0] = True
    d = fmm_distance(grid, src, 0.05)
    assert np.isinf(d[:, 6:]).all() and np.isfinite(d[:, :5]).all()
    assert np.isinf(fmm_distance(grid, np.zeros_like(grid), 0.05)).all()


def test_disk_is_skimage_disk():
    assert disk(2).sum() == 13 and disk(1).sum() == 5 and disk(2).shape == (5, 5)


# ------------------------------------------------------------------- the centre's free space


def test_gibson_channel_0_is_where_the_centre_may_stand(shared_data):
    house = load_house("gibson:Allensville/0", shared_data)
    free = centre_free(house, 0.18)
    assert house.centre_free is not None and np.array_equal(free, house.centre_free)
    sim = Simulator(house)
    assert np.array_equal(sim.free, free)  # not shrunk a second time by the robot radius
    # a navmesh cell next to its edge is a place the robot may stand
    edge = free & ~np.pad(free, 1)[2:, 1:-1]
    rc = np.argwhere(edge)[0]
    assert sim.is_free(house.nav.cell_to_world(rc))


def test_procthor_free_space_keeps_the_robot_radius_from_walls(shared_data):
    house = load_house("procthor:val/3", shared_data)
    assert house.centre_free is None and house.success_rule == "view_points"
    free = centre_free(house, 0.18)
    assert free.sum() < house.nav.navigable.sum()


def test_obstacles_stand_one_agent_radius_beyond_the_navmesh():
    nav = np.zeros((40, 60), dtype=bool)
    nav[5:35, 5:25] = True
    nav[5:35, 30:55] = True  # two rooms; a band of 5 cells (0.25 m) between them
    drawn = render_obstacles(nav, np.zeros_like(nav), radius=0.18, res=0.05)
    # around the outside, walls start more than 0.18 m (3.6 cells) beyond the navmesh
    assert drawn[20, 0] and not drawn[20, 1:5].any()
    # the thin band between the rooms keeps its middle (the ridge), not its edges
    assert drawn[20, 27] and not drawn[20, 25] and not drawn[20, 29]
    assert not (drawn & nav).any()


def test_a_robot_map_inflated_by_its_radius_opens_the_navmesh_doorways(shared_data):
    house = load_house("gibson:Allensville/0", shared_data)
    from hiconav.sim.geodesic import traversable

    seen_free = traversable(house.nav, 0.18)  # the drawn obstacles and objects, inflated by the radius
    free = centre_free(house, 0.18)
    # the navmesh cells are free on a map built from what the robot sees; shrinking the navmesh
    # by the radius again (the rule before stop 25) kept 2 of Habitat's 25 reference paths
    # traversable, and drawing labelled objects on all their cells (before stop 58) closed 12% of
    # this floor's navmesh, up to the objects whose projections the navmesh comes right up to
    assert (seen_free & free).sum() >= 0.99 * free.sum()


def test_a_labelled_object_is_drawn_one_agent_radius_beyond_the_navmesh(shared_data):
    house = load_house("gibson:Benevolence/0", shared_data)
    sofa = max(house.instances_of("sofa"), key=lambda o: len(house.footprint(o.instance_id)))
    cells = house.footprint(sofa.instance_id)
    drawn = ~house.nav.navigable[cells[:, 0], cells[:, 1]]
    dist = ndimage.distance_transform_edt(~house.centre_free)[cells[:, 0], cells[:, 1]] * 0.05
    # the sofa's scanned footprint reaches the navmesh: the cells nearer than the radius are not
    # drawn (the robot would see the corridor beside it closed), the rest are, and every cell of
    # the footprint still counts for success
    assert (dist <= 0.18).any() and not drawn[dist <= 0.18].any()
    assert drawn[dist > 0.25].all() and drawn.sum() >= 0.5 * len(cells)


def test_a_gap_the_navmesh_closes_is_drawn_across():
    nav = np.zeros((41, 61), dtype=bool)
    nav[1:40, 1:60] = True
    nav[5:20, 25:36] = False
    nav[21:36, 25:36] = False  # two pillars' navmesh holes, 1 cell apart
    nav[20, 30] = False  # the navmesh does not pass between them
    drawn = render_obstacles(nav, np.zeros_like(nav), radius=0.18, res=0.05)
    # the pillars are drawn from 0.18 m inside the holes' edges; between them the cells lie
    # nearer the navmesh than that, and without a line across the gap the robot saw it open
    assert drawn[20, 30]
    assert not drawn[20, 26:30].any() and not drawn[20, 31:35].any()  # the gap's crest only
    assert not (drawn & nav).any()


# ------------------------------------------------------------------------ success and SPL


def test_semexp_success_region_is_the_category_dilated_by_the_success_distance(shared_data):
    house = load_house("gibson:Allensville/0", shared_data)
    ids = [o.instance_id for o in house.instances_of("sofa")]
    goal = GoalDistance(house, instance_ids=ids)
    region = goal.success_region(1.0)
    foot = np.zeros(house.nav.shape, dtype=bool)
    for i in ids:
        c = house.footprint(i)
        foot[c[:, 0], c[:, 1]] = True
    from scipy import ndimage

    expected = ndimage.binary_dilation(foot, structure=disk(20))
    assert np.array_equal(region, expected)
    # the object field is <= 1 m exactly on the region, and the distance to it is 0 there
    assert np.array_equal(goal.field <= 1.0, region)
    field = goal.success_field(1.0)
    assert (field[region] == 0).all()
    outside = np.isfinite(field) & ~region
    assert (field[outside] > 0).all()


def test_semexp_success_needs_no_line_of_sight():
    from hiconav.sim.house import House, NavGrid, SimObject

    nav = np.ones((60, 60), dtype=bool)
    nav[:, 30] = False  # a wall; the object stands just behind it
    centre = nav.copy()
    obj = SimObject(0, "bed", np.array([1.6, 1.5, 0.3]), np.array([0.1, 0.1, 0.6]), 0.0, "test")
    house = House("test", [obj], NavGrid(nav, np.zeros(2), 0.05), centre_free=centre, success_rule="semexp",
                  footprints={0: np.array([[30, 32]])})
    goal = GoalDistance(house, instance_ids=[0])
    # 0.5 m from the bed on the far side of the wall: inside the region (SemExp: no sight test)
    assert goal.distance(np.array([1.1, 1.5])) <= 1.0


def test_reference_paths_are_traversable_with_habitat_like_distances(shared_data):
    from hiconav.sim.fidelity import check_path, read_reference_paths, summarise

    refs = read_reference_paths(shared_data / "gibson" / "reference_paths.jsonl")
    checks = [check_path(shared_data / "gibson" / "train_info.pbz2", ref) for ref in refs]
    s = summarise(checks)
    assert s["paths"] == 25
    # every path on a floor the maps file holds, but Woodbine's (its start lies in a chair's
    # footprint 0.35 m below the floor), is valid; the others are paths 2.4-3.3 m up or down
    on_floor = [c for c in checks if c.floor is not None]
    assert sum(c.valid for c in on_floor) >= len(on_floor) - 1 and s["valid"] >= 17
    # channel 0 is Habitat's navmesh: fast marching on it stays within 3% of Habitat's distances
    # (the grid's staircase boundary and first-order marching add a little, never take away)
    assert 1.0 <= s["ratio_min"] and s["ratio_max"] <= 1.03
    off = [c for c in checks if c.floor is None]
    assert all("no floor" in c.reason for c in off)


def test_semexp_mask_cuts_corners_below_habitats_distances(shared_data):
    from hiconav.sim.fidelity import check_path, read_reference_paths, summarise

    refs = read_reference_paths(shared_data / "gibson" / "reference_paths.jsonl")
    maps = shared_data / "gibson" / "train_info.pbz2"
    semexp = [check_path(maps, ref, mask="semexp") for ref in refs]
    navmesh = [check_path(maps, ref, mask="navmesh") for ref in refs]
    s = summarise(semexp)
    assert s["valid"] == summarise(navmesh)["valid"]
    # the 2-cell dilation widens every passage: every distance shrinks, none by more than 5%
    assert 0.95 <= s["ratio_min"] and s["ratio_max"] < 1.0
    assert all(a.ours < b.ours for a, b in zip(semexp, navmesh) if a.valid and b.valid)
    with pytest.raises(ValueError, match="mask"):
        check_path(maps, refs[0], mask="navmeshes")


def test_floor_is_chosen_by_the_start_height(shared_data):
    maps = shared_data / "gibson" / "train_info.pbz2"
    assert floor_for_height(maps, "Allensville", 0.18) == 0
    assert floor_for_height(maps, "Allensville", 2.8) is None


# ------------------------------------------------------------------------ data files anywhere


ISLAND = 5  # cells: the half size of a walled-off navigable island added to Allensville


def _island_centre(sem_map):
    from scipy import ndimage

    d = ndimage.distance_transform_edt(sem_map[0] == 0)
    m = 2 * ISLAND
    d[:m], d[-m:], d[:, :m], d[:, -m:] = 0, 0, 0, 0  # away from the map's edge
    return np.unravel_index(int(np.argmax(d)), d.shape)


@pytest.fixture()
def my_maps(shared_data, tmp_path):
    """A maps file of two scenes in a folder outside the data root; Allensville gains a small
    navigable island far from its floor (a closet no path reaches)."""
    info = load_info(str(shared_data / "gibson" / "train_info.pbz2"))
    mine = {k: {f: dict(rec) for f, rec in info[k].items()} for k in ("Allensville", "Cosmos")}
    sem = np.array(mine["Allensville"][0]["sem_map"])
    r, c = _island_centre(sem)
    sem[0, r - ISLAND:r + ISLAND + 1, c - ISLAND:c + ISLAND + 1] = 1.0
    mine["Allensville"][0]["sem_map"] = sem
    path = tmp_path / "elsewhere" / "val_info.pbz2"
    path.parent.mkdir()
    with bz2.BZ2File(path, "wb") as fh:
        pickle.dump(mine, fh)
    return path


def test_a_maps_file_anywhere_loads_by_file_and_scene(my_maps):
    from hiconav.eval.sources import gibson_house_specs

    specs = gibson_house_specs(my_maps)
    assert specs == [f"{my_maps.resolve()}#Allensville/0", f"{my_maps.resolve()}#Cosmos/0"]
    house = load_house(specs[0])
    assert house.success_rule == "semexp" and house.objects
    assert load_house(f"{my_maps}#Allensville").name == house.name


def test_held_out_split_takes_the_first_13_scenes_for_tuning(shared_data):
    from hiconav.eval.sources import gibson_house_specs

    maps = shared_data / "gibson" / "train_info.pbz2"
    tune, report = gibson_house_specs(maps, "tune"), gibson_house_specs(maps, "report")
    scenes = sorted(load_info(str(maps)))
    assert [s.split(":")[1].split("/")[0] for s in tune] == scenes[:13]
    assert len(report) == 12 and not set(tune) & set(report)
    with pytest.raises(Exception, match="Atlantis"):
        gibson_house_specs(maps, "Atlantis")


def _write_episodes(path, episodes):
    with gzip.open(path, "wt") as fh:
        json.dump({"episodes": episodes}, fh)


def _bad_and_good_episodes(shared_data, maps):
    """A good episode, one whose start is in a wall, and one that starts on the island."""
    from scipy import ndimage

    from hiconav.sim.episodes import generate_episodes

    house = load_house(f"{maps}#Allensville/0")
    (good,) = generate_episodes(house, 1, seed=3)
    base = {"scene_id": "gibson/Allensville.glb", "start_rotation": [0, 0, 0, 1], "floor_id": 0}
    mask = distance_mask(house, 0.18)
    wall = np.argwhere(~mask & ~ndimage.binary_dilation(mask, iterations=12))[0]
    lonely = np.array(_island_centre(np.asarray(load_info(str(shared_data / "gibson" / "train_info.pbz2"))
                                                ["Allensville"][0]["sem_map"])))

    def habitat(rc):
        xy = house.nav.cell_to_world(rc)
        return [float(xy[1]), house.floor_height + 0.1, float(xy[0])]

    return [
        {**base, "episode_id": "good", "start_position": [good.start.y, 0.1, good.start.x],
         "object_category": {"sofa": "couch", "plant": "potted plant"}.get(good.target, good.target)},
        {**base, "episode_id": "blocked", "start_position": habitat(wall), "object_category": "chair"},
        {**base, "episode_id": "unreachable", "start_position": habitat(lonely), "object_category": "chair"},
    ]


def test_unreachable_and_blocked_episodes_are_recorded_in_a_run_of_good_ones(shared_data, my_maps, tmp_path,
                                                                           monkeypatch):
    from hiconav.eval.config import EvalConfig
    from hiconav.eval.records import read_records
    from hiconav.eval.runner import evaluate
    from hiconav.eval.sources import gibson_source

    monkeypatch.syspath_prepend(str(Path(__file__).resolve().parents[1] / "eval"))  # sim_walker

    files = tmp_path / "content"
    files.mkdir()
    _write_episodes(files / "Allensville_episodes.json.gz", _bad_and_good_episodes(shared_data, my_maps))
    specs = gibson_source(my_maps, [files])
    by_id = {s.episode_id.rsplit("/", 1)[-1]: s for s in specs}
    assert by_id["good"].error is None
    assert "not on the traversable area" in by_id["blocked"].error
    assert "reachable" in by_id["unreachable"].error
    config = EvalConfig(runner="sim_walker:run_episode", workers=0, progress=False, report=False)
    evaluate(specs, tmp_path / "out", config)
    records = {r.episode_id.rsplit("/", 1)[-1]: r for r in read_records(tmp_path / "out" / "episodes.jsonl")}
    assert set(records) == {"good", "blocked", "unreachable"}
    assert records["good"].error is None and records["good"].steps > 0
    assert records["blocked"].error and records["unreachable"].error
    text = (tmp_path / "out" / "episodes.jsonl").read_text()
    assert "Infinity" not in text and "NaN" not in text


def _cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "hiconav.cli", *args], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


def test_dry_run_counts_valid_and_invalid_episodes_by_reason(shared_data, my_maps, tmp_path):
    files = tmp_path / "content"
    files.mkdir()
    _write_episodes(files / "Allensville_episodes.json.gz", _bad_and_good_episodes(shared_data, my_maps))
    done = _cli("eval", "--maps", str(my_maps), "--episodes", str(files), "--out", str(tmp_path / "o"), "--dry-run")
    assert done.returncode == 0, done.stderr
    last = json.loads(done.stdout.strip().splitlines()[-1])
    assert last == {"episodes": 3, "valid": 1, "invalid": {"no goal reachable from the start": 1,
                                                          "start off the traversable area": 1}}
    assert not (tmp_path / "o" / "episodes.jsonl").exists()


def test_a_run_with_no_valid_episode_exits_non_zero_with_the_reasons(shared_data, my_maps, tmp_path):
    files = tmp_path / "content"
    files.mkdir()
    _write_episodes(files / "Allensville_episodes.json.gz", _bad_and_good_episodes(shared_data, my_maps)[1:])
    for extra in (["--dry-run"], []):
        done = _cli("eval", "--maps", str(my_maps), "--episodes", str(files), "--out", str(tmp_path / "o"),
                    "--workers", "0", "--no-progress", *extra)
        assert done.returncode != 0
        assert "no episode of the input is valid" in done.stdout + done.stderr
        assert "Traceback" not in done.stderr


def test_a_procthor_houses_file_anywhere_runs_by_file_and_line(shared_data, tmp_path):
    source = shared_data / "procthor" / "val.jsonl.gz"
    mine = tmp_path / "houses" / "mine.jsonl.gz"
    mine.parent.mkdir()
    with gzip.open(source, "rt") as fh, gzip.open(mine, "wt") as out:
        out.writelines([next(fh) for _ in range(4)])
    house = load_house(f"{mine}#3")
    assert house.name == f"{mine.resolve()}#3"
    assert [o.category for o in house.objects] == [o.category for o in load_house("procthor:val/3").objects]
    shutil.copy(mine, tmp_path / "copy.jsonl.gz")
    with pytest.raises(Exception, match="out of range"):
        load_house(f"{tmp_path / 'copy.jsonl.gz'}#9")


def test_a_goal_joined_to_the_start_only_through_semexps_dilation_is_invalid(shared_data):
    from hiconav.eval.sources import EpisodeSpec, invalid_reason, validate_spec

    # Woodbine's toilet (the report floors' episode 4 at seed 0): SemExp's distance, on channel 0
    # dilated by 2 cells, is finite (16.2 m), but no piece of channel 0 that the robot can drive
    # on joins the start to the toilet's success region: recorded invalid, with the reason
    toilet = EpisodeSpec("gibson:Woodbine/0/4", "gibson:Woodbine/0", "toilet", (-1.175, -3.305, 2.75), (13,))
    error = validate_spec(toilet)
    assert error is not None and "only through SemExp's" in error
    assert invalid_reason(error) == "goal reachable only through SemExp's dilation"
    bed = EpisodeSpec("gibson:Woodbine/0/3", "gibson:Woodbine/0", "bed", (-2.075, -3.205, 0.95), (12,))
    assert validate_spec(bed) is None
    # a run records it as the dry run counts it: invalid, not a failure of the robot
    from hiconav.errors import DataError
    from hiconav.mission import run_episode

    with pytest.raises(DataError, match="only through SemExp's"):
        run_episode(toilet)


def test_generated_gibson_starts_lie_where_the_robot_can_drive_to_the_goal(shared_data):
    from hiconav.eval.sources import validate_spec
    from hiconav.sim.episodes import generate_episodes
    from hiconav.sim.geodesic import driving_pieces, reaching_pieces

    # Woodbine's toilet is cut off on channel 0 from most of the floor (the test above): a start is
    # drawn only on a piece of the robot's free space that holds the goal's success region, as
    # Habitat's generator keeps only starts with a navmesh path; the dry run's check then holds
    house = load_house("gibson:Woodbine/0")
    episodes = generate_episodes(house, 40, seed=0)
    pieces = driving_pieces(centre_free(house, 0.18))
    assert {ep.target for ep in episodes} >= {"toilet", "bed"}
    for ep in episodes:
        region = GoalDistance(house, ep).success_region(1.0)
        rc = house.nav.world_to_cell(np.array([ep.start.x, ep.start.y]))
        assert reaching_pieces(pieces, region)[rc[0], rc[1]], ep.episode_id
    from hiconav.eval.sources import generate_for_house

    assert all(validate_spec(spec) is None for spec in generate_for_house("gibson:Woodbine/0", 16, 0))
    # the rule: a piece counts only when it holds a region cell
    lone = np.zeros((5, 9), dtype=bool)
    lone[1:4, 1:3] = True
    lone[1:4, 5:8] = True
    region = np.zeros_like(lone)
    region[2, 6] = True
    assert np.array_equal(reaching_pieces(driving_pieces(lone), region), lone & (np.arange(9) >= 5))
    assert not reaching_pieces(driving_pieces(lone), np.zeros_like(lone)).any()


def test_a_gibson_record_carries_semexps_own_spl_beside_ours(shared_data):
    """On SemExp's maps a record also carries SPL as SemExp's code computes it (the success distance
    added to the shortest path, as published Gibson tables use); ours keeps Habitat's l^s."""
    from hiconav.eval.sources import EpisodeSpec
    from hiconav.eval.summary import semexp_code_spl, spl_value
    from hiconav.mission import run_episode

    chair = EpisodeSpec("gibson:Merom/0/0", "gibson:Merom/0", "chair", (-8.795, 4.535, 2.2467), (0, 1, 2), 1.875,
                        "find the chair")
    record = run_episode(chair, {"sim.max_steps": 60}, 506636410)
    assert record.success
    shortest = record.extra["shortest_to_success"]
    assert record.spl == pytest.approx(spl_value(True, shortest, record.path_length))
    assert record.extra["spl_semexp"] == pytest.approx(semexp_code_spl(True, shortest, 1.0, record.path_length))
    assert record.extra["spl_semexp"] > record.spl
    # the path beyond the shortest, split by the behaviours the steps served, adds up to the path less l
    excess = record.extra["excess_path"]
    assert excess["unmeasured_m"] == 0.0 and set(excess["by_behaviour"]) <= {"LookAround", "VerifyTarget", "Approach",
                                                                             "Explore"}
    assert sum(excess["by_behaviour"].values()) == pytest.approx(record.path_length - shortest, abs=1e-2)
