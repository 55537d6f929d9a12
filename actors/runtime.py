"""Runtimes that run a mission's nodes: real time (pykka threads, wall timers) and stepped time.

``RealtimeRuntime``: each node lives in its own pykka ``ThreadingActor`` (``NodeActor``); a
ticker thread per actor sends ``Tick`` messages at the node's rate (a tick is sent only when the
previous one was handled, so ticks never pile up: late ones are dropped and counted). Messages go
actor to actor with ``tell`` only (no ``ask``, so no ``.get()`` inside a handler); results for the
runtime go to its own inbox queue.

``SteppedRuntime``: the same nodes, the same messages, driven synchronously by a virtual-clock
scheduler. At each virtual instant the nodes whose tick is due run in a fixed order (the order
given, normally the data-flow order driver -> perception -> memory -> reasoning -> exploration ->
mission -> control); each first receives the messages that became visible by then (FIFO), then
ticks. A message emitted with ``delay`` (e.g. the VLM latency) becomes visible ``delay`` virtual
seconds later. Nothing depends on wall time, so the same seed gives the same run.

Both: nodes start in the given (dependency) order and stop in reverse; when a node raises, the
runtime records ``ActorFailed(actor, error)``, tells the driver to stop (zero command) and ends.
"""

from __future__ import annotations

import heapq
import itertools
import math
import queue
import threading
import time
import traceback
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import pykka
from hiconav.actors.node import Node, Outgoing

from hiconav.messages import ActorFailed, EmergencyStop, EpisodeEnded, MissionFinished, Tick

RUNTIME = "runtime"  # destination name of messages meant for the runtime (reports)


@dataclass
class RunReport:
    """How a run ended: reason ("episode_ended" | "mission_failed" | "actor_failed" | "timeout"),
    the failure if any, every report message, per-node stats, start and stop order, clocks."""

    reason: str
    failure: ActorFailed | None
    reports: list[Any]
    stats: dict[str, Any]
    start_order: list[str]
    stop_order: list[str]
    clock_s: float
    wall_s: float
    dropped_ticks: dict[str, int] = field(default_factory=dict)
    run_s: float = 0.0  # clock time when the run ended, before the actors were stopped

    @property
    def episode(self) -> EpisodeEnded | None:
        return next((r for r in self.reports if isinstance(r, EpisodeEnded)), None)

    @property
    def mission(self) -> MissionFinished | None:
        return next((r for r in self.reports if isinstance(r, MissionFinished)), None)


def _format_error(exc: BaseException) -> str:
    tb = traceback.extract_tb(exc.__traceback__)
    where = f" at {tb[-1].filename.rsplit('/', 1)[-1]}:{tb[-1].lineno}" if tb else ""
    return f"{type(exc).__name__}: {exc}{where}"


def _ends_run(msg: Any) -> str | None:
    if isinstance(msg, ActorFailed):
        return "actor_failed"
    if isinstance(msg, EpisodeEnded):
        return "episode_ended"
    if isinstance(msg, MissionFinished) and msg.status != "SUCCESS":
        return "mission_failed"
    return None


