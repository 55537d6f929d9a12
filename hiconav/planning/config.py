"""Settings of the planning area (global A*, local planner, discrete actions, recovery). Data only."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field

from hiconav.limits import MAX_DURATION_S


class LocalPlannerConfig(BaseModel):
    """planning.local.*: pure-pursuit velocity commands."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    lookahead_m: float = Field(0.5, gt=0.0, description="pure-pursuit lookahead distance")
    v_max: float = Field(0.5, gt=0.0, description="max forward speed (m/s)")
    omega_max: float = Field(1.2, gt=0.0, description="max yaw rate (rad/s)")
    accel_max: float = Field(1.0, gt=0.0, description="max forward acceleration (m/s^2)")
    rotate_in_place_deg: float = Field(
        45.0, gt=0.0, le=180.0, description="turn on the spot above this heading error"
    )
    heading_gain: float = Field(2.0, gt=0.0, description="omega = gain * error when rotating in place")
    slow_down_m: float = Field(
        0.5, ge=0.0, description="ramp the speed down inside this distance to the goal"
    )


class DiscreteConfig(BaseModel):
    """planning.discrete.*: velocity-free Habitat-style actions."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    turn_tolerance_deg: float = Field(15.0, gt=0.0, description="turn until the heading error is below this")
    forward_tolerance_deg: float = Field(
        35.0, gt=0.0, le=90.0,
        description="keep going forward up to this heading error while the step stays clear and near the path "
        "(a turn costs a whole step; without this the robot zig-zags left-forward-right-forward)",
    )
    forward_step_m: float = Field(0.25, gt=0.0)
    turn_deg: float = Field(30.0, gt=0.0)
    lookahead_m: float = Field(0.4, gt=0.0, description="steer toward the path point this far ahead")


class NavigatorConfig(BaseModel):
    """planning.*: the Navigator (A* + local planner + recovery)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    window_margin_m: float = Field(3.0, ge=0.0, description="A* first searches the start-goal box plus this")
    plan_through_unknown: bool = Field(False, description="let A* cross unknown cells")
    goal_snap_m: float = Field(
        1.0, ge=0.0, description="a blocked goal moves to the nearest free cell within this"
    )
    tight_fallback: bool = Field(
        True, description="when no path keeps the inflation margin, plan through passages only the robot radius clears"
    )
    squeeze_fallback: bool = Field(
        True, description="a goal through unknown floor (a push into a frontier, a creep) that no path reaches "
        "on the lethal layer plans once more on it shrunk by one cell"
    )
    trail_free: bool = Field(
        True, description="cells the robot centre has passed through are traversable (it stood there), "
        "even where the map's inflation closes them"
    )
    settle_steps: int = Field(
        10, ge=1, description="discrete: within settle_m of the goal (or of its snapped path end), this many steps "
        "without coming 2 cm nearer count as reached (a robot stepping 0.25 m can circle a goal that lies "
        "between two of its positions)"
    )
    settle_m: float = Field(0.3, ge=0.0, description="see settle_steps")
    replan_every: int = Field(10, ge=1, description="re-plan at least every n steps")
    deviation_m: float = Field(0.5, gt=0.0, description="re-plan when this far from the path")
    stuck_progress_m: float = Field(0.05, ge=0.0, description="velocity mode: moving less than twice this in "
                                                              "stuck_time_s is stuck")
    forward_blocked_m: float = Field(
        0.1, ge=0.0, description="discrete mode: a forward step that moved the robot (or brought a straight goal "
                                 "nearer) by less than this was blocked; a blocked step slides along the obstacle "
                                 "a few centimetres"
    )
    stuck_limit: int = Field(2, ge=1, description="stuck steps in a row before a recovery")
    virtual_obstacle_m: float = Field(
        0.15, ge=0.0, description="radius of the obstacle placed where the robot got stuck"
    )
    recovery_turns: int = Field(3, ge=1, description="discrete turns of a recovery (3 x 30 deg)")
    max_recoveries: int = Field(
        3, ge=0, description="recoveries for one goal within give_up_m of each other before the goal fails "
                             "(status 'stuck'; 0: never give up)"
    )
    give_up_m: float = Field(0.5, ge=0.0, description="see max_recoveries")
    back_off_s: float = Field(1.0, ge=0.0, le=MAX_DURATION_S, description="velocity mode: back off this long when stuck")
    back_off_speed: float = Field(0.15, ge=0.0)
    stuck_time_s: float = Field(2.0, gt=0.0, le=MAX_DURATION_S, description="velocity mode: no progress this long is stuck")
    local: LocalPlannerConfig = Field(default_factory=LocalPlannerConfig)
    discrete: DiscreteConfig = Field(default_factory=DiscreteConfig)
