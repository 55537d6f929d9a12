"""Toy nodes for runtime tests: a counter driver, a relay and a node that fails on demand."""

from __future__ import annotations

from dataclasses import dataclass

from hiconav.actors.node import Node

from hiconav.messages import CommandMsg, EpisodeEnded
from hiconav.types import DiscreteAction, VelocityCommand


@dataclass(frozen=True)
class Ping:
    n: int
    stamp: float


class ToyDriver(Node):
    """Emits Ping n at each tick to `relay`; executes commands; ends after `limit` commands."""

    name = "driver"

    def __init__(self, log: list, rate_hz: float = 10.0, limit: int = 5) -> None:
        super().__init__(rate_hz)
        self.log, self.limit, self.n = log, limit, 0
        self.executed: list[int] = []
        self.command: VelocityCommand | None = None
        self.ended = False
        self.latest_wins(CommandMsg)

    def start(self, now):
        self.log.append(("start", self.name))

    def stop(self, now):
        self.log.append(("stop", self.name))

    def tick(self, now):
        cmd = self.take(CommandMsg)
        if cmd is not None and not self.ended:
            self.executed.append(cmd.seq)
            self.command = VelocityCommand(0.3, 0.0, now)
            if len(self.executed) >= self.limit:
                self.ended = True
                self.emit("runtime", EpisodeEnded("stop", len(self.executed), now))
                return
        self.n += 1
        self.emit("relay", Ping(self.n, now))

    def emergency_stop(self, reason, now):
        self.command = VelocityCommand.zero(now)
        self.log.append(("emergency", reason))
        if not self.ended:
            self.ended = True
            self.emit("runtime", EpisodeEnded("emergency", len(self.executed), now))


class Relay(Node):
    """Turns the newest Ping into a command (latest-wins: older pings are dropped and counted)."""

    name = "relay"

    def __init__(self, log: list, rate_hz: float = 10.0, fail_at: int | None = None, delay: float = 0.0) -> None:
        super().__init__(rate_hz)
        self.log, self.fail_at, self.delay = log, fail_at, delay
        self.seen: list[int] = []
        self.latest_wins(Ping)

    def start(self, now):
        self.log.append(("start", self.name))

    def stop(self, now):
        self.log.append(("stop", self.name))

    def tick(self, now):
        ping = self.take(Ping)
        if ping is None:
            return
        if self.fail_at is not None and ping.n >= self.fail_at:
            raise RuntimeError(f"relay broke on ping {ping.n}")
        self.seen.append(ping.n)
        self.emit("driver", CommandMsg(ping.n, now, action=DiscreteAction.MOVE_FORWARD), self.delay)
