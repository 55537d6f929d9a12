"""One mission end to end: assemble the layers for a house and an episode, run them, score them.

``build_mission`` loads nothing itself: given a house and an episode it creates the simulator,
the detector (oracle, labelled), the embedder, the occupancy grid and frontier tracker, the
cognitive memory graph, the exploration planner, the reasoner (offline unless a VLM endpoint is
configured) and the navigator, wraps each in its actor node (``hiconav.actors``) and returns them
in start order. ``run_episode`` runs one episode on the stepped (virtual) clock and returns an
``EpisodeRecord`` (the entry point of ``hiconav eval``); ``run_mission`` does the same on either
clock and can write a Rerun recording; ``run_command`` is ``hiconav run``.

With ``robot=`` (``hiconav run --driver mavlink``) the driver actor drives a real-time robot
behind ``drivers.adapters.SimulatorFacade`` instead of the simulator; the mission then runs on
the real-time clock only, and is scored from the house's ground truth at the robot's reported
pose (the simulated vehicle runs the same house).

This module only wires and scores: every algorithm lives in its layer. It imports the actor
package (and so pykka) lazily, inside the functions, so that importing ``hiconav`` stays pure.
Stand-ins are labelled wherever they show: the detector's name ("oracle" for the simulator's
ground truth) and the reasoner ("offline" without a VLM) are part of every result.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from hiconav.errors import ConfigError
from hiconav.limits import MAX_DURATION_S, MAX_RATE_HZ
from hiconav.settings import _merge, nest
from hiconav.types import Pose2D

log = logging.getLogger(__name__)


def typer_option(default: Any, *names: str, help: str = "") -> Any:
    """``typer.Option`` imported lazily (typer is only needed by the CLI)."""
    import typer

    return typer.Option(default, *names, help=help)


class RatesConfig(BaseModel):
    """Actor rates in Hz (virtual Hz in stepped mode)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    driver: float = Field(10.0, gt=0, le=MAX_RATE_HZ)
    perception: float = Field(10.0, gt=0, le=MAX_RATE_HZ)
    memory: float = Field(10.0, gt=0, le=MAX_RATE_HZ)
    reasoning: float = Field(10.0, gt=0, le=MAX_RATE_HZ)
    exploration: float = Field(2.0, gt=0, le=MAX_RATE_HZ)
    mission: float = Field(10.0, gt=0, le=MAX_RATE_HZ)
    control: float = Field(10.0, gt=0, le=MAX_RATE_HZ)


