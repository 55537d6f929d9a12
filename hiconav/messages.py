"""Messages between the actors of one mission (frozen dataclasses, read-only arrays).

Every message is immutable so that it can cross threads (pykka mailboxes) without copies or
locks; arrays inside are frozen by the types they wrap (``Frame``, ``Detection``, ``Frontier``,
the memory snapshot) or here. Payloads owned by other layers (grid snapshot, memory snapshot,
exploration plan, target hypothesis) are typed ``Any`` so that this module imports only
``hiconav.types``. This module defines data only: no behaviour, no threads.

Flow (see ARCHITECTURE.md)::

    Driver --FrameMsg--> Perception --Observation--> Memory --WorldSnapshot--> Exploration,
    Reasoning, Mission, Control; Exploration --PlanMsg--> Mission; Reasoning --HypothesisMsg-->
    Mission, Memory; Mission --GoalMsg/StopRequest--> Control --CommandMsg--> Driver.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from hiconav.types import Detection, DiscreteAction, Frame, Frontier, Goal, Pose2D, TaskSpec, VelocityCommand


@dataclass(frozen=True)
class Tick:
    """A rate tick for one actor at clock time ``stamp`` (s, wall or virtual)."""

    stamp: float


@dataclass(frozen=True)
class FrameMsg:
    """Driver -> Perception: the newest sensor frame (latest-wins)."""

    frame: Frame
    steps: int = 0


@dataclass(frozen=True)
class Observation:
    """Perception -> Memory: a frame with its detections (latest-wins)."""

    frame: Frame
    detections: tuple[Detection, ...]
    stamp: float
    detector: str = "unknown"


@dataclass(frozen=True)
class WorldSnapshot:
    """Memory -> Exploration, Reasoning, Mission, Control: the world as integrated so far.

    ``grid``: the occupancy grid's read-only snapshot (``hiconav.mapping`` GridSnapshot);
    ``memory``: the cognitive memory graph's ``MemorySnapshot`` (None before the first update);
    ``pose``: the robot pose of the last integrated frame. Latest-wins everywhere.
    """

    seq: int
    stamp: float
    pose: Pose2D
    grid: Any
    memory: Any = None
    frame_seq: int = 0


@dataclass(frozen=True)
class ParseRequest:
    """Mission -> Reasoning: decompose this instruction into a TaskSpec."""

    instruction: str
    stamp: float = 0.0


@dataclass(frozen=True)
class TaskMsg:
    """Reasoning -> Mission (and Mission -> Exploration/Reasoning/Memory): the task to pursue."""

    task: TaskSpec
    stamp: float = 0.0


@dataclass(frozen=True)
class PlanMsg:
    """Exploration -> Mission: frontiers and the WTRP order; ``plan`` is an ``ExplorationPlan``."""

    plan: Any
    frontiers: tuple[Frontier, ...]
    stamp: float
    snapshot_seq: int = 0


@dataclass(frozen=True)
class RuledOut:
    """Reasoning -> Exploration: the object nodes of the target's category that the reasoning
    layer judged not to be the described instance (a relation of the instruction fails on them),
    the whole current set (latest wins); exploration stops treating them as target evidence.
    ``withdrawn``: the offers (hypotheses) the reasoning layer has taken back for good
    (``hiconav.reasoning.unresolved.withdrawn_offers``); the mission stops pursuing them."""

    object_ids: frozenset[int]
    stamp: float = 0.0
    withdrawn: frozenset[int] = frozenset()


@dataclass(frozen=True)
class KeyframeRequest:
    """Mission -> Memory: make the frames up to clock time ``until`` visual anchors, one at least
    every ``every_s`` seconds. Verification judges a candidate on anchors (keyframes); a robot that
    stands and glances at it moves less than delta_d and turns less than delta_theta from its last
    anchor, so the gate of eq. 2 alone makes none and the verdict waits for frames that only a
    newly detected object (often a spurious one) would make."""

    until: float
    every_s: float = 0.0
    stamp: float = 0.0


@dataclass(frozen=True)
class ExploredOut:
    """Mission -> Reasoning: the search has no frontier left and no confirmed target; the
    reasoning layer answers with a ``HypothesisMsg`` of its best unresolved candidate of a
    described instance (``hiconav.reasoning.unresolved``), or with nothing when none is left."""

    stamp: float = 0.0


@dataclass(frozen=True)
class HypothesisMsg:
    """Reasoning -> Mission, Memory: a ``TargetHypothesis`` (None: the subgraph held no target).

    ``stamp`` is when the reply became visible (request time + latency, virtual or wall).
    """

    hypothesis: Any
    stamp: float
    requested: float = 0.0
    prompt: str = ""
    reply: str = ""
    subgraph_kind: str = ""


@dataclass(frozen=True)
class GoalMsg:
    """Mission -> Control: navigate to ``goal`` (None cancels). ``seq`` identifies the request;
    ``source`` names what sent it (the mission tree's behaviour class, e.g. "Explore"), so that
    the control layer can say which decision its actions served."""

    seq: int
    goal: Goal | None
    stamp: float = 0.0
    source: str = ""


@dataclass(frozen=True)
class NavStatus:
    """Control -> Mission: progress on goal ``goal_seq``: "idle" | "active" | "reached" | "failed"."""

    goal_seq: int
    state: str
    stamp: float
    distance: float | None = None


@dataclass(frozen=True)
class ReasoningBusy:
    """Reasoning -> Control (sync_reasoning only): a call is in flight until ``until`` (clock s);
    the blocking design holds the robot still until then."""

    until: float
    stamp: float = 0.0


@dataclass(frozen=True)
class StopRequest:
    """Mission -> Control: end the episode with the STOP action (the robot believes it arrived)."""

    reason: str
    stamp: float = 0.0


@dataclass(frozen=True)
class CommandMsg:
    """Control -> Driver: one discrete action or a body velocity (latest-wins); ``source``: the
    behaviour whose goal it serves ("" when none is named)."""

    seq: int
    stamp: float
    action: DiscreteAction | None = None
    velocity: VelocityCommand | None = None
    source: str = ""


@dataclass(frozen=True)
class EmergencyStop:
    """Runtime -> Driver: zero the command now (an actor failed or the mission was aborted)."""

    reason: str
    stamp: float = 0.0


@dataclass(frozen=True)
class EpisodeEnded:
    """Driver -> Mission/runtime: the episode is over ("stop", "max_steps", "emergency")."""

    reason: str
    steps: int
    stamp: float


@dataclass(frozen=True)
class MissionFinished:
    """Mission -> runtime: the tree finished with ``status`` ("SUCCESS" | "FAILURE")."""

    status: str
    stamp: float
    feedback: str = ""


@dataclass(frozen=True)
class ActorFailed:
    """Any actor -> runtime: ``actor`` raised ``error``; the runtime stops the robot and reports it."""

    actor: str
    error: str
    stamp: float = 0.0


@dataclass(frozen=True)
class TargetRejected:
    """Mission -> Reasoning, Exploration: verification rejected this object node (a false
    positive: search on), for good (``permanent``) or deferred for a while; ``out_of_reach``:
    deferred only because no view point or approach cell of it could be reached. Exploration
    draws the search toward a node out of reach (``exploration.utility.reach_sigma``) and, with
    ``exploration.utility.exclude_rejected``, leaves one rejected for good out of S_struct."""

    object_id: int
    reason: str
    stamp: float = 0.0
    permanent: bool = False
    out_of_reach: bool = False


@dataclass(frozen=True)
class HealthAlert:
    """Monitor actor -> Mission: something the mission tree must react to (e.g. "battery")."""

    kind: str
    text: str
    stamp: float = 0.0


@dataclass(frozen=True)
class TreeStatus:
    """Mission -> recorder: the tree's status after one tick (for Rerun and the report)."""

    tick: int
    stamp: float
    status: str
    tip: str
    ascii: str = ""


@dataclass(frozen=True)
class ActorStats:
    """Per-actor counters for the report: ticks run, messages handled, stale ones dropped."""

    actor: str
    ticks: int
    handled: int
    dropped: dict[str, int] = field(default_factory=dict)
    busy_s: float = 0.0
