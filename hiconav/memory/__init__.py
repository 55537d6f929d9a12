"""The cognitive memory graph (paper section "Online Memory Construction").

Anchors (visual keyframes, eq. 2), object nodes merged by eq. (4), anchor pruning by the weighted
set multicover ILP of eqs. (5)-(7), immutable snapshots for the other actors, and the subgraph
decomposition of eqs. (8)-(11) that the reasoner sends to a VLM. Pure and synchronous.
"""

from hiconav.memory.anchors import AnchorGate, GateDecision, KeyframeSchedule
from hiconav.memory.config import MemoryConfig
from hiconav.memory.graph import CognitiveMemoryGraph, MemoryUpdate, PruneResult
from hiconav.memory.setcover import (
    SetCoverError,
    SetCoverInstance,
    SetCoverResult,
    greedy_multicover,
    multicover_requirements,
    read_orlib,
    solve_multicover,
)
from hiconav.memory.snapshot import AnchorView, MemorySnapshot, ObjectView
from hiconav.memory.subgraphs import Subgraph, decompose, task_similarity

__all__ = [
    "AnchorGate",
    "AnchorView",
    "CognitiveMemoryGraph",
    "GateDecision",
    "KeyframeSchedule",
    "MemoryConfig",
    "MemorySnapshot",
    "MemoryUpdate",
    "ObjectView",
    "PruneResult",
    "SetCoverError",
    "SetCoverInstance",
    "SetCoverResult",
    "Subgraph",
    "decompose",
    "greedy_multicover",
    "multicover_requirements",
    "read_orlib",
    "solve_multicover",
    "task_similarity",
]
