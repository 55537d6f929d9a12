"""The battery monitor example actor raises one alert when the modelled charge runs low."""

from __future__ import annotations

from hiconav.actors import SteppedRuntime
from hiconav.actors.monitor import BatteryMonitorNode
from hiconav.actors.node import Node

from hiconav.messages import EpisodeEnded, HealthAlert


class Sink(Node):
    name = "mission"

    def __init__(self) -> None:
        super().__init__(10.0)
        self.alerts: list[HealthAlert] = []
        self.on(HealthAlert, self._alert)

    def _alert(self, msg: HealthAlert, now: float) -> None:
        self.alerts.append(msg)
        self.emit("runtime", EpisodeEnded("battery", 0, now))


def test_battery_alert_arrives_once_below_the_threshold():
    sink = Sink()
    report = SteppedRuntime([BatteryMonitorNode(100.0, warn_fraction=0.5, rate_hz=1.0), sink]).run(max_time=200)
    assert report.reason == "episode_ended"
    assert len(sink.alerts) == 1 and sink.alerts[0].kind == "battery"
    assert 50.0 <= sink.alerts[0].stamp <= 52.0
