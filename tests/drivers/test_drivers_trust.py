"""Whom the MAVLink driver trusts: one vehicle (system AND component id), positions the vehicle
can physically reach, and (with a key) only MAVLink 2 signed messages; and how fast it stops
when the link goes.

The first part drives the driver's receive and send steps directly on a stepped clock (no
threads, no sockets): messages are real MAVLink 2 packets, encoded by a peer and decoded as the
driver's link would. The second part runs signed links against the simulated vehicle over UDP.
"""

from __future__ import annotations

import logging
import math

import pytest
from driver_helpers import free_udp_port, test_profile, wait_until
from hiconav.drivers.base import FailsafeState, LinkError
from hiconav.drivers.mavlink_driver import MavlinkDriver, mavlink, mavutil
from hiconav.drivers.profiles import load_profile, profile_from_dict
from hiconav.drivers.vehicle import SimulatedVehicle, VehicleConfig

from hiconav.errors import ConfigError
from hiconav.types import VelocityCommand

KEY_HEX = "6b" * 32
OTHER_KEY_HEX = "a5" * 32


class SteppedClock:
    def __init__(self, t: float = 0.0) -> None:
        self.t = t

    def __call__(self) -> float:
        return self.t


class FakeLink:
    """Stands in for the pymavlink connection: records the setpoints the driver sends."""

    probably_vehicle_heartbeat = mavutil.mavfile.probably_vehicle_heartbeat

    def __init__(self) -> None:
        self.mav = self
        self.setpoints: list[tuple[float, float]] = []  # (vx, NED yaw rate)

    def set_position_target_local_ned_send(self, *args: float) -> None:
        self.setpoints.append((args[8], args[15]))

    def heartbeat_send(self, *args: object) -> None:
        pass

    def command_long_send(self, *args: object) -> None:
        pass

    def close(self) -> None:
        pass


class Peer:
    """A MAVLink 2 sender with a system and component id; ``msg`` returns what a receiver decodes."""

    def __init__(self, system: int = 1, component: int = 1) -> None:
        self._out = mavlink.MAVLink(None, srcSystem=system, srcComponent=component)
        self._parser = mavlink.MAVLink(None)

    def msg(self, name: str, *fields: object):
        packet = getattr(self._out, f"{name}_encode")(*fields).pack(self._out)
        return self._parser.decode(bytearray(packet))

    def heartbeat(self):
        return self.msg("heartbeat", mavlink.MAV_TYPE_GROUND_ROVER, mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA,
                        mavlink.MAV_MODE_FLAG_CUSTOM_MODE_ENABLED, 0, mavlink.MAV_STATE_ACTIVE)

    def position(self, north: float, east: float):
        return self.msg("local_position_ned", 0, north, east, 0.0, 0.0, 0.0, 0.0)

    def attitude(self, yaw_ned: float = 0.0):
        return self.msg("attitude", 0, 0.0, 0.0, yaw_ned, 0.0, 0.0, 0.0)


def stepped_driver(**sections: dict) -> tuple[MavlinkDriver, SteppedClock, FakeLink]:
    clock = SteppedClock()
    driver = MavlinkDriver(test_profile(**sections), clock=clock, handle_signals=False)
    link = FakeLink()
    driver._conn = link
    return driver, clock, link


def hear(driver: MavlinkDriver, clock: SteppedClock, t: float, *messages) -> None:
    clock.t = t
    for m in messages:
        driver._handle(m)


# ---------------------------------------------------------------- link loss -> zero setpoint
def first_zero_after_loss(t_cut: float, phase: float) -> tuple[float, float]:
    """Vehicle messages every 40 ms until ``t_cut``; the driver's sender starts at ``phase`` and
    the navigator keeps commanding 0.3 m/s. Returns (last message time, first zero setpoint time)."""
    driver, clock, link = stepped_driver()
    vehicle = Peer()
    msg_t, last_msg, wake = 0.0, None, phase
    while True:
        if msg_t < t_cut and msg_t <= wake:
            hear(driver, clock, msg_t, vehicle.heartbeat(), vehicle.position(0.0, 0.0), vehicle.attitude())
            last_msg = msg_t
            msg_t = round(msg_t + 0.04, 9)
            continue
        clock.t = wake
        driver.send(VelocityCommand(0.3, 0.0))
        n = len(link.setpoints)
        wake = driver._tick(wake)
        v = link.setpoints[n][0]
        if clock.t < t_cut - 0.1:
            assert clock.t < 0.1 or v == pytest.approx(0.3), "healthy link: the command goes out"
        elif clock.t > t_cut and v == 0.0:
            return last_msg, clock.t
        assert clock.t < t_cut + 5.0


@pytest.mark.parametrize("phase", [0.0, 0.013, 0.029, 0.047])
def test_link_loss_sends_the_first_zero_setpoint_within_half_a_second(phase):
    for k in range(8):  # the cut at every offset against the 40 ms message and 50 ms setpoint grids
        last_msg, zero_at = first_zero_after_loss(2.0 + 0.006 * k, phase)
        assert zero_at - last_msg <= 0.45  # 0.4 s link timeout, then at once (not a period later)