class MissionConfig(BaseModel):
    """mission.*: the tree, the clock, the rates and the mission's own switches."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    tree: str = "objectnav"
    clock: str = Field("stepped", pattern="^(stepped|real)$")
    rates: RatesConfig = Field(default_factory=RatesConfig)
    verify: bool = True
    use_memory_labels: bool = True  # candidates from memory labels as well as from hypotheses
    # a candidate deferred for a label flip is due again after this many new observations under a
    # target label (0: only when its deferral time runs out)
    requalify_observations: int = Field(3, ge=0)
    # a candidate deferred for want of a reachable view or approach cell is due again once the known
    # free floor within 2 m of it has grown by this much (0: only when its deferral time runs out)
    remap_area_m2: float = Field(1.0, ge=0)
    # the reasoning layer verifies subgraphs (False, the no_reasoning ablation: memory label
    # matches alone propose candidates, also for a described instance)
    reasoning: bool = True
    # the robot holds still while a reasoning call is in flight (the sync_reasoning ablation: the
    # blocking design the paper argues against)
    sync_reasoning: bool = False
    # stepped: a reply becomes visible after this, overriding reasoning.latency_s (None: the model
    # reasoning.latency_s +- reasoning.latency_jitter_s)
    vlm_latency_s: float | None = Field(None, ge=0, le=MAX_DURATION_S)
    parse_latency_s: float | None = Field(None, ge=0, le=MAX_DURATION_S)
    # stepped: reasoning.latency_s is robot time ("robot": a call spans as many discrete actions as
    # a real robot makes in that time, ACTION_SECONDS each) or clock seconds ("clock": one action
    # per driver tick, so at 10 Hz a 2 s call spans 20 actions, 5 m of driving)
    latency_time: Literal["robot", "clock"] = "robot"
    max_time_s: float = Field(600.0, gt=0, le=MAX_DURATION_S)  # clock seconds before the run is cut off
    prune_every: int = Field(20, ge=0)  # ILP anchor pruning every n integrations (0: never)
    control_mode: str = Field("discrete", pattern="^(discrete|velocity)$")
    # user actors by import path "package.module:NodeClass" -> keyword arguments; each is a
    # hiconav.actors.Node subclass (e.g. "hiconav.actors.monitor:BatteryMonitorNode": {"capacity_s": 300})
    extra_actors: dict[str, dict[str, Any]] = Field(default_factory=dict)


class LatencyModel:
    """A reasoning call's modelled latency on the stepped clock: ``base`` +- ``jitter`` seconds of
    robot time, uniform, from a generator seeded per mission (``float(model)`` draws the next
    call's), times ``scale``: the stepped clock's seconds per second of robot time."""

    def __init__(self, base: float, jitter: float, seed: int, scale: float = 1.0) -> None:
        import numpy as np

        self.base, self.jitter = float(base), min(float(jitter), float(base))
        self.scale = float(scale)
        self._rng = np.random.default_rng([int(seed), 0x5EA5])

    def __float__(self) -> float:
        if self.jitter <= 0:
            return self.base * self.scale
        return float(self.base + self._rng.uniform(-self.jitter, self.jitter)) * self.scale


def stepped_time_scale(rates: Any, control_mode: str) -> float:
    """Stepped-clock seconds per second of robot time: one driver tick (``1 / rates.driver`` clock
    seconds) carries one discrete action, which takes a robot ``ACTION_SECONDS`` (a 0.25 m step at
    0.5 m/s, a 30 degree turn), or, in velocity mode, ``1 / rates.control`` seconds of motion."""
    from hiconav.sim.simulator import ACTION_SECONDS

    robot_s = ACTION_SECONDS if control_mode == "discrete" else 1.0 / float(rates.control)
    return (1.0 / float(rates.driver)) / robot_s


def area_config(cls: type[BaseModel], overrides: dict[str, Any], area: str) -> BaseModel:
    """``cls`` defaults with the ``area.*`` overrides applied; errors name the settings path."""
    nested = nest(overrides).get(area, {})
    try:
        return cls.model_validate(_merge(cls().model_dump(), nested))
    except Exception as exc:  # pydantic.ValidationError
        raise ConfigError(f"invalid {area} settings: {exc}", field=area) from exc


# ------------------------------------------------------------------------------------- assembly
@dataclass
class MissionParts:
    """The nodes of one mission (start order) and what is needed to score it."""

    nodes: list[Any]
    sim: Any
    driver: Any
    mission: Any
    reasoning: Any
    detector_name: str
    reasoner_name: str
    fallbacks: list[str] = field(default_factory=list)
    control: Any = None  # the ControlNode (its ``actions`` tally)


def build_mission(house: Any, start: Pose2D, instruction: str, *, seed: int = 0,
                  overrides: dict[str, Any] | None = None, tree: str | Path | None = None,
                  clock: str | None = None, embedder: Any = None, sim_config: Any = None,
                  record: str | Path | None = None, spawn: bool = False, robot: Any = None) -> MissionParts:
    """Create the simulator and every layer for one mission; nodes are returned in start order.

    ``robot``: a simulator-shaped real-time robot (``drivers.adapters.SimulatorFacade``) that the
    driver actor drives instead of a new ``Simulator`` (real-time clock only).
    """
    from hiconav.decisions.config import DecisionsConfig
    from hiconav.actors.control import ControlNode
    from hiconav.actors.driver import DriverNode
    from hiconav.actors.exploration import ExplorationNode
    from hiconav.actors.memory import MemoryNode
    from hiconav.actors.mission import MissionNode
    from hiconav.actors.perception import PerceptionNode
    from hiconav.actors.reasoning import ReasoningNode
    from hiconav.mapping import FrontierTracker, MappingConfig, OccupancyGrid, PoseGate
    from hiconav.planning import Navigator
    from hiconav.planning.config import NavigatorConfig
    from hiconav.sim import SimConfig, Simulator

    overrides = dict(overrides or {})
    cfg: MissionConfig = area_config(MissionConfig, overrides, "mission")  # type: ignore[assignment]
    clock = clock or cfg.clock
    stepped = clock == "stepped"
    fallbacks: list[str] = []
    sim_cfg = sim_config or area_config(SimConfig, overrides, "sim")
    if robot is not None and stepped:
        raise ConfigError("a live robot runs on the real-time clock: the stepped (virtual) clock cannot "
                          "pause a vehicle between actor ticks; use --clock real", field="mission.clock")
    sim = robot if robot is not None else Simulator(house, sim_cfg, seed=seed)
    # durations stated in robot time (reasoning latency, decisions.*, reasoning.marginal_patience_s)
    # on the mission's clock: one to one on a robot; on the simulator (either clock) a driver tick
    # carries a whole discrete action
    time_scale = 1.0 if robot is not None else stepped_time_scale(cfg.rates, cfg.control_mode)

    # perception -------------------------------------------------------------------------------
    from hiconav.perception.config import PerceptionConfig
    from hiconav.perception.factory import build_detector, build_embedder

    perception_cfg: Any = area_config(PerceptionConfig, overrides, "perception")
    detector = build_detector(perception_cfg, instance_categories=house.instance_categories, seed=seed)
    if embedder is None:
        embedder = build_embedder(perception_cfg)
    similarity = embedder.similarity

    # memory -----------------------------------------------------------------------------------
    mapping_cfg = area_config(MappingConfig, overrides, "mapping")
    grid = OccupancyGrid(mapping_cfg.occupancy)  # type: ignore[attr-defined]
    tracker = FrontierTracker(mapping_cfg.frontiers)  # type: ignore[attr-defined]
    from hiconav.exploration import ExplorationPlanner
    from hiconav.exploration.config import ExplorationConfig
    from hiconav.memory import CognitiveMemoryGraph, decompose
    from hiconav.memory.config import MemoryConfig
    from hiconav.reasoning.reasoner import Reasoner

    mem_cfg: Any = area_config(MemoryConfig, overrides, "memory")
    prune_every = cfg.prune_every if mem_cfg.prune else 0
    cmg = CognitiveMemoryGraph(mem_cfg, embedder=embedder)

    # exploration ------------------------------------------------------------------------------
    planner = ExplorationPlanner(area_config(ExplorationConfig, overrides, "exploration"), deterministic=stepped)

    # reasoning --------------------------------------------------------------------------------
    from hiconav.reasoning.config import ReasoningConfig
    from hiconav.reasoning.decompose import decompose_instruction

    r_cfg: Any = area_config(ReasoningConfig, overrides, "reasoning")
    use_vlm = r_cfg.use_vlm()
    verifier = None
    if use_vlm:
        from hiconav.reasoning.verifier import VLMVerifier
        from hiconav.reasoning.vlm_client import VLMClient

        verifier = VLMVerifier(VLMClient(r_cfg.vlm), r_cfg)
    else:
        from hiconav.reasoning.verifier import OfflineVerifier

        verifier = OfflineVerifier(r_cfg, similarity)

    def parse(text: str) -> Any:
        return decompose_instruction(text, r_cfg, similarity=similarity)

    vlm_latency: Any = cfg.vlm_latency_s
    parse_latency: Any = cfg.parse_latency_s
    if stepped:
        # Every reasoning call takes the modelled latency on the stepped clock, offline or VLM: the
        # wall time of local computation depends on the machine's load (a first MiniLM encode
        # takes 0.1-1 s) and would make same-seed runs differ, and a real VLM's would make them
        # depend on the network. Seeded jitter, one draw per call.
        # The model is in robot time: a 2 s call lasts as long as 4 discrete actions of a robot at
        # 0.5 m/s, whatever the stepped clock's tick (``mission.latency_time: clock`` takes it
        # in clock seconds instead, 20 actions at the default 10 Hz)
        scale = time_scale if cfg.latency_time == "robot" else 1.0
        model = LatencyModel(r_cfg.latency_s, r_cfg.latency_jitter_s, seed, scale)
        vlm_latency = model if vlm_latency is None else vlm_latency
        parse_latency = model if parse_latency is None else parse_latency
    rates = cfg.rates
    nav_cfg = area_config(NavigatorConfig, overrides, "planning")
    driver = DriverNode(sim, start, rate_hz=rates.driver, max_steps=sim_cfg.max_steps,
                        velocity_dt=1.0 / rates.control, lockstep=robot is not None,
                        stream=not stepped)
    perception = PerceptionNode(detector, rate_hz=rates.perception)
    memory = MemoryNode(grid, cmg, rate_hz=rates.memory, prune_every=prune_every,
                        pose_gate=PoseGate(mapping_cfg.pose_gate))  # type: ignore[attr-defined]
    reasoning = ReasoningNode(parse=parse, make_reasoner=lambda task: Reasoner(task, r_cfg),
                              verifier=verifier if cfg.reasoning else None, decompose=decompose,
                              similarity=similarity, k=r_cfg.k,
                              rate_hz=rates.reasoning, stepped=stepped, latency_s=vlm_latency,
                              parse_latency_s=parse_latency, sync=cfg.sync_reasoning,
                              marginal_patience_s=r_cfg.marginal_patience_s * time_scale)
    exploration = ExplorationNode(tracker, planner, rate_hz=rates.exploration, similarity=similarity)
    control = ControlNode(Navigator(nav_cfg), rate_hz=rates.control, mode=cfg.control_mode,
                          velocity_dt=1.0 / rates.control, hold_while_reasoning=cfg.sync_reasoning)
    mission = MissionNode(tree or cfg.tree, instruction, rate_hz=rates.mission,
                          success_distance=sim_cfg.success_distance, verify=cfg.verify,
                          use_memory_labels=cfg.use_memory_labels, reasoning=cfg.reasoning,
                          requalify_observations=cfg.requalify_observations,
                          remap_area_m2=cfg.remap_area_m2,
                          decisions=area_config(DecisionsConfig, overrides, "decisions"),  # type: ignore[arg-type]
                          time_scale=time_scale,
                          record_tree=record is not None or spawn)
    nodes = [driver, perception, memory, reasoning, exploration, control, mission]
    for path, kwargs in cfg.extra_actors.items():
        from hiconav.actors.node import Node
        from hiconav.registry import Registry

        cls = Registry("actor").get(path, field=f"mission.extra_actors.{path}")
        if not (isinstance(cls, type) and issubclass(cls, Node)):
            raise ConfigError(f"{path} is not a hiconav.actors.Node subclass", field=f"mission.extra_actors.{path}")
        try:
            extra = cls(**kwargs)
        except TypeError as exc:
            raise ConfigError(f"cannot create {path}: {exc}", field=f"mission.extra_actors.{path}") from exc
        nodes.append(extra)
        driver.frame_to = (*driver.frame_to, extra.name)  # user actors see the robot's frames
    if record is not None or spawn:
        from hiconav.actors.recording import RecorderNode

        nodes.insert(0, RecorderNode(record, spawn=spawn, rate_hz=rates.driver))
    return MissionParts(nodes, sim, driver, mission, reasoning, getattr(detector, "name", "oracle"),
                        "vlm" if use_vlm else "offline", fallbacks, control)


# ------------------------------------------------------------------------------------- running
@dataclass
class MissionResult:
    """Outcome of one mission: metrics, how it ended, timings and the per-actor counters."""

    metrics: Any  # hiconav.sim.metrics.EpisodeMetrics
    termination: str
    mission_status: str
    failure: str | None
    clock: str
    clock_s: float
    wall_s: float
    detector: str
    reasoner: str
    fallbacks: list[str]
    stats: dict[str, Any]
    trajectory: Any
    tree_history: list[Any]
    reasoning_events: list[dict[str, Any]]
    report: Any = None
    pauses: list[dict[str, Any]] = field(default_factory=list)  # failsafe pauses of a live robot
    driver: str = "sim"
    mission_feedback: str = ""  # the tree's last words, e.g. "Approach: no reachable approach cell"
    # discrete actions per behaviour whose goal they served ({"Explore": {"turns", "forward",
    # "other"}}; ``ControlNode.actions``); None under velocity control, where steps are control ticks
    actions_by_behaviour: dict[str, dict[str, int]] | None = None
    # the path beyond the shortest by the behaviour each step served (``metrics.excess_by_source``;
    # the simulator's ground truth), None on a robot
    excess_path: dict[str, Any] | None = None

    def summary(self) -> dict[str, Any]:
        m = self.metrics
        out = {"success": bool(m.success), "spl": round(float(m.spl), 4), "steps": int(m.steps),
                "dts": round(float(m.dts), 3), "path_length": round(float(m.path_length), 3),
                "termination": self.termination, "mission": self.mission_status, "clock": self.clock,
                "clock_s": round(self.clock_s, 2), "wall_s": round(self.wall_s, 2), "detector": self.detector,
                "reasoner": self.reasoner, "failure": self.failure, "fallbacks": self.fallbacks}
        if self.driver != "sim":
            out.update({"driver": self.driver, "pauses": self.pauses})
        return out


def _termination(report: Any, parts: MissionParts) -> str:
    if report.reason == "actor_failed":
        return "error"
    ended = parts.driver.ended
    if ended is not None and ended.reason == "stop":
        return "stop"
    if ended is not None and ended.reason == "max_steps":
        return "step_limit"
    finished = parts.mission.finished
    if finished is not None and finished.status == "FAILURE":
        return "no_frontier" if "frontier" in finished.feedback else "stuck"
    return "stuck"


def run_mission(house: Any, episode: Any, *, seed: int = 0, overrides: dict[str, Any] | None = None,
                tree: str | Path | None = None, clock: str | None = None, instruction: str | None = None,
                record: str | Path | None = None, spawn: bool = False, embedder: Any = None,
                robot: Any = None) -> MissionResult:
    """Run one episode (``hiconav.sim.episodes.Episode``) on the chosen clock and score it.

    ``robot``: a connected ``drivers.adapters.SimulatorFacade`` (e.g. over MAVLink) driven instead
    of the simulator, on the real-time clock; ``episode.start`` should be the robot's pose. The
    metrics then come from ``house``'s ground truth at the robot's reported pose. The robot is
    closed (zero setpoint, link released) when the run ends, also on Ctrl-C.
    """
    from hiconav.actors import TICK_ORDER, RealtimeRuntime, SteppedRuntime
    from hiconav.sim.metrics import EpisodeTracker

    overrides = dict(overrides or {})
    cfg: MissionConfig = area_config(MissionConfig, overrides, "mission")  # type: ignore[assignment]
    clock = clock or ("real" if robot is not None else cfg.clock)
    text = instruction or episode.instruction
    try:
        parts = build_mission(house, episode.start, text, seed=seed, overrides=overrides, tree=tree, clock=clock,
                              embedder=embedder, record=record, spawn=spawn, robot=robot)
    except BaseException:
        if robot is not None:
            robot.close()
        raise
    for note in parts.fallbacks:
        log.warning("FALLBACK %s", note)
    if robot is None:
        tracker: Any = EpisodeTracker(parts.sim, episode)
    else:
        tracker = _RobotTracker(house, episode, robot, area_config(_sim_config_cls(), overrides, "sim"))
    if clock == "stepped":
        runtime: Any = SteppedRuntime(parts.nodes, tick_order=TICK_ORDER)
    else:
        runtime = RealtimeRuntime(parts.nodes)
    if robot is None:
        report = runtime.run(max_time=cfg.max_time_s)
    else:
        report = _run_robot(runtime, robot, cfg.max_time_s)
    metrics = tracker.finish()
    mission_status = parts.mission.finished.status if parts.mission.finished else "RUNNING"
    failure = None if report.failure is None else f"{report.failure.actor}: {report.failure.error}"
    result = MissionResult(metrics, _termination(report, parts), mission_status, failure, clock, report.clock_s,
                           report.wall_s, parts.detector_name, parts.reasoner_name, parts.fallbacks,
                           {k: v for k, v in report.stats.items()}, parts.driver.path, parts.mission.history,
                           parts.reasoning.events, report,
                           mission_feedback=parts.mission.finished.feedback if parts.mission.finished else "")
    control = parts.control
    if control is not None and getattr(control, "mode", "") == "discrete":
        result.actions_by_behaviour = {k: dict(v) for k, v in control.actions.items()}
    if robot is None:
        result.excess_path = _excess_path(result.trajectory, getattr(parts.driver, "sources", ()), tracker)
    else:
        result.pauses = list(getattr(parts.driver, "pauses", []))
        result.driver = str(getattr(robot, "name", "robot"))
    try:
        parts.sim.close()
    except Exception:  # closing the renderer must not hide the result
        pass
    return result


def _excess_path(trajectory: Any, sources: Any, tracker: Any) -> dict[str, Any] | None:
    """``metrics.excess_by_source`` over the driver's ``trajectory`` ((N + 1, 3), the result's) and
    the behaviours its commands served (``sources``), measured by the episode's ``tracker`` (None
    when the two do not line up)."""
    from hiconav.sim.metrics import excess_by_source

    sources = list(sources)
    xy = trajectory[:, :2]
    if len(xy) != len(sources) + 1:
        return None
    success_distance = float(tracker.sim.config.success_distance)
    return excess_by_source(xy, sources, lambda p: tracker.goal.to_success(p, success_distance))


def _sim_config_cls() -> type[BaseModel]:
    from hiconav.sim import SimConfig

    return SimConfig


class _RobotTracker:
    """Scores a mission driven on a real-time robot from the house's ground truth at the pose
    the robot reports (success: STOP called within ``success_distance`` geodesic m of a goal)."""

    def __init__(self, house: Any, episode: Any, robot: Any, sim_cfg: Any) -> None:
        from hiconav.sim.geodesic import GoalDistance

        self.episode = episode
        self.robot = robot
        self.config = sim_cfg
        self.goal = GoalDistance(house, episode, radius=sim_cfg.robot_radius)
        self.shortest_to_success = self.goal.to_success(episode.start.xy, sim_cfg.success_distance)

    def finish(self) -> Any:
        from hiconav.sim.metrics import episode_metrics

        r = self.robot
        return episode_metrics(self.episode, final_distance=self.goal.distance(r.pose.xy),
                               path_length=float(r.path_length), steps=int(r.steps), stopped=bool(r.stopped),
                               collisions=0, shortest_to_success=self.shortest_to_success,
                               config=self.config,
                               final_to_success=self.goal.to_success(r.pose.xy, self.config.success_distance))


def _run_robot(runtime: Any, robot: Any, max_time: float) -> Any:
    """``runtime.run`` for a live robot: on Ctrl-C send a zero setpoint, stop every actor, re-raise.

    (The MAVLink driver's own SIGINT hook has already sent zero; this repeats it and makes sure
    no actor thread keeps commanding the robot.)
    """
    try:
        return runtime.run(max_time=max_time)
    except KeyboardInterrupt:
        try:
            robot.stop()
        finally:
            for ref in reversed(list(getattr(runtime, "refs", {}).values())):
                try:
                    ref.stop(block=True, timeout=5.0)
                except Exception:  # already dead or stuck: the robot is stopped either way
                    pass
            robot.close()
        raise


def run_episode(spec: Any, overrides: dict[str, Any] | None = None, seed: int = 0) -> Any:
    """``hiconav eval``'s episode runner: one ``EpisodeSpec`` on the stepped clock -> ``EpisodeRecord``."""
    from hiconav.eval.records import EpisodeRecord
    from hiconav.eval.taxonomy import last_progress_step
    from hiconav.sim import load_house
    from hiconav.sim.episodes import Episode, instruction_for

    house = load_house(spec.house)
    if house.success_rule == "semexp":
        # a finite SemExp distance may run through its 2-cell dilation of the navmesh alone, where
        # the robot cannot drive: the dry run's check, so that a run records what it would count
        from hiconav.errors import DataError
        from hiconav.eval.sources import validate_spec

        error = validate_spec(spec)
        if error:
            raise DataError(error, field="start")
    start = Pose2D(*map(float, spec.start))
    episode = Episode(spec.episode_id, house.name, start, spec.target, tuple(spec.goal_instance_ids),
                      float(spec.geodesic_distance), spec.instruction or instruction_for(spec.target),
                      task=getattr(spec, "task", "objectnav"))
    wall0 = time.perf_counter()
    result = run_mission(house, episode, seed=seed, overrides=overrides, clock="stepped")
    m = result.metrics
    positions = result.trajectory[:, :2] if len(result.trajectory) else result.trajectory.reshape(0, 2)
    sim_cfg: Any = area_config(_sim_config_cls(), dict(overrides or {}), "sim")
    semexp = None
    if house.success_rule == "semexp":  # published Gibson tables' SPL, beside ours (docs/evaluation.md)
        from hiconav.eval.summary import semexp_code_spl

        semexp = semexp_code_spl(bool(m.success), float(m.shortest_to_success), float(sim_cfg.success_distance),
                                 float(m.path_length))
    return EpisodeRecord(
        episode_id=spec.episode_id, house=spec.house, target=spec.target, seed=seed, success=bool(m.success),
        spl=float(m.spl), dts=float(m.dts) if math.isfinite(m.dts) else math.inf, steps=int(m.steps),
        max_steps=int(sim_cfg.max_steps),
        path_length=float(m.path_length), geodesic_distance=float(spec.geodesic_distance),
        termination=result.termination, last_progress_step=last_progress_step(positions),
        task_time_s=float(result.clock_s), wall_time_s=time.perf_counter() - wall0,
        layer_time_s={k: float(v.busy_s) for k, v in result.stats.items()},
        layer_frames={k: int(v.ticks) for k, v in result.stats.items()},
        vlm_calls=int(sum(1 for e in result.reasoning_events if e["kind"] == "verify" and e["source"] == "vlm")),
        detector=result.detector, reasoner=result.reasoner, error=result.failure,
        error_kind="runtime" if result.failure else None,
        extra={"mission": result.mission_status, "fallbacks": result.fallbacks,
               "reasoning_calls": int(sum(1 for e in result.reasoning_events
                                          if e["kind"] == "verify" or (e["kind"] == "unresolved" and e["found"]))),
               "feedback": result.mission_feedback,
               "shortest_to_success": float(m.shortest_to_success),  # SPL's l (docs/evaluation.md)
               "spl_semexp": semexp,  # SemExp's own code's SPL on its maps (Gibson), else None
               "turns": m.turns,  # of the steps, discrete turns in place (None: velocity control)
               # the actions per behaviour whose goal they served (None: velocity control)
               "actions_by_behaviour": result.actions_by_behaviour,
               # the path beyond the shortest by behaviour (ground truth; None: not measured)
               "excess_path": result.excess_path,
               "goal_in_view": None if m.steps_to_view is None else {
                   "steps": int(m.steps_to_view), "path_m": float(m.path_to_view),
                   "to_success_m": None if m.view_to_success is None or not math.isfinite(m.view_to_success)
                   else float(m.view_to_success)},
               "dropped": {k: dict(v.dropped) for k, v in result.stats.items() if v.dropped}})


