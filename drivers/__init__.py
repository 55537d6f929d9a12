"""Robot drivers (installed as ``hiconav.drivers``): the ``Driver`` protocol and its health report
(``base``), robot profiles (``profiles``), failsafes (``failsafe``), and the drivers themselves:
``sim_driver`` (the built-in simulator, default), ``mavlink_driver`` (ArduPilot / PX4 over
pymavlink), ``replay_driver`` (a recorded folder of frames), plus ``vehicle`` (a simulated MAVLink
vehicle to test against) and ``cli`` (``hiconav vehicle``).

Importing this package stays light: pymavlink and the simulator load only with their modules.
Use ``open_driver(name, profile, **options)`` to build a registered driver by name.
"""

from __future__ import annotations

import importlib
from typing import Any

from hiconav.drivers.base import (
    DRIVERS,
    CommandRefused,
    Driver,
    DriverError,
    DriverHealth,
    FailsafeState,
    FrameSource,
    LinkError,
)

__all__ = [
    "DRIVERS",
    "CommandRefused",
    "Driver",
    "DriverError",
    "DriverHealth",
    "FailsafeState",
    "FrameSource",
    "LinkError",
    "open_driver",
]

_MODULES = {"sim": "hiconav.drivers.sim_driver", "mavlink": "hiconav.drivers.mavlink_driver",
            "replay": "hiconav.drivers.replay_driver"}


def open_driver(name: str, profile: Any = None, **options: Any) -> Driver:
    """Build the driver registered as ``name`` ("sim", "mavlink", "replay" or "pkg.module:Factory").

    ``profile`` is a ``RobotProfile``, a profile name or path, or None for the driver's default;
    ``options`` go to the driver's factory (e.g. ``url=``, ``frame_source=``, ``house=``).
    """
    from hiconav.drivers.profiles import RobotProfile, load_profile

    if name in _MODULES and name not in DRIVERS:
        importlib.import_module(_MODULES[name])
    if profile is None:
        profile = RobotProfile(name=f"{name}-default", driver=name if name in _MODULES else "sim")
    elif not isinstance(profile, RobotProfile):
        profile = load_profile(profile)
    factory = DRIVERS.get(name, field="driver")
    return factory(profile, **options)