def test_profiles_keep_link_timeout_plus_a_setpoint_period_below_half_a_second():
    for name in ("ardupilot_rover", "px4_rover", "sim_vehicle"):
        p = load_profile(name)
        assert p.failsafe.link_timeout_s + 1.0 / p.rates.setpoint_hz <= 0.45, name


# ---------------------------------------------------------------- one vehicle: system and component
def test_profile_named_vehicle_ignores_a_peer_heard_first():
    driver, clock, _ = stepped_driver(mavlink={"target_system": 1, "target_component": 1})
    hear(driver, clock, 0.0, Peer(system=7).heartbeat(), Peer(system=7).position(50.0, 50.0))
    assert driver._last_heartbeat is None and driver.pose is None
    vehicle = Peer(system=1)
    hear(driver, clock, 0.1, vehicle.heartbeat(), vehicle.position(1.0, 2.0), vehicle.attitude())
    assert driver.target_system == 1 and driver.target_component == 1
    assert (driver.pose.x, driver.pose.y) == (2.0, 1.0)
    assert driver.stats["other_system"] == 2


def test_a_forged_system_id_from_another_component_is_ignored():
    driver, clock, _ = stepped_driver(mavlink={"target_system": 1, "target_component": 1})
    vehicle, forger = Peer(1, 1), Peer(1, 42)
    hear(driver, clock, 0.0, vehicle.heartbeat(), vehicle.position(0.0, 0.0), vehicle.attitude())
    hear(driver, clock, 0.02, forger.heartbeat(), forger.position(0.1, 0.1))
    assert (driver.pose.x, driver.pose.y) == (0.0, 0.0)
    assert driver.stats["other_component"] == 2


def test_first_heard_vehicle_is_locked_with_a_warning(caplog):
    driver, clock, _ = stepped_driver()  # target_system 0: the first vehicle heard
    with caplog.at_level(logging.WARNING, logger="hiconav.drivers.mavlink"):
        hear(driver, clock, 0.0, Peer(3, 1).heartbeat())
    assert (driver.target_system, driver.target_component) == (3, 1)
    assert "locked to the first vehicle heard" in caplog.text and "system 3, component 1" in caplog.text
    hear(driver, clock, 0.1, Peer(4, 1).heartbeat(), Peer(3, 2).heartbeat())
    assert (driver.target_system, driver.target_component) == (3, 1)
    assert driver.stats["other_system"] == 1 and driver.stats["other_component"] == 1


def test_shipped_mavlink_profiles_name_the_vehicle():
    for name in ("ardupilot_rover", "px4_rover", "sim_vehicle"):
        m = load_profile(name).mavlink
        assert (m.target_system, m.target_component) == (1, 1), name


# ---------------------------------------------------------------- physically possible positions
def test_a_position_jump_beyond_the_possible_is_rejected_and_stops_the_robot():
    # a peer forging the vehicle's system and component id reports a pose 1,414 m away
    driver, clock, link = stepped_driver(limits={"max_linear": 0.5})
    vehicle = Peer(1, 1)
    for i in range(10):  # 0.3 m/s east: possible
        hear(driver, clock, 0.04 * i, vehicle.heartbeat(), vehicle.position(0.0, 0.012 * i), vehicle.attitude())
    driver.send(VelocityCommand(0.3, 0.0))
    driver._tick(clock.t)
    assert link.setpoints[-1][0] == pytest.approx(0.3) and driver.health().ok
    before = driver.pose
    hear(driver, clock, 0.4, vehicle.position(1000.0, 1000.0))
    assert driver.pose == before and driver.stats["pose_jumps"] == 1
    h = driver.health()
    assert h.failsafe == FailsafeState.POSE_JUMP and h.paused and not h.ok
    assert "1414" in h.reason
    driver.send(VelocityCommand(0.3, 0.0))
    driver._tick(clock.t)
    assert link.setpoints[-1] == (0.0, -0.0)


def test_motion_at_the_vehicles_top_speed_is_not_a_jump():
    driver, clock, _ = stepped_driver(limits={"max_linear": 0.5})
    vehicle = Peer(1, 1)
    for i in range(50):  # 0.5 m/s north, and a 0.3 m odometry step (within the 0.5 m margin)
        north = 0.02 * i + (0.3 if i >= 25 else 0.0)
        hear(driver, clock, 0.04 * i, vehicle.heartbeat(), vehicle.position(north, 0.0), vehicle.attitude())
    assert driver.stats["pose_jumps"] == 0 and driver.pose.y == pytest.approx(1.28)
    assert driver.health().failsafe == FailsafeState.OK


def test_after_a_rejected_jump_resume_waits_until_the_jumps_stop():
    driver, clock, _ = stepped_driver()
    vehicle = Peer(1, 1)
    hear(driver, clock, 0.0, vehicle.heartbeat(), vehicle.position(0.0, 0.0), vehicle.attitude())
    hear(driver, clock, 0.04, vehicle.position(30.0, 0.0))
    with pytest.raises(Exception, match="rejected"):
        driver.resume()
    t = 0.04
    while t < 1.0:  # the real vehicle keeps reporting where it is
        t += 0.04
        hear(driver, clock, t, vehicle.heartbeat(), vehicle.position(0.0, 0.0), vehicle.attitude())
    driver.resume()
    assert driver.health().ok


