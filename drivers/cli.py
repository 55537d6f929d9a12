"""``hiconav vehicle``: run the simulated MAVLink vehicle (``drivers/vehicle.py``) until Ctrl-C.

Registered in ``hiconav/cli.py`` as ``("vehicle", "hiconav.drivers.cli", "vehicle")``. Heavy
imports (pymavlink, the simulator) happen inside the command. This module only parses options
and prints a status line; it must not implement vehicle behaviour.
"""

from __future__ import annotations

import typer

from hiconav.errors import ConfigError


def vehicle(
    house: str | None = typer.Option(None, "--house", help="House spec (procthor:val/3, gibson:Allensville, a file); none = free space."),
    listen: str = typer.Option("udpout:127.0.0.1:14550", "--listen",
                               help="pymavlink URL: udpout:HOST:PORT sends to a GCS listening there (hiconav run --connect udpin:HOST:PORT)."),
    autopilot: str = typer.Option("ardupilot", "--autopilot", help="ardupilot (GUIDED) or px4 (OFFBOARD)."),
    start: str | None = typer.Option(None, "--start", help="x,y,yaw world start pose (default: the house's start, else 0,0,0)."),
    system_id: int = typer.Option(1, "--system-id", min=1, max=255),
    pose_hz: float = typer.Option(25.0, "--pose-hz", min=1.0, max=200.0),
    setpoint_timeout: float = typer.Option(0.4, "--setpoint-timeout", min=0.05, help="s without a setpoint before the vehicle stops."),
    gcs_timeout: float = typer.Option(3.0, "--gcs-timeout", min=0.1, help="s without a GCS heartbeat before the vehicle stops."),
    max_linear: float = typer.Option(1.0, "--max-linear", min=0.01),
    max_angular: float = typer.Option(2.0, "--max-angular", min=0.01),
    radius: float = typer.Option(0.18, "--radius", min=0.01, help="robot radius for collisions (m)."),
    refuse_mode: list[str] = typer.Option([], "--refuse-mode", help="Mode names to refuse (repeatable), for testing."),
    refuse_arm: bool = typer.Option(False, "--refuse-arm", help="Refuse arming, for testing."),
    signing_key: str | None = typer.Option(None, "--signing-key", help="MAVLink 2 signing key, 64 hex digits: sign what the vehicle sends, refuse unsigned messages."),
    signing_key_file: str | None = typer.Option(None, "--signing-key-file", help="A file holding the signing key (64 hex digits)."),
    quiet: bool = typer.Option(False, "--quiet", help="No status line."),
) -> None:
    """Run the built-in simulator's kinematics as a MAVLink vehicle on this machine."""
    from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig

    from hiconav.types import Pose2D

    if autopilot not in ("ardupilot", "px4"):
        raise ConfigError(f"--autopilot must be ardupilot or px4, got {autopilot!r}", field="autopilot")
    sim_house = None
    pose = Pose2D(0.0, 0.0, 0.0)
    if house:
        from hiconav.sim import load_house

        sim_house = load_house(house)
        if sim_house.start_hint is not None:
            pose = Pose2D(*sim_house.start_hint)
    if start:
        try:
            x, y, yaw = (float(v) for v in start.split(","))
        except ValueError:
            raise ConfigError(f"--start must be x,y,yaw (three numbers), got {start!r}", field="start") from None
        pose = Pose2D(x, y, yaw)
    key = _signing_key(signing_key, signing_key_file)
    config = VehicleConfig(autopilot=autopilot, system_id=system_id, start=pose, pose_hz=pose_hz,
                           setpoint_timeout_s=setpoint_timeout, gcs_timeout_s=gcs_timeout, max_linear=max_linear, max_angular=max_angular,
                           robot_radius=radius, refuse_modes=frozenset(m.upper() for m in refuse_mode),
                           refuse_arm=refuse_arm, signing_key=key)
    try:
        sim = SimulatedVehicle(listen, config, house=sim_house)
    except ValueError as exc:
        raise ConfigError(str(exc), field="start") from None
    sim.start()
    typer.echo(f"vehicle ({autopilot}, system {system_id}) on {listen}"
               + (f", house {house}" if house else ", free space") + f", start {pose}"
               + (", MAVLink 2 signing on" if key is not None else "") + "; Ctrl-C to stop")

    def report(state) -> None:
        if not quiet:
            p = state.pose
            typer.echo(f"{state.mode:9s} {'ARMED' if state.armed else 'disarmed':8s} x={p.x:7.2f} y={p.y:7.2f} "
                       f"yaw={p.yaw:+.2f} v={state.v:+.2f} w={state.omega:+.2f}"
                       + (" COLLIDED" if state.collided else "")
                       + (f" [{state.stop_reason}]" if state.stop_reason else ""))

    sim.run_forever(report)


def _signing_key(text: str | None, path: str | None) -> bytes | None:
    """The vehicle's signing key from --signing-key or --signing-key-file (as a profile reads it)."""
    from hiconav.drivers.profiles import MavlinkProfile, parse_signing_key

    if text is not None and path is not None:
        raise ConfigError("give --signing-key or --signing-key-file, not both", field="signing_key")
    if text is not None:
        try:
            return parse_signing_key(text, "--signing-key")
        except ValueError as exc:
            raise ConfigError(str(exc), field="signing_key") from None
    return MavlinkProfile(signing_key_file=path).secret_key() if path is not None else None
