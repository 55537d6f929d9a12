"""hiconav.perception.OracleDetector: boxes and masks from the instance channel, seeded noise."""

from __future__ import annotations

import logging

import numpy as np
import pytest

from hiconav.errors import FrameError
from hiconav.perception import DETECTORS, Detector, OracleConfig, OracleDetector
from hiconav.types import CameraIntrinsics, Frame, Pose2D, camera_pose_from_base

H, W = 120, 160
CATS = {0: "sofa", 1: "tv", 2: "plant", 3: "chair", 4: "bed", 7: "toilet"}
PERFECT = OracleConfig(miss_rate=0.0, false_positive_rate=0.0, confusion_rate=0.0, min_pixel_area=20)


def make_frame(seq: int = 0, inst: np.ndarray | None = None) -> Frame:
    if inst is None:
        inst = np.full((H, W), -1, np.int32)
        inst[10:40, 20:70] = 0  # sofa 30 x 50
        inst[50:60, 100:110] = 1  # tv 10 x 10
        inst[80:82, 5:8] = 2  # plant: 6 px, below any sensible min area
        inst[60:100, 120:150] = 3  # chair
        inst[0:5, 0:5] = 99  # an id the house does not know (wall, floor): never reported
    K = CameraIntrinsics.from_hfov(W, H, 79.0)
    return Frame(
        rgb=np.zeros((H, W, 3), np.uint8),
        depth=np.ones((H, W), np.float32),
        intrinsics=K,
        T_world_cam=camera_pose_from_base(Pose2D(0, 0, 0), 0.88),
        base_pose=Pose2D(0, 0, 0),
        stamp=0.0,
        instances=inst,
        seq=seq,
    )


def test_perfect_oracle_gives_exact_boxes_and_masks():
    det = OracleDetector(CATS, PERFECT)
    assert isinstance(det, Detector)
    out = {d.label: d for d in det.detect(make_frame(), [])}
    assert set(out) == {"sofa", "tv", "chair"}  # plant too small, id 99 unknown
    sofa = out["sofa"]
    np.testing.assert_array_equal(sofa.box_xyxy, [20, 10, 70, 40])
    assert sofa.mask.shape == (H, W) and sofa.mask.sum() == 30 * 50 and sofa.mask[10:40, 20:70].all()
    assert sofa.instance_id == 0 and sofa.source == "oracle"
    assert all(d.source == "oracle" and 0.0 < d.score <= 1.0 for d in out.values())
    assert not sofa.mask.flags.writeable


def test_vocabulary_filters_and_keeps_the_callers_words():
    det = OracleDetector(CATS, PERFECT)
    out = det.detect(make_frame(), ["Couch", "television"])
    assert sorted(d.label for d in out) == ["Couch", "television"]


def test_min_pixel_area():
    det = OracleDetector(CATS, PERFECT.model_copy(update={"min_pixel_area": 2}))
    assert "plant" in {d.label for d in det.detect(make_frame(), [])}
    det = OracleDetector(CATS, PERFECT.model_copy(update={"min_pixel_area": 400}))
    assert {d.label for d in det.detect(make_frame(), [])} == {"sofa", "chair"}


def summary(dets):
    return [(d.label, round(d.score, 9), tuple(d.box_xyxy), d.instance_id) for d in dets]


def test_noise_is_deterministic_per_seed_and_frame_seq():
    cfg = OracleConfig(miss_rate=0.3, false_positive_rate=0.5, confusion_rate=0.3, min_pixel_area=20)
    a = OracleDetector(CATS, cfg, seed=7)
    b = OracleDetector(CATS, cfg, seed=7)
    runs = [summary(a.detect(make_frame(seq=s), [])) for s in range(30)]
    assert runs == [summary(b.detect(make_frame(seq=s), [])) for s in range(30)]
    assert runs[3] == summary(a.detect(make_frame(seq=3), []))  # same frame again: same answer
    c = OracleDetector(CATS, cfg, seed=8)
    assert runs != [summary(c.detect(make_frame(seq=s), [])) for s in range(30)]


def test_noise_rates_are_close_to_the_configured_ones():
    cfg = OracleConfig(miss_rate=0.2, false_positive_rate=0.3, confusion_rate=0.25, min_pixel_area=20)
    det = OracleDetector(CATS, cfg, seed=1)
    n, seen, fps, confused = 600, 0, 0, 0
    for s in range(n):
        for d in det.detect(make_frame(seq=s), []):
            if d.instance_id is None:
                fps += 1
                assert d.label in set(CATS.values()) - {"sofa", "tv", "chair"} or d.label == "plant"
            else:
                seen += 1
                confused += d.label != CATS[d.instance_id]
    assert seen / (3 * n) == pytest.approx(0.8, abs=0.05)
    assert fps / n == pytest.approx(0.3, abs=0.06)
    assert confused / seen == pytest.approx(0.25, abs=0.05)