# ---------------------------------------------------------------- MAVLink 2 signing
def test_a_bad_signing_key_in_the_profile_names_the_field():
    with pytest.raises(ConfigError, match="64 hex digits") as err:
        profile_from_dict({"name": "t", "driver": "mavlink", "mavlink": {"signing_key": "abc"}})
    assert err.value.field == "mavlink.signing_key"


def test_a_missing_signing_key_file_is_a_clear_error(tmp_path):
    missing = tmp_path / "no.key"
    with pytest.raises(ConfigError, match="signing key file") as err:
        MavlinkDriver(test_profile(mavlink={"signing_key_file": str(missing)}), handle_signals=False)
    assert str(missing) in str(err.value)


def signed_pair(port: int, vehicle_key: str | None, driver_key: str | None, **mavlink_options):
    vehicle = SimulatedVehicle(f"udpout:127.0.0.1:{port}", VehicleConfig(
        signing_key=bytes.fromhex(vehicle_key) if vehicle_key else None))
    driver = MavlinkDriver(test_profile(mavlink={"target_system": 1, "target_component": 1,
                                                 "signing_key": driver_key, **mavlink_options}),
                           url=f"udpin:127.0.0.1:{port}", handle_signals=False)
    return vehicle, driver


def test_signed_link_drives_the_simulated_vehicle(port):
    vehicle, driver = signed_pair(port, KEY_HEX, KEY_HEX)
    with vehicle, driver:
        driver.engage()
        driver.send(VelocityCommand(0.5, 0.0))
        assert wait_until(lambda: vehicle.state().v > 0.4, 5.0)
        assert driver._conn.mav.signing.goodsig_count > 0
        assert vehicle._conn.mav.signing.goodsig_count > 0
        assert driver.stats["bad_signature"] == 0 and vehicle.state().counters.get("bad_signature", 0) == 0


def test_a_wrong_signing_key_means_no_link(port):
    vehicle, driver = signed_pair(port, KEY_HEX, OTHER_KEY_HEX, heartbeat_wait_s=1.5)
    with vehicle:
        with pytest.raises(LinkError, match="signature"):
            driver.connect()
    assert vehicle.state().v == 0.0


def test_signing_on_refuses_an_unsigned_vehicle(port):
    vehicle, driver = signed_pair(port, None, KEY_HEX, heartbeat_wait_s=1.5)
    with vehicle:
        with pytest.raises(LinkError, match="signature"):
            driver.connect()


def test_unsigned_forged_position_is_refused_on_a_signed_link(port):
    vehicle, driver = signed_pair(port, KEY_HEX, KEY_HEX)
    with vehicle, driver:
        assert wait_until(lambda: driver.pose is not None, 5.0)
        # a peer with the vehicle's ids but no key: a forged pose to the driver, and a setpoint
        # (with the driver's ids) to the vehicle
        to_driver = mavutil.mavlink_connection(f"udpout:127.0.0.1:{port}", source_system=1, source_component=1)
        vehicle_port = vehicle._conn.port.getsockname()[1]
        to_vehicle = mavutil.mavlink_connection(f"udpout:127.0.0.1:{vehicle_port}", source_system=255,
                                                source_component=190)
        try:
            for _ in range(20):
                to_driver.mav.local_position_ned_send(0, 1000.0, 1000.0, 0.0, 0.0, 0.0, 0.0)
                to_vehicle.mav.command_long_send(1, 1, mavlink.MAV_CMD_COMPONENT_ARM_DISARM, 0, 1, 0, 0, 0, 0, 0, 0)
            assert wait_until(lambda: driver.stats["bad_signature"] >= 20, 5.0)
            assert wait_until(lambda: vehicle.state().counters.get("bad_signature", 0) >= 20, 5.0)
        finally:
            to_driver.close()
            to_vehicle.close()
        p = driver.pose
        assert math.hypot(p.x, p.y) < 0.1 and driver.stats["pose_jumps"] == 0
        assert driver.health().failsafe == FailsafeState.OK
        assert not vehicle.state().armed and driver.armed is False


def test_signing_key_file_is_read(tmp_path):
    key_file = tmp_path / "vehicle.key"
    key_file.write_text(KEY_HEX + "\n")
    profile = test_profile(mavlink={"signing_key_file": str(key_file)})
    assert profile.mavlink.secret_key() == bytes.fromhex(KEY_HEX)
    port = free_udp_port()
    with SimulatedVehicle(f"udpout:127.0.0.1:{port}", VehicleConfig(signing_key=bytes.fromhex(KEY_HEX))), \
            MavlinkDriver(profile, url=f"udpin:127.0.0.1:{port}", handle_signals=False) as driver:
        assert wait_until(lambda: driver.pose is not None, 5.0)
