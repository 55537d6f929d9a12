"""Renderer: metric depth, instance ids consistent with geometry, RGB texture, EGL errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sim_synthetic import box_room, obj

from hiconav.sim.house import Wall
from hiconav.sim.renderer import Renderer, RenderError
from hiconav.sim.simulator import Simulator
from hiconav.types import CameraIntrinsics, Pose2D, camera_pose_from_base

K = CameraIntrinsics.from_hfov(640, 480, 79)


def _render(house, pose: Pose2D, tilt: float = 0.0, **kw):
    r = Renderer(640, 480, **kw)
    r.set_house(house)
    try:
        return r.render(camera_pose_from_base(pose, 0.88, tilt), K)
    finally:
        r.release()


def test_depth_of_a_wall_at_known_distance_within_1cm():
    # Wall centred on x = 3 with 0.1 m thickness: its face is the plane x = 2.95.
    house = box_room(8.0, extra_walls=[Wall((3.0, 0.5), (3.0, 7.5), 2.5, 0.1)])
    rgb, depth, inst = _render(house, Pose2D(1.0, 4.0, 0.0))
    assert rgb.shape == (480, 640, 3) and rgb.dtype == np.uint8
    assert depth.shape == (480, 640) and depth.dtype == np.float32
    assert inst.shape == (480, 640) and inst.dtype == np.int32
    # A fronto-parallel plane has the same optical-axis depth in every pixel it covers.
    band = depth[200:280, 40:600]
    assert np.all(np.abs(band - 1.95) < 0.01), (band.min(), band.max())
    assert np.all(inst[200:280] == -1)


def test_depth_of_an_oblique_wall_matches_ray_geometry():
    house = box_room(8.0, extra_walls=[Wall((3.0, 0.5), (3.0, 7.5), 2.5, 0.1)])
    yaw = math.radians(20.0)
    _rgb, depth, _inst = _render(house, Pose2D(1.0, 4.0, yaw))
    # Pixel (v=240, u): ray direction in the camera frame ((u - cx)/fx, 0, 1); world x of the
    # ray hits the plane x = 2.95.
    for u in (100, 320, 500):
        dx_cam = (u - K.cx) / K.fx
        # camera x axis = right = (sin yaw, -cos yaw); z = forward = (cos yaw, sin yaw).
        wx = math.cos(yaw) + dx_cam * math.sin(yaw)
        expected = (2.95 - 1.0) / wx  # depth along z where the ray reaches x = 2.95
        assert abs(depth[240, u] - expected) < 0.01, (u, depth[240, u], expected)


def test_depth_outside_the_range_reads_zero():
    house = box_room(8.0, extra_walls=[Wall((3.0, 0.5), (3.0, 7.5), 2.5, 0.1)])
    _, depth, _ = _render(house, Pose2D(1.0, 4.0, 0.0), max_depth=1.5)
    assert np.all(depth[200:280, 40:600] == 0.0)
    _, depth, _ = _render(house, Pose2D(1.0, 4.0, 0.0), min_depth=2.5)
    assert np.all(depth[200:280, 40:600] == 0.0)


def test_instances_in_view_are_the_objects_in_the_frustum():
    objects = [
        obj(0, "chair", (4.0, 4.0, 0.45), (0.5, 0.5, 0.9)),      # ahead
        obj(1, "sofa", (3.5, 5.2, 0.4), (0.8, 0.4, 0.8)),        # ahead-left, inside hfov
        obj(2, "bed", (0.6, 4.0, 0.3), (0.6, 1.0, 0.6)),         # behind the camera
        obj(3, "tv", (2.0, 7.4, 1.0), (0.6, 0.2, 0.4)),          # far to the left, outside
        obj(4, "plant", (6.0, 2.8, 0.2), (0.3, 0.3, 0.4)),       # ahead-right, 4 m away
    ]
    house = box_room(8.0, objects)
    pose = Pose2D(2.0, 4.0, 0.0)
    _, _depth, inst = _render(house, pose)
    T = camera_pose_from_base(pose, 0.88)
    view = np.linalg.inv(T)
    expected = set()
    for o in objects:
        pc = view[:3, :3] @ o.center + view[:3, 3]
        if pc[2] <= 0:
            continue
        u, v = K.fx * pc[0] / pc[2] + K.cx, K.fy * pc[1] / pc[2] + K.cy
        if 0 <= u < 640 and 0 <= v < 480:
            expected.add(o.instance_id)
    seen = set(np.unique(inst).tolist()) - {-1}
    assert seen == expected == {0, 1, 4}


def _backproject(depth, T):
    v, u = np.nonzero(depth > 0)
    z = depth[v, u].astype(np.float64)
    pc = np.stack([(u - K.cx) / K.fx * z, (v - K.cy) / K.fy * z, z], axis=1)
    return v, u, pc @ T[:3, :3].T + T[:3, 3]


@pytest.mark.parametrize("spec", ["procthor:val/3", "gibson:Allensville"])
def test_instance_pixels_backproject_into_their_object_box(shared_data, spec):
    from hiconav.sim.episodes import generate_episodes
    from hiconav.sim.houses import load_house

    house = load_house(spec, shared_data)
    sim = Simulator(house)
    checked = 0
    views = [Pose2D(ep.start.x, ep.start.y, ep.start.yaw + k * 2.0)
             for ep in generate_episodes(house, 5, seed=3) for k in range(3)]
    for pose in views:
        frame = sim.reset(pose)
        v, u, pts = _backproject(frame.depth, frame.T_world_cam)
        ids = frame.instances[v, u]
        for iid in np.unique(ids):
            if iid < 0:
                continue
            o = house.objects[iid]
            grown = type(o)(o.instance_id, o.category, o.center, o.size + 0.04, o.yaw,
                            o.source_type)
            inside = grown.contains(pts[ids == iid])
            assert inside.mean() > 0.99, (spec, iid, inside.mean())
            checked += 1
    sim.close()
    assert checked >= 3


def test_rgb_is_textured_and_shaded_not_flat():
    house = box_room(8.0, [obj(0, "sofa", (4.0, 4.0, 0.4), (1.0, 2.0, 0.8))])
    rgb, _, inst = _render(house, Pose2D(1.5, 3.0, 0.3))
    pix = rgb[inst == 0].astype(float)
    assert len(pix) > 1000
    assert pix.std(axis=0).max() > 3.0  # texture noise and shading vary within one object
    wall = rgb[(inst == -1)].astype(float)
    assert len(np.unique(wall.reshape(-1, 3), axis=0)) > 50


def test_egl_failure_names_the_cause(monkeypatch):
    import moderngl

    from hiconav.sim import renderer

    def boom(*a, **k):
        raise RuntimeError("libEGL.so.1: cannot open shared object file")

    monkeypatch.setattr(renderer, "_THREAD_CONTEXTS", {})
    monkeypatch.setattr(moderngl, "create_standalone_context", boom)
    with pytest.raises(RenderError, match="EGL.*libEGL.so.1"):
        Renderer(64, 48)


def test_a_simulator_driven_from_another_thread_still_renders():
    import threading

    from hiconav.sim.config import SimConfig

    house = box_room(8.0, extra_walls=[Wall((3.0, 0.5), (3.0, 7.5), 2.5, 0.1)])
    sim = Simulator(house, SimConfig(width=160, height=120))
    first = sim.reset(Pose2D(1.0, 4.0, 0.0))  # renders in this thread
    out = {}

    def worker():
        out["frame"] = sim.observe()  # an actor thread takes over the simulator

    t = threading.Thread(target=worker)
    t.start()
    t.join()
    assert first.depth[60, 80] == pytest.approx(1.95, abs=0.01)
    assert out["frame"].depth[60, 80] == pytest.approx(1.95, abs=0.01)
    renderer = Renderer(64, 48)
    renderer.set_house(house)
    errors = []
    t = threading.Thread(target=lambda: errors.append(
        pytest.raises(RenderError, renderer.render, np.eye(4), CameraIntrinsics.from_hfov(64, 48, 79))))
    t.start()
    t.join()
    assert errors  # a Renderer refuses a foreign thread instead of returning blank images


def _door_house():
    """An L-shaped room (concave floor polygon) with a 1 m door in its exterior east wall."""
    from hiconav.sim.house import Room, assemble_house

    poly = np.array([[0, 0], [6, 0], [6, 6], [3, 6], [3, 8], [0, 8]], float)
    walls = [Wall((0.0, 0.0), (6.0, 0.0), 2.5, 0.1),
             Wall((6.0, 0.0), (6.0, 6.0), 2.5, 0.1, holes=((3.0, 4.0, 0.0, 2.0),)),
             Wall((6.0, 6.0), (3.0, 6.0), 2.5, 0.1), Wall((3.0, 6.0), (3.0, 8.0), 2.5, 0.1),
             Wall((3.0, 8.0), (0.0, 8.0), 2.5, 0.1), Wall((0.0, 8.0), (0.0, 0.0), 2.5, 0.1)]
    return assemble_house("door", [Room("room|0", "LivingRoom", poly)], walls, []), poly


def test_no_floor_or_ceiling_is_visible_beyond_an_exterior_door():
    house, _ = _door_house()
    pose = Pose2D(4.5, 3.5, 0.0)  # 1.5 m in front of the door (x = 6, y in [3, 4]), facing it
    _rgb, depth, inst = _render(house, pose, max_depth=20.0)
    T = camera_pose_from_base(pose, 0.88)
    _v, _u, pts = _backproject(depth, T)
    assert len(pts) > 10000
    # Floor inside the room is rendered up to the wall line ...
    floor = np.abs(pts[:, 2]) < 0.01
    assert (floor & (pts[:, 0] > 5.5)).sum() > 500
    # ... and nothing at all beyond the exterior wall: background (no depth, no instance).
    assert not np.any(pts[:, 0] > 6.06), pts[pts[:, 0] > 6.06][:5]
    # The door opening's lower part (a ray from the camera hits x = 7 at floor-ish height)
    # shows background: depth 0 and instance -1.
    view = np.linalg.inv(T)
    pc = view[:3, :3] @ np.array([7.0, 3.5, 0.3]) + view[:3, 3]
    uu, vv = int(K.fx * pc[0] / pc[2] + K.cx), int(K.fy * pc[1] / pc[2] + K.cy)
    assert depth[vv, uu] == 0.0 and inst[vv, uu] == -1


def test_floor_covers_exactly_the_concave_room_polygon():
    from matplotlib.path import Path as MplPath

    house, poly = _door_house()
    for pose in (Pose2D(1.5, 1.0, math.radians(60)), Pose2D(1.5, 7.5, -math.radians(60))):
        T = camera_pose_from_base(pose, 0.88, -math.radians(30))
        _rgb, depth, _inst = _render(house, pose, tilt=-math.radians(30), max_depth=20.0)
        _v, _u, pts = _backproject(depth, T)
        floor = pts[np.abs(pts[:, 2]) < 0.01, :2]
        assert len(floor) > 20000
        # every floor point lies in the L (grown by the half wall thickness the walls hide)
        assert MplPath(poly).contains_points(floor, radius=0.1).all() or \
            MplPath(poly[::-1]).contains_points(floor, radius=0.1).all()


def test_scanned_house_floor_is_only_over_floor_cells(shared_data):
    """Gibson: rendered floor points lie on navigable cells, object footprints or next to them."""
    from scipy import ndimage

    from hiconav.sim.episodes import generate_episodes
    from hiconav.sim.house import floor_mask
    from hiconav.sim.houses import load_house

    house = load_house("gibson:Allensville", shared_data)
    allowed = ndimage.binary_dilation(floor_mask(house), np.ones((5, 5), bool))
    r = Renderer(640, 480, max_depth=20.0)
    r.set_house(house)
    n = 0
    try:
        for ep in generate_episodes(house, 4, seed=5):
            T = camera_pose_from_base(ep.start, 0.88, -math.radians(30))
            _rgb, depth, _inst = r.render(T, K)
            _v, _u, pts = _backproject(depth, T)
            rc = house.nav.world_to_cell(pts[np.abs(pts[:, 2]) < 0.01, :2])
            assert house.nav.in_bounds(rc).all()
            assert allowed[rc[:, 0], rc[:, 1]].all()
            n += len(rc)
    finally:
        r.release()
    assert n > 20000


@pytest.mark.parametrize("reverse", [False, True])
def test_ear_clipping_covers_a_rectilinear_polygon_exactly(reverse):
    from hiconav.sim.house import triangulate_polygon

    # U shape with a collinear corner on the bottom edge; area 6*4 - 2*3 = 18
    poly = np.array([[0, 0], [3, 0], [6, 0], [6, 4], [4, 4], [4, 1], [2, 1], [2, 4], [0, 4]],
                    float)
    poly = poly[::-1] if reverse else poly
    t = poly[triangulate_polygon(poly)]
    area = 0.5 * ((t[:, 1, 0] - t[:, 0, 0]) * (t[:, 2, 1] - t[:, 0, 1])
                  - (t[:, 1, 1] - t[:, 0, 1]) * (t[:, 2, 0] - t[:, 0, 0]))
    assert np.all(area > 0)  # counter-clockwise whatever the input orientation
    assert area.sum() == pytest.approx(18.0)
    centres = t.mean(axis=1)  # no triangle bridges the notch x in (2, 4), y > 1
    assert not np.any((centres[:, 0] > 2) & (centres[:, 0] < 4) & (centres[:, 1] > 1))
    with pytest.raises(ValueError):
        triangulate_polygon(np.array([[0, 0], [1, 0], [2, 0]], float))