def test_confusions_are_between_similar_categories():
    cfg = OracleConfig(miss_rate=0.0, false_positive_rate=0.0, confusion_rate=1.0, min_pixel_area=20)
    det = OracleDetector(CATS, cfg)
    labels = {d.instance_id: d.label for d in det.detect(make_frame(), [])}
    assert labels[0] in {"armchair", "bed"}  # sofa
    assert labels[1] in {"laptop", "monitor"}  # tv
    assert labels[3] in {"armchair", "stool"}  # chair


def test_default_noise_makes_verification_matter():
    cfg = OracleConfig()
    assert cfg.miss_rate > 0 and cfg.false_positive_rate > 0 and cfg.confusion_rate > 0


def test_frame_without_instances_is_rejected():
    frame = make_frame()
    bare = Frame(
        rgb=frame.rgb,
        depth=frame.depth,
        intrinsics=frame.intrinsics,
        T_world_cam=frame.T_world_cam,
        base_pose=frame.base_pose,
        stamp=0.0,
    )
    with pytest.raises(FrameError, match="instances"):
        OracleDetector(CATS).detect(bare, [])


def test_oracle_is_registered_and_announces_itself(caplog):
    assert DETECTORS.get("oracle") is OracleDetector
    with caplog.at_level(logging.INFO, logger="hiconav.perception.oracle"):
        OracleDetector(CATS)
    assert any("oracle" in r.getMessage().lower() for r in caplog.records)


def test_oracle_on_a_rendered_frame(shared_data):
    sim_mod = pytest.importorskip("hiconav.sim")
    house = sim_mod.load_house("procthor:val/3")
    sim = sim_mod.Simulator(house)
    free = np.argwhere(sim.free)
    xy = house.nav.cell_to_world(free[len(free) // 2])
    frame = sim.reset(Pose2D(float(xy[0]), float(xy[1]), 0.0))
    best = []
    for _ in range(12):
        dets = OracleDetector(house.instance_categories, PERFECT).detect(frame, [])
        best = dets if len(dets) > len(best) else best
        frame = sim.step(__import__("hiconav.types", fromlist=["DiscreteAction"]).DiscreteAction.TURN_LEFT)
    assert best, "no object seen in a full turn"
    for d in best:
        assert d.label == house.instance_categories[d.instance_id]
        x0, y0, x1, y1 = d.box_xyxy
        assert 0 <= x0 < x1 <= 640 and 0 <= y0 < y1 <= 480


def test_build_detector_from_config():
    from hiconav.errors import ConfigError
    from hiconav.perception import PerceptionConfig, build_detector

    det = build_detector(PerceptionConfig(), instance_categories=CATS, seed=3)
    assert isinstance(det, OracleDetector) and det.seed == 3
    with pytest.raises(ConfigError, match="perception.detector"):
        build_detector(PerceptionConfig())  # the oracle outside the simulator
    with pytest.raises(ConfigError, match=r"perception\.owlvit\.weights_path"):
        build_detector(PerceptionConfig(detector="owlvit"))
    with pytest.raises(ConfigError, match="perception.detector"):
        build_detector(PerceptionConfig(detector="yolo"))


def test_counter_draws_are_uniform_and_keyed_by_seed_seq_and_key():
    from hiconav.perception.oracle import CounterDraws

    a = CounterDraws(7, 3, 11).random(4)
    assert a == CounterDraws(7, 3, 11).random(4)
    assert a != CounterDraws(7, 3, 12).random(4) and a != CounterDraws(7, 4, 11).random(4)
    assert a != CounterDraws(8, 3, 11).random(4)
    u = np.array([CounterDraws(0, seq, key).random() for seq in range(200) for key in range(50)])
    assert 0.0 <= u.min() and u.max() < 1.0
    assert abs(u.mean() - 0.5) < 0.01 and abs(np.mean(u < 0.1) - 0.1) < 0.01
    k = np.array([CounterDraws(1, seq, 0).integers(3, 7) for seq in range(4000)])
    assert set(k.tolist()) == {3, 4, 5, 6} and abs(np.mean(k == 6) - 0.25) < 0.03