# ============================================================================== stepped time
class SteppedRuntime:
    """Virtual-clock scheduler: ticks nodes in a fixed order, delivers messages after their delay."""

    def __init__(self, nodes: Sequence[Node], *, driver: str = "driver",
                 tick_order: Sequence[str] | None = None) -> None:
        """``nodes`` in start (dependency) order; ``tick_order``: names, default the same order."""
        names = [n.name for n in nodes]
        if len(set(names)) != len(names):
            raise ValueError(f"node names must be unique: {names}")
        self.by_name = {n.name: n for n in nodes}
        self.start_nodes = list(nodes)
        order = [n for n in (tick_order or names) if n in self.by_name]
        order += [n for n in names if n not in order]
        self.nodes = [self.by_name[n] for n in order]
        self.driver = driver
        self.now = 0.0
        self._seq = itertools.count()
        self._inbox: dict[str, list[tuple[float, int, Any]]] = {n: [] for n in names}
        self._tick_index = {n: 0 for n in names}
        self.reports: list[Any] = []
        self.start_order: list[str] = []
        self.stop_order: list[str] = []

    def clock(self) -> float:
        return self.now

    def _route(self, outs: list[Outgoing]) -> None:
        for out in outs:
            if out.dest == RUNTIME:
                self.reports.append(out.msg)
            elif out.dest in self._inbox:
                heapq.heappush(self._inbox[out.dest], (self.now + max(out.delay, 0.0), next(self._seq), out.msg))
            # a destination that is not part of this mission is ignored (e.g. an optional recorder)

    def _next_time(self, node: Node) -> float:
        return round(self._tick_index[node.name] * node.period, 9)

    def run(self, *, max_time: float = 3600.0) -> RunReport:
        wall0 = time.perf_counter()
        failure: ActorFailed | None = None
        reason = "timeout"
        started: list[Node] = []
        current = self.start_nodes[0]
        try:
            for node in self.start_nodes:
                current = node
                node.start(self.now)
                started.append(node)
                self.start_order.append(node.name)
                self._route(node.drain())
            while self.now <= max_time:
                for node in self.nodes:
                    if self._next_time(node) > self.now + 1e-9:
                        continue
                    current = node
                    inbox = self._inbox[node.name]
                    while inbox and inbox[0][0] <= self.now + 1e-9:
                        _, _, msg = heapq.heappop(inbox)
                        node.receive(msg, self.now)
                        self._route(node.drain())
                    node.run_tick(self.now)
                    self._route(node.drain())
                    self._tick_index[node.name] += 1
                ended = next((r for r in map(_ends_run, self.reports) if r), None)
                if ended:
                    reason = ended
                    failure = next((r for r in self.reports if isinstance(r, ActorFailed)), None)
                    break
                self.now = min(self._next_time(n) for n in self.nodes)
        except Exception as exc:  # a node failed: stop the robot, name the actor
            failure = ActorFailed(current.name, _format_error(exc), self.now)
            self.reports.append(failure)
            reason = "actor_failed"
        if failure is not None and self.driver in self.by_name and self.by_name[self.driver] in started:
            try:
                self.by_name[self.driver].emergency_stop(f"{failure.actor} failed: {failure.error}", self.now)
                self._route(self.by_name[self.driver].drain())
            except Exception as exc:  # the driver itself is broken: nothing more to stop
                self.reports.append(ActorFailed(self.driver, _format_error(exc), self.now))
        for node in reversed(started):
            try:
                node.stop(self.now)
            except Exception as exc:
                self.reports.append(ActorFailed(node.name, f"on stop: {_format_error(exc)}", self.now))
            self.stop_order.append(node.name)
        return RunReport(reason, failure, self.reports, {n.name: n.stats for n in self.nodes}, self.start_order,
                         self.stop_order, self.now, time.perf_counter() - wall0, run_s=self.now)


# ============================================================================== real time
@dataclass(frozen=True)
class _Go:
    """Runtime -> actor: everyone is up; here are the other actors; start ticking."""

    routes: dict[str, Any]


class NodeActor(pykka.ThreadingActor):
    """A pykka actor that owns one ``Node`` and runs it at the node's rate on its own thread."""

    def __init__(self, node: Node, reports: queue.Queue, clock: Callable[[], float]) -> None:
        super().__init__()
        self.node = node
        self.reports = reports
        self.clock = clock
        self.routes: dict[str, Any] = {}
        self._halt = threading.Event()
        self._tick_pending = threading.Event()
        self._ticker: threading.Thread | None = None
        self.dropped_ticks = 0
        self.early_ticks = 0
        self._last_tick = -math.inf
        self._timers: list[threading.Timer] = []

    def __str__(self) -> str:
        return f"{type(self).__name__}({self.node.name})"

    # pykka hooks --------------------------------------------------------------------------------
    def on_start(self) -> None:
        try:
            self.node.start(self.clock())
        except Exception as exc:
            self.reports.put(ActorFailed(self.node.name, f"on start: {_format_error(exc)}", self.clock()))
            raise

    def _count_dropped_ticks(self) -> None:
        if self.dropped_ticks:
            self.node.stats.dropped["Tick"] = self.dropped_ticks

    def on_stop(self) -> None:
        self._halt.set()
        self._count_dropped_ticks()
        for t in self._timers:
            t.cancel()
        self.node.stop(self.clock())

    def on_failure(self, exc_type: Any, exc: BaseException | None, tb: Any) -> None:
        self._halt.set()
        self._count_dropped_ticks()
        error = _format_error(exc) if exc is not None else str(exc_type)
        self.reports.put(ActorFailed(self.node.name, error, self.clock()))
        try:  # a failing driver zeroes its own command before its thread ends
            self.node.emergency_stop(f"{self.node.name} failed: {error}", self.clock())
        except Exception:
            pass

    def on_receive(self, message: Any) -> Any:
        now = self.clock()
        if isinstance(message, Tick):
            self._tick_pending.clear()
            if now - self._last_tick >= 0.5 * self.node.period:  # else an input tick just ran
                self._run_tick(now)
        elif isinstance(message, _Go):
            self.routes = dict(message.routes)
            self._ticker = threading.Thread(target=self._tick_loop, name=f"ticker-{self.node.name}", daemon=True)
            self._ticker.start()
        elif isinstance(message, EmergencyStop):
            self.node.emergency_stop(message.reason, now)
        else:
            self.node.receive(message, now)
            # Nodes of the per-frame chain work on new input at once instead of at their next timer
            # tick; otherwise every hop of the driver -> perception -> memory -> control loop adds up
            # to one period of latency and the loop runs at a fraction of the driver's rate. The
            # driver keeps its timer, so the loop never runs faster than the configured camera rate.
            if self.node.event_driven:
                self.early_ticks += 1
                self._run_tick(now)
        self._route(self.node.drain())
        return None

    def _run_tick(self, now: float) -> None:
        self._last_tick = now
        self.node.run_tick(now)

    # helpers ------------------------------------------------------------------------------------
    def _route(self, outs: list[Outgoing]) -> None:
        for out in outs:
            if out.dest == RUNTIME:
                self.reports.put(out.msg)
                continue
            ref = self.routes.get(out.dest)
            if ref is None:
                continue
            if out.delay > 0:  # configured latency (e.g. a simulated VLM): deliver later, never block
                timer = threading.Timer(out.delay, self._tell_if_alive, args=(ref, out.msg))
                timer.daemon = True
                self._timers = [t for t in self._timers if t.is_alive()] + [timer]
                timer.start()
            else:
                self._tell_if_alive(ref, out.msg)

    @staticmethod
    def _tell_if_alive(ref: Any, msg: Any) -> None:
        try:
            ref.tell(msg)
        except pykka.ActorDeadError:
            pass

    def _tick_loop(self) -> None:
        period = self.node.period
        next_t = time.monotonic()
        while not self._halt.is_set():
            next_t += period
            if self._halt.wait(max(0.0, next_t - time.monotonic())):
                break
            if self._tick_pending.is_set():  # the last tick is still queued: drop this one
                self.dropped_ticks += 1
                continue
            self._tick_pending.set()
            try:
                self.actor_ref.tell(Tick(self.clock()))
            except pykka.ActorDeadError:
                break
            if time.monotonic() - next_t > period:  # fell behind: resynchronise, don't burst
                next_t = time.monotonic()


