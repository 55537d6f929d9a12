"""Settings of the cognitive memory graph (CMG), validated by pydantic.

Only data lives here: no graph code, nothing heavier than pydantic. Field names follow the
paper's symbols where it names them (delta_d, delta_theta, lambda_1, lambda_2, tau, r).

Defaults and where they come from:
- delta_d = 1.0 m, delta_theta = 45 deg: the anchor gate of eq. (2) (values given in issue #5).
- lambda_1 = lambda_2 = 0.5, tau = 0.6: eq. (4). The paper gives no numbers; ConceptGraphs-style
  mergers (geometric + semantic terms, equal weights) use 0.5-0.6 of the combined maximum. With
  equal weights a detection merges into a node of the same label (s_s = 1) when s_g >= 0.2, and
  into one of a different label with s_s ~ 0.5 only when s_g >= 0.7.
- s_g: the paper says "3D IoU between point clouds". Plain IoU of axis-aligned boxes fails on
  partial views (one visible face of a box is a flat slab that barely overlaps the next view's
  slab): on a 150-step ProcTHOR replay it left 23 duplicate nodes for 24 objects. The default is
  therefore ``geometric="overlap"``: intersection over the smaller of the two boxes, each padded by
  ``box_padding`` (5 cm); that replay then has 4 duplicates and no node mixing two objects.
  ``geometric="iou"`` restores the paper's wording.
- max_depth = 6 m: the authors' mapping range; detections beyond it are kept only as the anchor's
  ``labels_seen`` (out-of-boundary visual evidence).
- voxel = 2 cm for object point clouds; r = 2 for the multicover of eq. (7).
"""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, ConfigDict, Field

from hiconav.limits import MAX_DURATION_S


class MemoryConfig(BaseModel):
    """memory.* settings of the cognitive memory graph."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    # Anchor gate, eq. (2)
    delta_d: float = Field(1.0, gt=0.0, description="anchor when translation since last anchor > delta_d (m)")
    delta_theta_deg: float = Field(45.0, gt=0.0, le=180.0,
                                   description="anchor when rotation since last anchor > delta_theta (deg)")
    anchor_on_new_label: bool = Field(True, description="a label never seen before (even beyond "
                                      "max_depth) counts as a new object for the gate")
    image_width: int = Field(160, ge=8, description="width of the anchor image kept for the VLM (px)")
    image_height: int = Field(120, ge=8, description="height of the anchor image kept for the VLM (px)")

    # Detection -> 3D
    min_depth: float = Field(0.1, ge=0.0, description="ignore depth below this (m)")
    max_depth: float = Field(6.0, gt=0.0, description="detections farther than this are not mapped (m)")
    stride: int = Field(2, ge=1, description="minimum pixel stride of mask back-projection")
    max_pixels: int = Field(1500, ge=100, description="the stride grows so that one detection "
                            "samples at most about this many pixels")
    min_points: int = Field(10, ge=1, description="a detection needs this many 3D points to be mapped")
    voxel: float = Field(0.02, gt=0.0, description="voxel size of object point clouds (m)")
    max_points: int = Field(4000, ge=16, description="cap on points stored per object node")
    outlier_quantile: float = Field(0.02, ge=0.0, lt=0.5,
                                    description="3D box from these point quantiles (robust to mask bleed)")
    depth_band: float = Field(1.0, gt=0.0, description="keep mask points within this depth (m) of the "
                              "mask's median depth (drops background seen through the mask)")
    min_score: float = Field(0.0, ge=0.0, le=1.0, description="ignore detections scoring below this")

    # Merging, eq. (4)
    lambda_1: float = Field(0.5, ge=0.0, description="weight of geometric similarity s_g (3D IoU)")
    lambda_2: float = Field(0.5, ge=0.0, description="weight of semantic similarity s_s")
    tau: float = Field(0.6, ge=0.0, le=1.0, description="merge threshold on s = l1 s_g + l2 s_s")
    box_padding: float = Field(0.05, ge=0.0, description="pad 3D boxes by this (m) per side before IoU, "
                               "so thin or partially seen surfaces can overlap")
    geometric: Literal["iou", "overlap"] = Field(
        "overlap", description="s_g: 'iou' (paper) or 'overlap' = intersection / smaller volume")
    node_geometry: Literal["majority_label", "all"] = Field(
        "majority_label", description="a node's points and box: its majority label's observations "
        "(a one-frame spurious box of another label merged by eq. 4 does not stretch it) or 'all' "
        "of them (eq. 3's P_j)")
    merge_nodes: bool = Field(True, description="node-node merging as views accumulate")
    update_objects_every_frame: bool = Field(
        False, description="also fold non-anchor frames into object nodes (paper: anchors only)")

    # Pruning, eqs. (5)-(7)
    prune: bool = Field(True, description="let the memory actor prune anchors periodically "
                        "(CognitiveMemoryGraph.prune() itself always prunes when called)")
    r: int = Field(2, ge=1, description="required coverage r in r_j = min(r, deg(o_j))")
    anchor_cost: Literal["unit", "quality"] = Field(
        "unit", description="c_i: 1 for every anchor, or 1 + quality_weight * (1 - image quality)")
    quality_weight: float = Field(1.0, ge=0.0)
    prune_time_limit_s: float = Field(0.5, gt=0.0, le=MAX_DURATION_S, description="HiGHS time limit of one pruning")
    keep_latest_anchor: bool = Field(True, description="never prune the newest anchor")
    keep_far_evidence: bool = Field(True, description="each label seen only beyond max_depth is an "
                                    "extra element to cover once, so pruning keeps that evidence")

    # Subgraphs, eqs. (8)-(11)
    k: int = Field(5, ge=1, description="max anchors per subgraph")
    label_match_threshold: float = Field(0.8, ge=0.0, le=1.0,
                                         description="object label matches a task word at this similarity")
    far_evidence_weight: float = Field(0.5, ge=0.0, description="weight of labels_seen-only labels in "
                                       "S(G_k) (0 = paper's eq. 11 exactly)")

    embedder: str = Field("minilm", description="registered embedder for label features")
