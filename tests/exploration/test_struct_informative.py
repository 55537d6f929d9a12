"""S_struct must help: on real ProcTHOR layouts, with the other objects of the house as memory,
points near an (unseen) target score higher than points far from it (AUC > 0.5), and the
similarity floor (s_j = max(0, s - floor)) makes the signal stronger. Slow: loads MiniLM."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pytest

from hiconav.exploration.config import UtilityConfig
from hiconav.exploration.utility import LabelScorer, structural_utility
from hiconav.types import TaskSpec

TARGETS = ("bed", "sofa", "toilet", "tv", "dining_table", "plant", "chair")


@dataclass(frozen=True)
class _Obj:
    label: str
    center: np.ndarray
    box_min: np.ndarray
    box_max: np.ndarray


def _auc(score: np.ndarray, pos: np.ndarray) -> float:
    from scipy.stats import rankdata

    r = rankdata(score)
    n1, n0 = int(pos.sum()), int((~pos).sum())
    return float((r[pos].sum() - n1 * (n1 + 1) / 2) / (n1 * n0))


@pytest.mark.slow
def test_struct_ranks_points_near_the_target_higher(shared_data) -> None:
    sim_mod = pytest.importorskip("hiconav.sim")
    perception = pytest.importorskip("hiconav.perception")
    similarity = perception.get_embedder("minilm").similarity
    rng = np.random.default_rng(0)
    aucs: dict[float, list[float]] = {0.0: [], 0.45: []}
    for k in range(10):  # train houses: the floor was chosen on val houses 0-19
        house = sim_mod.load_house(f"procthor:train/{k}")
        free = np.argwhere(house.nav.navigable)
        pts = house.nav.cell_to_world(free[rng.choice(len(free), min(300, len(free)), replace=False)])
        for t in TARGETS:
            tgt = np.array([np.asarray(o.center)[:2] for o in house.objects if o.category == t])
            if len(tgt) == 0:
                continue
            pos = np.min(np.linalg.norm(pts[:, None] - tgt[None], axis=-1), axis=1) < 2.0
            if pos.sum() < 5 or (~pos).sum() < 5:
                continue
            memory = [_Obj(o.category, np.asarray(o.center), np.asarray(o.center) - np.asarray(o.size) / 2,
                           np.asarray(o.center) + np.asarray(o.size) / 2) for o in house.objects if o.category != t]
            scorer = LabelScorer(TaskSpec(f"find {t}", targets=(t,)), similarity)
            for floor, values in aucs.items():
                s = structural_utility(pts, memory, scorer, UtilityConfig(similarity_floor=floor))
                values.append(_auc(s, pos) if s.max() > s.min() else 0.5)
    assert len(aucs[0.45]) >= 20
    assert np.mean(aucs[0.45]) > 0.65
    assert np.mean(aucs[0.45]) > np.mean(aucs[0.0]) + 0.05