# ------------------------------------------------------------------------------------- hiconav run
def connect_robot(house: Any, episode: Any, profile: Any, url: str | None,
                  overrides: dict[str, Any] | None = None, *, handle_signals: bool = True) -> tuple[Any, Any]:
    """Connect and engage a MAVLink robot for ``hiconav run --driver mavlink``.

    ``profile``: a ``RobotProfile``, a profile name or a YAML path; ``url`` overrides its
    ``mavlink.url``. Frames are rendered in ``house`` at the vehicle's reported pose (the
    profile's frame source). Returns ``(robot, episode)``: the ``SimulatorFacade`` and the episode
    re-anchored at the vehicle's pose (a robot starts where it stands: same target and goals, the
    shortest path recomputed from there).
    """
    from dataclasses import replace

    from hiconav.drivers.adapters import open_mission_robot
    from hiconav.drivers.profiles import RobotProfile, load_profile
    from hiconav.sim.geodesic import GoalDistance

    prof = profile if isinstance(profile, RobotProfile) else load_profile(profile)
    sim_cfg: Any = area_config(_sim_config_cls(), dict(overrides or {}), "sim")
    robot = open_mission_robot(prof, url=url, house=house, handle_signals=handle_signals)
    try:
        deadline = time.monotonic() + prof.mavlink.heartbeat_wait_s
        while robot.driver.pose is None and time.monotonic() < deadline:  # pose follows the heartbeat
            time.sleep(0.02)
        pose = robot.driver.pose
        if pose is None:
            from hiconav.drivers.base import DriverError

            raise DriverError(f"no pose from the vehicle on {robot.driver.url}", field="mavlink.url")
        goal = GoalDistance(house, episode, radius=sim_cfg.robot_radius)
        shortest = float(goal.distance(pose.xy))
        if not math.isfinite(shortest):
            from hiconav.errors import DataError

            raise DataError(f"the vehicle at ({pose.x:.2f}, {pose.y:.2f}) cannot reach any {episode.target} "
                            f"of {house.name}: is the vehicle running the same house (--house)?", field="house")
    except BaseException:
        robot.close()
        raise
    return robot, replace(episode, episode_id=f"{episode.episode_id}/mavlink", start=pose,
                          geodesic_distance=shortest)


