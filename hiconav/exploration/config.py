"""Settings of the exploration area (frontier utility, weights, motion cost, WTRP ordering,
goal hysteresis), validated by pydantic. Data only: no computation here.

Symbols follow the paper (section "Context-Aware Frontier Exploration", "Goal Selection and Planning"). Equation numbers
used throughout hiconav.exploration: S (9), phi_j (10), s~_j (11), S_struct (12), S_vis (13),
C_i (14), WTRP objective (15), W (16), t (17), c_c (18), c_s (19), M_0k (20), M_krks (21).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from hiconav.limits import MAX_DURATION_S


class UtilityConfig(BaseModel):
    """exploration.utility.*: S(f) = l1 S_struct(f) + l2 S_vis(f) and the weights W (eq. 16)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    lambda1: float = Field(1.0, ge=0.0, description="weight of S_struct (eq. 9)")
    lambda2: float = Field(1.0, ge=0.0, description="weight of S_vis (eq. 9)")
    gamma: float = Field(1.5, ge=1.0, description="semantic gain of related objects O_r (eq. 11)")
    beta: float = Field(3.0, ge=0.0, description="temperature of W = exp(beta S_bar) / exp(beta) (eq. 16)")
    weight_min_range: float = Field(0.1, ge=0.0, description="eq. 16's min-max normalisation divides by "
                                    "max(S_max - S_min, this): frontiers whose utilities differ by less "
                                    "weigh nearly alike, and travel time orders them (0: the paper's plain "
                                    "min-max)")
    sigma_scale: float = Field(1.0, gt=0.0, description="sigma_j = sigma_scale * mean 3D box extent (m)")
    sigma_min: float = Field(0.5, gt=0.0, description="lower clip of sigma_j (m): tiny boxes still "
                             "spread context over a room part")
    sigma_max: float = Field(3.0, gt=0.0, description="upper clip of sigma_j (m)")
    reach_sigma: float = Field(2.0, ge=0.0, description="sigma_j (m) of a target candidate that verification set "
                               "aside as out of reach (no view point of it on the map yet) is at least this: it "
                               "draws the frontiers on the way to it, not only those within its own extent (0: as "
                               "other objects). Chosen on the Gibson tune floors (docs/results_history.md, stop 60)")
    exclude_rejected: bool = Field(False, description="nodes the mission's verification rejected for good are no "
                                   "target evidence: S_struct leaves them out as it leaves out the ones the reasoning "
                                   "layer ruled out")
    similarity_floor: float = Field(0.45, description="s_j = max(0, similarity - floor): text embedders give "
                                    "unrelated labels ~0.4-0.5 (MiniLM), which would make S_struct count "
                                    "objects instead of relevant ones; 0.45 suits MiniLM (see report)")
    min_object_similarity: float = Field(0.0, description="objects with s_j (after the floor) below this add "
                                         "nothing")
    vis_range: float = Field(8.0, gt=0.0, description="range of an anchor's frustum for S_vis (m): the "
                             "image sees past the mapping depth")
    vis_hfov_margin_deg: float = Field(0.0, ge=0.0, description="widen the anchor frustum by this (deg)")
    use_struct: bool = Field(True, description="ablation: S_struct on/off")
    use_vis: bool = Field(True, description="ablation: S_vis on/off")


class CostConfig(BaseModel):
    """exploration.cost.*: the transition costs M (eq. 17-21)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    v_max: float = Field(0.5, gt=0.0, description="max linear speed (m/s), eq. 17")
    xi_dot_max: float = Field(0.8, gt=0.0, description="max yaw rate (rad/s), eq. 17")
    w_c: float = Field(1.0, ge=0.0, description="weight of the motion-consistency term c_c (s/rad), eq. 18, 20")
    w_f: float = Field(0.0, ge=0.0, description="weight of the openness term c_s (s), eq. 19, 20: above 0 a "
                       "confined unknown pocket is visited first. The paper gives no value; 0 was chosen on the "
                       "Gibson tune floors (docs/results_history.md, stop 59)")
    h_max: float = Field(3.0, gt=0.0, description="truncation of the ray-cast openness h_k (m), eq. 19")
    min_speed: float = Field(0.05, ge=0.0, description="below this |v_0| (m/s) c_c is 0 (no heading)")
    stride: int = Field(2, ge=1, description="the geodesic Dijkstra runs on the grid coarsened "
                        "by this factor (a coarse cell is traversable if any fine cell is and none is an obstacle)")
    snap_radius_m: float = Field(0.5, ge=0.0, description="a robot/viewpoint cell that is blocked snaps to "
                                 "the nearest traversable cell within this radius (m)")
    unknown_traversable: bool = Field(False, description="treat unknown cells as traversable (optimistic)")


class OrderingConfig(BaseModel):
    """exploration.ordering.*: the WTRP solve and goal hysteresis."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    ordering: Literal["wtrp", "greedy_utility", "nearest"] = Field(
        "wtrp", description="ablation: WTRP order, highest weight first, or nearest first")
    solver: str = Field("auto", description="WTRP solver: auto | exact | ils | ortools | greedy | module:callable")
    time_limit: float = Field(0.2, gt=0.0, le=MAX_DURATION_S, description="solver time limit (s) per plan")
    stepped_restarts: int = Field(2, ge=1, description="on the stepped clock the ILS has no time limit and "
                                  "runs this many starts instead, so an episode is the same on any machine")
    seed: int = 0
    switch_margin: float = Field(0.1, ge=0.0, description="switch goals only if the new order's objective is "
                                 "lower than keeping the current goal first by this fraction")
    reached_distance: float = Field(0.5, ge=0.0, description="the current goal counts as reached within this "
                                    "distance of its viewpoint (m)")
    max_frontiers: int = Field(60, ge=1, description="keep at most this many frontiers (largest weight first)")


class ExplorationConfig(BaseModel):
    """exploration.*"""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    utility: UtilityConfig = Field(default_factory=UtilityConfig)
    cost: CostConfig = Field(default_factory=CostConfig)
    ordering: OrderingConfig = Field(default_factory=OrderingConfig)
