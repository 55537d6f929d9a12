"""The exploration planner: frontiers -> utilities -> weights -> motion costs -> WTRP order ->
mid-term goal, with hysteresis (paper "Goal Selection and Planning").

One call of ``ExplorationPlanner.plan`` (meant for 1-2 Hz):
1. utilities S, S_struct, S_vis at the frontier centroids from the memory snapshot (eq. 9-13);
2. weights W = exp(beta minmax(S)) / exp(beta) (eq. 16), over all frontiers of this call;
3. the cost matrix M over the frontiers reachable from the robot (eq. 17-21), unreachable
   ones dropped; at most ``max_frontiers`` kept (largest weight first);
4. the order: WTRP (eq. 15, ``solve_wtrp``) or an ablation ("greedy_utility": highest weight
   first; "nearest": smallest M_0k first);
5. hysteresis: if the previous goal is still a reachable frontier and not reached, keep it
   first unless the new order's objective is lower than the objective of "previous goal first,
   then the new order" by more than ``switch_margin`` (relative). The first node is the
   mid-term goal; the rest is guidance.

The planner keeps only the previous goal id between calls. It is pure and synchronous: it must
not navigate, read sensors or own the grid/memory (it receives read-only snapshots).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Collection, Sequence
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from hiconav.exploration.config import ExplorationConfig
from hiconav.exploration.cost import CostMatrix, GridLike, cost_matrix
from hiconav.exploration.utility import AnchorLike, ObjectLike, frontier_utility, utility_weights
from hiconav.exploration.wtrp import AUTO_EXACT_MAX_N, solve_wtrp, wtrp_cost
from hiconav.types import Frontier, Goal, Pose2D, TaskSpec, label_key


def _exact_label_match(label: str, target: str) -> float:
    """FALLBACK similarity when no embedder is given: 1.0 for the same label, else 0.0."""
    return float(label_key(label) == label_key(target))


class SnapshotLike(Protocol):
    """What the planner needs of a memory MemorySnapshot (None = empty memory)."""

    objects: Sequence[ObjectLike]
    anchors: Sequence[AnchorLike]


@dataclass(frozen=True)
class ExplorationPlan:
    """Result of one planning call.

    goal: the mid-term goal frontier (None when no frontier is reachable); order: frontier ids
    in visiting order (goal first); weights / utilities: W (eq. 16) and S (eq. 9) by frontier id
    (every frontier of the call, reachable or not); switched: the goal differs from the previous
    call's; solver: the ordering used ("exact", "ils", ..., "greedy_utility", "nearest", or
    "none"); cost: WTRP objective (eq. 15) of ``order``; dropped: ids unreachable from the robot.
    """

    goal: Frontier | None
    order: tuple[int, ...]
    weights: dict[int, float]
    utilities: dict[int, float]
    switched: bool
    solver: str
    cost: float = 0.0
    dropped: tuple[int, ...] = ()
    kept_previous: bool = False
    stamp: float = 0.0
    seconds: float = 0.0
    s_struct: dict[int, float] = field(default_factory=dict)
    s_vis: dict[int, float] = field(default_factory=dict)

    def goal_message(self, tolerance: float = 0.25) -> Goal | None:
        """The goal as a hiconav.types.Goal at the frontier's viewpoint (kind "frontier")."""
        if self.goal is None:
            return None
        x, y = (float(v) for v in self.goal.viewpoint)
        return Goal(x=x, y=y, yaw=None, tolerance=tolerance, kind="frontier", ref_id=self.goal.id)