class RealtimeRuntime:
    """Runs nodes as pykka actors on wall-clock timers; ``run`` blocks until the episode ends."""

    def __init__(self, nodes: Sequence[Node], *, driver: str = "driver") -> None:
        self.nodes = list(nodes)
        self.driver = driver
        self.reports: queue.Queue = queue.Queue()
        self.refs: dict[str, Any] = {}
        self.start_order: list[str] = []
        self.stop_order: list[str] = []
        self._t0 = time.monotonic()

    def clock(self) -> float:
        return time.monotonic() - self._t0

    def run(self, *, max_time: float = 3600.0, stop_timeout: float = 10.0) -> RunReport:
        wall0 = time.perf_counter()
        collected: list[Any] = []
        failure: ActorFailed | None = None
        reason = "timeout"
        try:
            for node in self.nodes:  # dependency order
                ref = getattr(node, "actor_class", NodeActor).start(node, self.reports, self.clock)
                self.refs[node.name] = ref
                self.start_order.append(node.name)
                if not ref.is_alive():
                    raise RuntimeError(f"{node.name} did not start")
            for name, ref in self.refs.items():
                try:
                    ref.tell(_Go(dict(self.refs)))
                except pykka.ActorDeadError:  # it failed in on_start; its ActorFailed is in the inbox
                    pass
            deadline = time.monotonic() + max_time
            while time.monotonic() < deadline:
                try:
                    msg = self.reports.get(timeout=min(0.5, max(deadline - time.monotonic(), 0.01)))
                except queue.Empty:
                    continue
                collected.append(msg)
                ended = _ends_run(msg)
                if ended:
                    reason = ended
                    if isinstance(msg, ActorFailed):
                        failure = msg
                    break
        except RuntimeError:
            pass
        while True:  # anything reported meanwhile (e.g. a failure during start)
            try:
                msg = self.reports.get_nowait()
            except queue.Empty:
                break
            collected.append(msg)
            if isinstance(msg, ActorFailed) and failure is None:
                failure, reason = msg, "actor_failed"
        run_s = self.clock()
        if failure is not None:
            driver = self.refs.get(self.driver)
            if driver is not None and driver.is_alive():
                driver.tell(EmergencyStop(f"{failure.actor} failed: {failure.error}", self.clock()))
        for name in reversed(list(self.refs)):
            ref = self.refs[name]
            try:
                ref.stop(block=True, timeout=stop_timeout)
            except pykka.Timeout:
                collected.append(ActorFailed(name, f"did not stop within {stop_timeout} s", self.clock()))
            self.stop_order.append(name)
        while True:
            try:
                collected.append(self.reports.get_nowait())
            except queue.Empty:
                break
        return RunReport(reason, failure, collected, {n.name: n.stats for n in self.nodes}, self.start_order,
                         self.stop_order, self.clock(), time.perf_counter() - wall0,
                         {n.name: n.stats.dropped.get("Tick", 0) for n in self.nodes}, run_s)