def episode_for_instruction(house: Any, start: Pose2D, instruction: str, episode_id: str = "run") -> Any:
    """An Episode whose goals are every instance of the instruction's first target category."""
    from hiconav.errors import DataError
    from hiconav.reasoning.decompose import decompose_instruction
    from hiconav.sim.episodes import Episode
    from hiconav.sim.geodesic import GoalDistance

    task = decompose_instruction(instruction)
    for target in task.targets:
        ids = tuple(o.instance_id for o in house.instances_of(target))
        if ids:
            shortest = GoalDistance(house, instance_ids=ids).distance(start.xy)
            return Episode(episode_id, house.name, start, target, ids, float(shortest), instruction)
    raise DataError(f"{house.name} has no {' or '.join(task.targets) or 'target'} (from {instruction!r}); "
                    f"categories: {', '.join(sorted(house.categories))}", field="instruction")


def run_command(
    house: str = typer_option("procthor:val/3", "--house", help="House spec, e.g. procthor:val/3 or gibson:Allensville."),
    instruction: str | None = typer_option(None, "--instruction", help="Instruction; default: the episode's."),
    seed: int = typer_option(0, "--seed", help="Seed of the episode draw, detector noise and planners."),
    episode: int = typer_option(0, "--episode", help="Index of the generated episode (start pose, target)."),
    out: Path | None = typer_option(None, "--out", help="Folder for result.json (created)."),
    record: Path | None = typer_option(None, "--record", help="Write a Rerun recording (.rrd) here."),
    spawn: bool = typer_option(False, "--spawn", help="Open a live Rerun viewer."),
    clock: str | None = typer_option(None, "--clock", help="stepped (virtual time, reproducible; default with the sim) or real (default and only choice with --driver mavlink)."),
    mission: str = typer_option("objectnav", "--mission", help="Mission tree: a YAML file or a name."),
    settings: list[str] = typer_option([], "--set", help="Override a setting: area.key=value (repeatable)."),
    config_file: Path | None = typer_option(None, "--config", help="Settings YAML (sections sim, memory, ...); --set wins."),
    driver: str = typer_option("sim", "--driver", help="sim (the built-in simulator) or mavlink (a vehicle over MAVLink, e.g. `hiconav vehicle`)."),
    connect: str | None = typer_option(None, "--connect", help="MAVLink URL (udpin:127.0.0.1:14550, tcp:HOST:PORT, /dev/ttyACM0); default: the profile's."),
    profile: str | None = typer_option(None, "--profile", help="Robot profile name (config/robots) or YAML path; --driver mavlink: default sim_vehicle."),
) -> None:
    """Run one ObjectNav mission end to end (built-in simulator, or a MAVLink vehicle) and print the outcome."""
    import json

    import typer

    from hiconav.sim import generate_episodes, load_house

    if driver not in ("sim", "mavlink"):
        raise ConfigError(f"--driver must be 'sim' or 'mavlink', got {driver!r}", field="driver")
    if driver == "sim" and (connect is not None or profile is not None):
        raise ConfigError("--connect and --profile need --driver mavlink", field="driver")
    if clock is not None:
        clock = {"realtime": "real", "real-time": "real"}.get(clock, clock)
        if clock not in ("stepped", "real"):
            raise ConfigError(f"--clock must be 'stepped' or 'real', got {clock!r}", field="clock")
    from hiconav.settings import resolve

    overrides = resolve(config_file, settings)  # validated: unknown keys and bad values name file:line
    if driver == "mavlink":
        forced = clock or nest(overrides).get("mission", {}).get("clock")
        if forced == "stepped":
            raise ConfigError("--driver mavlink runs on the real-time clock: a live vehicle keeps moving between "
                              "actor ticks, so the stepped (virtual) clock makes no sense against it; drop "
                              "--clock stepped / mission.clock=stepped (or use --clock real)", field="clock")
        clock = "real"
    clock = clock or area_config(MissionConfig, overrides, "mission").clock  # type: ignore[attr-defined]
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    if record is not None:
        record.parent.mkdir(parents=True, exist_ok=True)
    the_house = load_house(house)
    episodes = generate_episodes(the_house, episode + 1, seed=seed)
    ep = episodes[episode]
    robot = None
    if driver == "mavlink":
        robot, ep = connect_robot(the_house, ep, profile or "sim_vehicle", connect, overrides)
        typer.echo(f"connected to {robot.driver.url} (profile {robot.profile.name}, mode {robot.driver.mode}, "
                   f"{'armed' if robot.driver.armed else 'disarmed'}); vehicle at {ep.start}; frames rendered in "
                   f"{the_house.name} at the reported pose; Ctrl-C sends a zero setpoint")
    if instruction:
        ep = episode_for_instruction(the_house, ep.start, instruction, f"{ep.episode_id}/custom")
    typer.echo(f"house {the_house.name}, episode {ep.episode_id}: {ep.instruction!r} "
               f"(target {ep.target}, shortest path {ep.geodesic_distance:.2f} m), clock {clock}, mission {mission}")
    try:
        result = run_mission(the_house, ep, seed=seed, overrides=overrides, tree=mission, clock=clock,
                             instruction=instruction or ep.instruction, record=record, spawn=spawn, robot=robot)
    except KeyboardInterrupt:
        if robot is None:
            raise
        typer.secho("interrupted: zero setpoint sent, actors stopped, link closed", fg=typer.colors.YELLOW, err=True)
        raise typer.Exit(130) from None
    for pause in result.pauses:
        end = "still paused at the end" if pause["end"] is None else f"resumed at {pause['end']:.1f} s"
        typer.secho(f"FAILSAFE: mission paused at {pause['start']:.1f} s ({pause['reason']}); {end}",
                    fg=typer.colors.YELLOW, err=True)
    summary = result.summary()
    m = result.metrics
    typer.echo(f"success: {bool(m.success)}  SPL: {m.spl:.3f}  steps: {m.steps}  DTS: {m.dts:.2f} m  "
               f"path: {m.path_length:.2f} m  ended by: {result.termination} (tree {result.mission_status})")
    typer.echo(f"clock: {result.clock} {result.clock_s:.1f} s  wall: {result.wall_s:.1f} s  "
               f"detector: {result.detector} (ground-truth oracle)  reasoner: {result.reasoner}")
    for note in result.fallbacks:
        typer.echo(f"FALLBACK: {note}")
    if record is not None:
        typer.echo(f"recording: {record}")
    if out is not None:
        summary.update({"house": the_house.name, "episode_id": ep.episode_id, "target": ep.target,
                        "instruction": instruction or ep.instruction, "seed": seed, "mission_tree": mission,
                        "dropped": {k: dict(v.dropped) for k, v in result.stats.items() if v.dropped}})
        (out / "result.json").write_text(json.dumps(summary, indent=2, default=str))
        typer.echo(f"wrote {out / 'result.json'}")
    if result.failure is not None:
        typer.secho(f"error: actor {result.failure}", fg=typer.colors.RED, err=True)
        raise typer.Exit(1)
