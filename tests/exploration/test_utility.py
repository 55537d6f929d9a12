"""Frontier utility (eq. 9-13) and weights (eq. 16) on hand-made cases."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _exploration_fakes import make_anchor, make_object, similarity

from hiconav.exploration.config import UtilityConfig
from hiconav.exploration.utility import (
    LabelScorer,
    frontier_utility,
    object_sigma,
    structural_utility,
    utility_weights,
    visual_utility,
)
from hiconav.types import TaskSpec

TASK = TaskSpec("find a bed", targets=("bed",), related=("nightstand",))


def scorer() -> LabelScorer:
    return LabelScorer(TASK, similarity)


def test_struct_peaks_at_the_object_with_its_similarity() -> None:
    cfg = UtilityConfig(similarity_floor=0.0)
    obj = make_object("sofa", (2.0, 1.0), (1.0, 1.0, 1.0))
    xs = np.linspace(-2, 6, 81)
    pts = np.stack([xs, np.full_like(xs, 1.0)], axis=1)
    s = structural_utility(pts, [obj], scorer(), cfg)
    assert xs[np.argmax(s)] == pytest.approx(2.0)
    assert s.max() == pytest.approx(0.3)  # s_j = similarity(sofa, bed), no boost
    assert np.all(np.diff(s[xs >= 2.0]) < 0)  # decays away from the object


def test_sigma_is_the_mean_box_extent() -> None:
    cfg = UtilityConfig(sigma_scale=1.0, sigma_min=0.1, sigma_max=10.0, similarity_floor=0.0)
    obj = make_object("sofa", (0.0, 0.0), (1.0, 2.0, 3.0))
    assert object_sigma(obj.box_min, obj.box_max, cfg) == pytest.approx(2.0)
    s = structural_utility(np.array([[2.0, 0.0], [0.0, 4.0]]), [obj], scorer(), cfg)
    assert s[0] == pytest.approx(0.3 * math.exp(-0.5))  # at one sigma
    assert s[1] == pytest.approx(0.3 * math.exp(-2.0))  # at two sigma
    # clipping
    assert object_sigma(obj.box_min, obj.box_max, UtilityConfig(sigma_max=1.5)) == pytest.approx(1.5)


def test_gamma_boosts_related_objects_only() -> None:
    cfg = UtilityConfig(gamma=2.0, similarity_floor=0.0)
    related = make_object("nightstand", (0.0, 0.0), (0.5, 0.5, 0.5))
    other = make_object("lamp", (10.0, 0.0), (0.5, 0.5, 0.5))
    s = structural_utility(np.array([[0.0, 0.0], [10.0, 0.0]]), [related, other], scorer(), cfg)
    assert s[0] == pytest.approx(2.0 * 0.6)
    assert s[1] == pytest.approx(0.4)


def test_struct_is_a_superposition() -> None:
    cfg = UtilityConfig(similarity_floor=0.0)
    a = make_object("sofa", (0.0, 0.0), (1.0, 1.0, 1.0))
    b = make_object("lamp", (1.0, 0.0), (1.0, 1.0, 1.0))
    p = np.array([[0.5, 0.3]])
    both = structural_utility(p, [a, b], scorer(), cfg)
    assert both == pytest.approx(structural_utility(p, [a], scorer(), cfg) + structural_utility(p, [b], scorer(), cfg))


def test_vis_uses_the_latest_anchor_whose_frustum_contains_the_frontier() -> None:
    cfg = UtilityConfig(vis_range=8.0, similarity_floor=0.0)
    old = make_anchor(0, 0, 0.0, stamp=1.0, labels=("toilet",))
    new = make_anchor(0, 0, 0.0, stamp=2.0, labels=("sofa", "nightstand"))
    behind = make_anchor(0, 0, math.pi, stamp=3.0, labels=("bed",))
    pts = np.array([[3.0, 0.5],   # in front: seen by old and new -> new (max over labels: 0.6)
                    [-3.0, 0.0],  # behind: only the anchor facing -x
                    [3.0, 6.0],   # outside the 90 deg field of view of all
                    [20.0, 0.0]])  # beyond vis_range
    s = visual_utility(pts, [old, new, behind], scorer(), cfg)
    assert s.tolist() == pytest.approx([0.6, 1.0, 0.0, 0.0])


def test_total_utility_and_ablations() -> None:
    obj = make_object("sofa", (3.0, 0.0), (1.0, 1.0, 1.0))
    anc = make_anchor(0, 0, 0.0, 1.0, ("lamp",))
    pts = np.array([[3.0, 0.0]])
    S, st, sv = frontier_utility(pts, [obj], [anc], TASK, similarity, UtilityConfig(lambda1=2.0, lambda2=0.5, similarity_floor=0.0))
    assert st[0] == pytest.approx(0.3) and sv[0] == pytest.approx(0.4)
    assert S[0] == pytest.approx(2.0 * 0.3 + 0.5 * 0.4)
    S, st, _ = frontier_utility(pts, [obj], [anc], TASK, similarity, UtilityConfig(use_struct=False, similarity_floor=0.0))
    assert st[0] == 0.0 and S[0] == pytest.approx(0.4)
    S, _, sv = frontier_utility(pts, [obj], [anc], TASK, similarity, UtilityConfig(use_vis=False, similarity_floor=0.0))
    assert sv[0] == 0.0 and S[0] == pytest.approx(0.3)


def test_exact_target_label_scores_one_without_the_embedder() -> None:
    calls = []

    def counting(a: str, b: str) -> float:
        calls.append((a, b))
        return 0.2

    sc = LabelScorer(TaskSpec("find the tv", targets=("tv",)), counting)
    assert sc("TV") == 1.0 and calls == []
    assert sc("sofa") == 0.2 and sc("sofa") == 0.2 and len(calls) == 1  # memoised


def test_weights_in_unit_interval_and_monotone() -> None:
    rng = np.random.default_rng(0)
    S = rng.normal(size=50)
    W = utility_weights(S, beta=4.0)
    assert np.all(W > 0) and np.all(W <= 1)
    assert W.max() == pytest.approx(1.0)
    assert W.min() == pytest.approx(math.exp(-4.0))
    assert np.all(np.diff(W[np.argsort(S)]) >= 0)
    assert utility_weights(np.full(5, 0.3), beta=4.0).tolist() == [1.0] * 5
    assert utility_weights(np.array([0.0, 1.0]), beta=0.0).tolist() == [1.0, 1.0]
    # larger beta = more contrast (eq. 16)
    assert utility_weights(np.array([0.0, 1.0]), beta=5.0)[0] < utility_weights(np.array([0.0, 1.0]), beta=1.0)[0]


def test_weight_floor_keeps_small_utility_spreads_from_ordering_the_frontiers() -> None:
    """eq. 16 with ``min_range``: a spread below the floor is the evidence's noise, so the weights
    stay near 1 (travel time orders the frontiers); a spread above it is stretched as before."""
    small = np.array([0.50, 0.51, 0.52])
    plain = utility_weights(small, beta=3.0)
    assert plain.min() == pytest.approx(math.exp(-3.0))  # 0.02 apart: weights 0.05 .. 1
    floored = utility_weights(small, beta=3.0, min_range=0.1)
    assert floored.max() == pytest.approx(1.0)
    assert floored.min() == pytest.approx(math.exp(-3.0 * 0.02 / 0.1))  # 0.55: nearly alike
    assert np.all(np.diff(floored) > 0)  # the order by utility is kept
    wide = np.array([0.0, 0.3, 0.6])
    assert utility_weights(wide, beta=3.0, min_range=0.1) == pytest.approx(utility_weights(wide, beta=3.0))
    assert utility_weights(np.full(4, 0.2), beta=3.0, min_range=0.1).tolist() == [1.0] * 4


def test_weight_floor_turns_the_wtrp_order_to_travel_time() -> None:
    """Two frontiers with near-equal utility: without the floor the WTRP visits the slightly
    better far one first; with it the near one (less travel, the same expected find)."""
    from hiconav.exploration.wtrp import solve_wtrp

    travel = np.array([[0.0, 2.0, 10.0], [2.0, 0.0, 9.0], [10.0, 9.0, 0.0]])  # 0: robot, 1: near, 2: far
    S = np.array([0.50, 0.52])
    for floor, first in ((0.0, 2), (0.1, 1)):
        W = utility_weights(S, beta=3.0, min_range=floor)
        order = list(solve_wtrp(travel, W, method="exact").order)
        assert order[0] == first, (floor, order)


def test_similarity_floor_removes_the_embedder_baseline() -> None:
    """s_j = max(0, similarity - floor): a weakly related object adds nothing, a related one
    keeps its excess; the anchor score (S_vis) uses the same floor."""
    cfg = UtilityConfig(similarity_floor=0.35, gamma=1.0)
    weak = make_object("sofa", (0.0, 0.0), (1.0, 1.0, 1.0))  # similarity 0.3
    strong = make_object("nightstand", (10.0, 0.0), (1.0, 1.0, 1.0))  # similarity 0.6
    s = structural_utility(np.array([[0.0, 0.0], [10.0, 0.0]]), [weak, strong], scorer(), cfg)
    assert s[0] == pytest.approx(0.0, abs=1e-12)
    assert s[1] == pytest.approx(0.6 - 0.35)
    pts = np.array([[3.0, 0.0]])
    assert visual_utility(pts, [make_anchor(0, 0, 0.0, 1.0, ("sofa",))], scorer(), cfg)[0] == 0.0
    assert visual_utility(pts, [make_anchor(0, 0, 0.0, 1.0, ("sofa", "lamp"))], scorer(),
                          cfg)[0] == pytest.approx(0.4 - 0.35)


def test_a_candidate_out_of_reach_draws_the_frontiers_on_the_way_to_it() -> None:
    """reach_sigma: a target's box seen from afar (a sliver) spreads its field no farther than
    sigma_min, and the frontier through which the way to it goes, 3 m off, reads 0; once
    verification has set it aside as out of reach (``drawn``) that frontier reads the target's
    field at 3 m. Other objects, and the same box not drawn, keep their sigma."""
    from types import SimpleNamespace

    def node(i, obj):
        return SimpleNamespace(id=i, label=obj.label, center=obj.center, box_min=obj.box_min, box_max=obj.box_max)

    sliver = node(1, make_object("bed", (4.0, 0.0), (0.05, 0.3, 0.2)))
    lamp = node(2, make_object("nightstand", (-4.0, 10.0), (0.05, 0.3, 0.2)))
    pts = np.array([[1.0, 0.0], [-1.0, 10.0]])  # 3 m from each
    cfg = UtilityConfig(similarity_floor=0.0, gamma=1.0, reach_sigma=2.0)
    plain = structural_utility(pts, [sliver, lamp], scorer(), cfg)
    assert plain[0] < 1e-6 and plain[1] < 1e-6
    drawn = structural_utility(pts, [sliver, lamp], scorer(), cfg, drawn={1})
    assert drawn[0] == pytest.approx(1.0 * math.exp(-9.0 / 8.0))
    assert drawn[1] == pytest.approx(plain[1], abs=1e-6)
    off = structural_utility(pts, [sliver, lamp], scorer(), UtilityConfig(similarity_floor=0.0, gamma=1.0, reach_sigma=0.0),
                             drawn={1})
    assert off[0] == pytest.approx(plain[0])  # reach_sigma 0: as other objects