class ExplorationPlanner:
    """Frontier ordering with goal hysteresis (see module docstring).

    ``deterministic`` (the stepped clock): the ILS, which the "auto" and "ils" solvers use
    above ``AUTO_EXACT_MAX_N`` frontiers, runs ``ordering.stepped_restarts`` starts with no
    time limit instead of stopping at ``ordering.time_limit`` wall seconds. A wall-time limit
    binds from about 30 frontiers on (0.2 s), so the order, and with it the episode, depended
    on how fast and how busy the machine was; ``hiconav eval`` promises the same episode for
    the same seed."""

    def __init__(self, config: ExplorationConfig | None = None, *, deterministic: bool = False) -> None:
        self.config = config or ExplorationConfig()
        self.deterministic = deterministic
        self.goal_id: int | None = None
        self.last_cost: CostMatrix | None = None  # diagnostics of the last call

    def reset(self) -> None:
        """Forget the current goal (new episode)."""
        self.goal_id = None
        self.last_cost = None

    def _order(self, M: np.ndarray, W: np.ndarray) -> tuple[tuple[int, ...], str]:
        ocfg = self.config.ordering
        n = M.shape[0] - 1
        if ocfg.ordering == "greedy_utility":
            order = np.lexsort((M[0, 1:], -W)) + 1  # highest weight first, ties: nearest
            return tuple(int(i) for i in order), "greedy_utility"
        if ocfg.ordering == "nearest":
            return tuple(int(i) for i in np.argsort(M[0, 1:], kind="stable") + 1), "nearest"
        if n == 0:
            return (), "none"
        if self.deterministic and (ocfg.solver == "ils" or (ocfg.solver == "auto" and n > AUTO_EXACT_MAX_N)):
            from hiconav.exploration.wtrp.ils import solve_ils  # numba: imported when first needed

            sol = solve_ils(M, W, time_limit=None, max_restarts=ocfg.stepped_restarts, seed=ocfg.seed)
        else:
            sol = solve_wtrp(M, W, method=ocfg.solver, time_limit=ocfg.time_limit, seed=ocfg.seed)
        return sol.order, sol.method

    def plan(self, grid: GridLike, frontiers: Sequence[Frontier], snapshot: SnapshotLike | None,
             task: TaskSpec, pose: Pose2D, velocity_xy: np.ndarray | Sequence[float],
             similarity: Callable[[str, str], float] | None, now: float = 0.0,
             ruled_out: Collection[int] = (), drawn: Collection[int] = (),
             rejected: Collection[int] = ()) -> ExplorationPlan:
        """Order the frontiers and pick the mid-term goal.

        grid: the current occupancy grid (snapshot); frontiers: from the FrontierTracker (stable
        ids); snapshot: memory objects/anchors (None = none); pose: robot base pose (world);
        velocity_xy: (2,) robot velocity in the world frame (m/s); similarity(label, target) in
        [0, 1]-ish (an Embedder's similarity; None = FALLBACK exact label match only: 1 for a
        target label, 0 otherwise); now: stamp copied into the plan; ruled_out: ids of memory
        objects that are no evidence of the target (instances of its category that the reasoning
        layer judged not to be the described one): S_struct leaves them out, or the robot would
        be drawn back, frontier after frontier, to the wrong instances it has already seen;
        rejected: ids of nodes the mission's verification rejected for good (left out like the
        ruled-out ones when ``exclude_rejected``); drawn: ids of target candidates the mission
        set aside as out of reach (no view point on the map yet): their field reaches at least
        ``reach_sigma`` (``utility.object_peaks``).
        """
        if similarity is None:
            similarity = _exact_label_match
        t0 = time.perf_counter()
        ucfg, ocfg = self.config.utility, self.config.ordering
        previous = self.goal_id
        frontiers = list(frontiers)
        objects = tuple(getattr(snapshot, "objects", ())) if snapshot is not None else ()
        skip = set(ruled_out) | (set(rejected) if ucfg.exclude_rejected else set())
        if skip:
            objects = tuple(o for o in objects if getattr(o, "id", None) not in skip)
        anchors = tuple(getattr(snapshot, "anchors", ())) if snapshot is not None else ()
        ids = [f.id for f in frontiers]
        if not frontiers:
            self.goal_id = None
            return ExplorationPlan(None, (), {}, {}, previous is not None, "none", stamp=now,
                                   seconds=time.perf_counter() - t0)
        centroids = np.array([np.asarray(f.centroid, float)[:2] for f in frontiers])
        S, s_struct, s_vis = frontier_utility(centroids, objects, anchors, task, similarity, ucfg,
                                              drawn=frozenset(drawn) - skip)
        W_all = utility_weights(S, ucfg.beta, ucfg.weight_min_range)  # eq. 16
        weights = {i: float(w) for i, w in zip(ids, W_all)}
        utilities = {i: float(s) for i, s in zip(ids, S)}
        extra = {"s_struct": {i: float(v) for i, v in zip(ids, s_struct)},
                 "s_vis": {i: float(v) for i, v in zip(ids, s_vis)}}

        cm = cost_matrix(grid, pose.xy, pose.yaw, np.asarray(velocity_xy, float), frontiers, self.config.cost)
        if not cm.kept:
            # no frontier is reachable on the lethal layer: the tracker keeps, as a last resort, those
            # a passage one cell thinner reaches (``FrontierTracker``), and they are costed so too
            cm = cost_matrix(grid, pose.xy, pose.yaw, np.asarray(velocity_xy, float), frontiers, self.config.cost,
                             squeeze=True)
        kept = list(cm.kept)
        dropped = tuple(ids[i] for i in range(len(frontiers)) if i not in set(kept))
        M = cm.M
        if len(kept) > ocfg.max_frontiers:  # keep the heaviest (then nearest) frontiers
            sel = np.lexsort((M[0, 1:], -W_all[kept]))[: ocfg.max_frontiers]
            sel = np.sort(sel)
            dropped = dropped + tuple(ids[kept[i]] for i in range(len(kept)) if i not in set(sel.tolist()))
            M = M[np.ix_(np.concatenate([[0], sel + 1]), np.concatenate([[0], sel + 1]))]
            kept = [kept[i] for i in sel]
        self.last_cost = cm
        if not kept:
            self.goal_id = None
            return ExplorationPlan(None, (), weights, utilities, previous is not None, "none",
                                   dropped=dropped, stamp=now, seconds=time.perf_counter() - t0, **extra)
        W = W_all[kept]
        order, solver = self._order(M, W)
        cost = wtrp_cost(M, W, order)

        # hysteresis: keep the previous goal first unless the new order is better by the margin
        kept_previous = False
        node_of_id = {ids[k]: j + 1 for j, k in enumerate(kept)}
        if previous is not None and previous in node_of_id and order and node_of_id[previous] != order[0]:
            g = node_of_id[previous]
            f_prev = frontiers[kept[g - 1]]
            reached = float(np.hypot(*(np.asarray(f_prev.viewpoint, float) - pose.xy))) <= ocfg.reached_distance
            if not reached:
                keep_order = (g,) + tuple(i for i in order if i != g)
                keep_cost = wtrp_cost(M, W, keep_order)
                if not cost < (1.0 - ocfg.switch_margin) * keep_cost:
                    order, cost, kept_previous = keep_order, keep_cost, True
        goal = frontiers[kept[order[0] - 1]]
        self.goal_id = goal.id
        return ExplorationPlan(
            goal=goal, order=tuple(ids[kept[i - 1]] for i in order), weights=weights, utilities=utilities,
            switched=goal.id != previous, solver=solver, cost=float(cost), dropped=dropped,
            kept_previous=kept_previous, stamp=now, seconds=time.perf_counter() - t0, **extra)
