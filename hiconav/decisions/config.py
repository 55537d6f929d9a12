"""decisions.*: every threshold of the mission's decisions, one typed field each.

The decision modules of ``hiconav/decisions/`` (frontier following, view planning, target
confirmation, approach) and the behaviours that poll them read their numbers from here, and
from nowhere else: each field has its default, its range and a one-line reason, and
``hiconav config --describe`` lists them. A mission tree may override a field for one node
(``Approach: {distance: 0.9}``), checked against the same field; the shipped trees set none, so
a ``--config`` file or ``--set decisions.approach.distance=0.9`` changes what the mission does.

Durations are seconds of robot time (``_d`` fields; ``robot_time_fields``): how long a robot
that makes one discrete action in ``ACTION_SECONDS`` (a 0.25 m step at 0.5 m/s, a 30 degree turn)
waits, drives or glances. The mission puts them on its clock (``DecisionsConfig.in_clock``): on
a robot one to one; on the simulator's clocks, where a driver tick (0.1 s at 10 Hz) carries a
whole action, at a fifth, so that a robot gives a frontier up after the same 150 actions of no
frontier as the simulator does. ``verify.recent_view_s`` is compared with the frames' own stamps,
which are robot time already.

The defaults were chosen on ProcTHOR train houses and the Gibson tune floors (README "Results").
This module holds data only.
"""

from __future__ import annotations

import functools
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from hiconav.limits import MAX_DURATION_S


def _f(default: Any, reason: str, ge: float | None = None, le: float | None = None, **kw: Any) -> Any:
    """A field with its default, its inclusive range and its one-line reason."""
    return Field(default, ge=ge, le=le, description=reason, **kw)


#: ``json_schema_extra`` of a duration in robot time (``_d``)
ROBOT_TIME = {"time": "robot"}


def _d(default: float, reason: str, ge: float | None = None, le: float | None = None) -> Any:
    """A duration in seconds of robot time (``DecisionsConfig.in_clock`` puts it on the mission's clock)."""
    return _f(default, f"{reason} (s of robot time)", ge, le, json_schema_extra=ROBOT_TIME)


@functools.lru_cache(maxsize=None)
def robot_time_fields(section: type[BaseModel]) -> frozenset[str]:
    """The fields of a settings section that are durations in robot time."""
    return frozenset(name for name, f in section.model_fields.items() if f.json_schema_extra == ROBOT_TIME)


class _Section(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)


class ParseSettings(_Section):
    """ParseInstruction: waiting for the reasoning layer's decomposition."""

    timeout_s: float = _d(300.0, "no task from the reasoning layer in this long: the mission fails", 0.0,
                          MAX_DURATION_S)


class TargetSettings(_Section):
    """TargetConfirmed: what makes a candidate worth verifying."""

    min_confidence: float = _f(0.0, "candidates scored below this are not taken up", 0.0, 1.0)
    min_observations: int = _f(1, "candidates observed fewer times are not taken up", 1, 1000)


class ExploreSettings(_Section):
    """Explore: following the WTRP order of frontiers (``hiconav.decisions.frontiers``)."""

    max_idle_s: float = _d(75.0, "no frontier for this long: exploration fails (the map is explored out)", 0.0,
                           MAX_DURATION_S)
    goal_tolerance: float = _f(0.3, "a frontier viewpoint is reached within this (m)", 0.05, 5.0)
    switch_distance: float = _f(0.5, "re-send a frontier goal whose viewpoint moved this far (m)", 0.0, 10.0)
    look_turns: int = _f(4, "quarter turns in place per spot when no frontier is known", 0, 100)
    look_spot_m: float = _f(1.0, "look_turns count anew once the robot is this far from where it last looked (m)",
                            0.0, 100.0)
    start_look_turns: int = _f(4, "quarter turns in place at the mission's start: the camera sees 79 degrees, "
                                  "so the start room is otherwise known in one direction only", 0, 100)
    spent_radius: float = _f(0.4, "a frontier viewpoint this near a reached one that did not clear its frontier "
                                  "is spent (m)", 0.0, 5.0)
    spent_after_s: float = _d(2.5, "judge a reached viewpoint on plans made this long after the visit", 0.0, 60.0)
    push_through: bool = _f(True, "drive once into a nearby frontier whose viewpoint did not clear it, as a "
                                  "person steps into a doorway")
    push_radius: float = _f(1.5, "push only into spent frontiers whose centroid is this near the robot (m)",
                            0.0, 10.0)
    push_m: float = _f(0.6, "the push goal lies this far beyond the centroid (m)", 0.0, 5.0)
    push_s: float = _d(30.0, "a push may take this long before it counts as blocked", 0.1, 3000.0)
    stall_s: float = _d(40.0, "a frontier goal the robot came no nearer to (by progress_m) for this long is "
                             "skipped: a passage the map shows open that the robot does not fit", 0.1, 600.0)
    stall_near: float = _f(0.35, "within this of a frontier goal the robot is arriving, not stalled (m)", 0.0, 5.0)
    progress_m: float = _f(0.25, "coming this much nearer a goal is progress (stall and idle clocks, m)",
                           0.01, 5.0)
    squeeze: bool = _f(True, "with every frontier failed, try each once more through unknown floor on the "
                             "navigator's thinner masks before giving up")
    unresolved_asks: int = _f(3, "explored out in search of a described instance, ask the reasoning layer this "
                                 "many times for its best unresolved candidate before failing", 0, 100)
    linger_turns: int = _f(4, "quarter turns in place beside an undecided instance of the target's category "
                              "that a described-instance search comes upon (hiconav.decisions.linger; 0: never)",
                           0, 100)
    linger_m: float = _f(1.5, "an instance within this of the robot's footprint distance is close enough to "
                              "linger by (m)", 0.0, 10.0)
    last_resort: bool = _f(True, "explored out with a candidate set aside only as out of reach (no view point or "
                                 "approach cell it could reach): stop as near the best of it as the map allows "
                                 "rather than fail (hiconav.decisions.last_resort)")


class VerifySettings(_Section):
    """VerifyTarget: where to stand to look at a candidate (``hiconav.decisions.viewing``) and what
    evidence confirms it (``hiconav.decisions.confirmation``)."""

    verify_distance: float = _f(1.5, "the candidate is judged from within this of its footprint (m)", 0.3, 10.0)
    view_margin: float = _f(0.35, "view cells lie this far inside verify_distance (m)", 0.0, 5.0)
    fov_spare_deg: float = _f(8.0, "the view ring is far enough for the candidate's centre to be this far inside "
                                   "the vertical field of view", 0.0, 45.0)
    max_view_ring: float = _f(4.0, "the view ring widens for high or low objects up to this (m)", 0.3, 20.0)
    from_here: bool = _f(True, "a robot already standing where a view cell would (within the view ring, the "
                               "candidate in sight) judges it from there instead of driving to a view cell")
    path_cost: bool = _f(True, "view cells are weighed by the length of the path to them on the robot's map, "
                               "not the straight line (a cell across a bed is a walk round it)")
    close_ring_gap: float = _f(0.35, "frames are judged from at least this beyond the view ring (m)", 0.0, 5.0)
    close_margin: float = _f(0.25, "frames are judged this far beyond verify_distance or the view ring, and a "
                                   "closer cell must lie beyond that less this (m)", 0.0, 5.0)
    stand_margin: float = _f(0.05, "objects whose footprint overlaps the candidate's grown by this hold it up or "
                                   "hang it and never hide it (m)", 0.0, 2.0)
    blocker_shrink: float = _f(0.05, "other objects' boxes shrink by this a side horizontally before they may "
                                     "hide the candidate: box edges are loose (m)", 0.0, 1.0)
    min_fresh_views: int = _f(2, "frames in view that observed the candidate needed to confirm it", 0, 100)
    recent_view_s: float = _f(600.0, "frames of a candidate the reasoning layer put forward, taken from within the "
                                     "view ring this long before its verification began (sensor time: the frames' "
                                     "stamps), count as its views; 600: any frame of a mission (0: only frames "
                                     "after it began)", 0.0, 600.0)
    min_detection_rate: float = _f(0.5, "fresh views per frame with the candidate in view needed to confirm it",
                                   0.0, 1.0)
    max_view_frames: int = _f(8, "frames in view after which a rarely detected candidate is rejected", 1, 10000)
    unseen_view_frames: int = _f(4, "frames in view without a single detection after which a candidate observed "
                                    "at most unseen_max_observations times is rejected", 1, 10000)
    unseen_max_observations: int = _f(2, "candidates observed more often get the full max_view_frames", 0, 10000)
    min_confidence: float = _f(0.3, "a confirmed candidate scored below this is deferred", 0.0, 1.0)
    confident_observations: int = _f(10, "nodes observed this often pass min_confidence: detectors score small "
                                         "objects low in every frame", 1, 100000)
    view_ray_weight: float = _f(2.0, "1 m nearer the line the candidate was seen along is worth this many m more "
                                     "to drive (0: no preference)", 0.0, 100.0)
    timeout_s: float = _d(300.0, "no verdict in this long: the candidate is deferred", 0.1, MAX_DURATION_S)
    support_margin: float = _f(0.15, "target-labelled nodes whose box overlaps the candidate's grown by this "
                                     "support it (m)", 0.0, 2.0)
    defer_s: float = _d(150.0, "a deferred candidate waits this long", 0.0, MAX_DURATION_S)
    max_deferrals: int = _f(2, "deferrals after which a candidate is rejected for good", 1, 100)
    flip_reads: int = _f(2, "a candidate whose node's vote flips to a look-alike while the robot judges it is judged "
                            "on, and deferred once this many fresh views read it so and none as a target (0: "
                            "deferred at the flip)", 0, 1000)
    reposition_after: int = _f(4, "frames that could not show the candidate before trying another view cell",
                               1, 1000)
    view_cells: int = _f(3, "view cells tried before the candidate is deferred as hidden", 1, 100)
    glance_deg: float = _f(35.0, "glances alternate this far left and right of facing the candidate", 0.0, 90.0)
    keyframe_every_s: float = _d(5.0, "while judging, the memory makes a frame an anchor this often (KeyframeRequest): "
                                      "a robot glancing from one spot crosses no anchor gate", 0.0, 300.0)
    keyframe_window_s: float = _d(10.0, "each keyframe request covers this long; renewed while judging", 0.1, 300.0)
    closer_moves: int = _f(2, "with no view cell on the map, drive toward the candidate this many times before "
                              "deferring it (0: defer at once)", 0, 100)
    closer_min_gain: float = _f(1.0, "a closer cell lies this much nearer the candidate's box than the robot (m)",
                                0.1, 10.0)
    closer_box_weight: float = _f(4.0, "for a closer cell, 1 m nearer the box is worth this many m more to drive",
                                  0.0, 100.0)
    unknown_moves: int = _f(1, "with no view cell reachable on the known map and no closer cell, head for a view "
                               "cell through unknown floor this many times before deferring (0: never)", 0, 100)
    unknown_min_observations: int = _f(3, "only candidates observed this often head through unknown floor: the "
                                          "way is a guess, not worth one for a one-frame box", 0, 100000)
    switch_margin: float = _f(1.0, "on the way to the candidate, verify instead a candidate that comes this much "
                                   "nearer the robot (m; 0: never switch)", 0.0, 100.0)
    max_switches: int = _f(3, "switches to a nearer candidate per verification: two candidates must not trade "
                              "places for ever", 0, 100)
    near_view_distance: float = _f(0.6, "a frame whose camera stood this near the candidate's box and detected "
                                        "the target's label without placing it in 3D (no depth that near) counts "
                                        "as a fresh view (0: never)", 0.0, 5.0)
    stall_s: float = _d(30.0, "a view cell the robot came no nearer to (by 0.25 m) for this long counts as failed",
                        0.1, 600.0)
    stall_near: float = _f(0.35, "within this of its view cell the robot is there, glancing about (m)", 0.0, 5.0)


class ApproachSettings(_Section):
    """Approach: the final ring, the straight-in step and the creep (``hiconav.decisions.approach``)."""

    distance: float = _f(0.9, "stop this near the target's box: 0.1 m inside the 1 m success distance for the "
                              "box's error", 0.1, 5.0)
    inner_margin: float = _f(0.0, "the first ring tried lies this far inside the distance (m)", 0.0, 5.0)
    settle_rings: list[float] = _f([1.0, 1.25, 1.5, 2.0], "wider rings to settle on, up to max_distance, when "
                                                           "furniture leaves no free cell within the distance")
    max_distance: float = _f(1.5, "settle this far at most when nothing closer is reachable (m)", 0.1, 5.0)
    settle_box_weight: float = _f(4.0, "on a ring wider than distance, 1 m nearer the object's box is worth this "
                                       "many m more to drive", 0.0, 100.0)
    centre_weight: float = _f(0.9, "1 m nearer the footprint's centre is worth this many m more to drive (below "
                                   "1: of the cells in line with the centre, the nearest)", 0.0, 100.0)
    facing_tolerance_deg: float = _f(35.0, "done only when facing the target within this", 1.0, 180.0)
    arrive_radius: float = _f(0.3, "done only this near the approach cell, when one was sent (m)", 0.0, 5.0)
    max_attempts: int = _f(4, "approach cells tried before the target is deferred", 1, 50)
    timeout_s: float = _d(600.0, "no arrival in this long: the target is deferred", 0.1, MAX_DURATION_S)
    defer_s: float = _d(150.0, "an unreachable target waits this long", 0.0, MAX_DURATION_S)
    creep: bool = _f(True, "settled beyond the distance: creep toward the object through floor the map does not "
                           "know before stopping")
    creep_s: float = _d(15.0, "a creep may take this long (blocked by clutter it would rock on)", 0.1, 3000.0)
    corner_radius: float = _f(0.3, "the robot's distance to the target is measured to its box with the corners rounded "
                              "by this (m, at most half the shorter side): most objects leave their box's corners "
                              "empty, so off a corner the object lies farther than the box (0: the box)", 0.0, 5.0)
    path_cost: bool = _f(True, "approach cells are weighed by the length of the path to them on the robot's "
                               "map, not the straight line (a cell across a table is a walk round it)")
    measure: Literal["box", "points"] = _f("box", "how far the robot is from the object: its memory box, or a "
                                                  "low quantile of its points' planar distances ('points')")
    points_quantile: float = _f(0.02, "with measure 'points', a node's points nearer than this quantile are its "
                                      "noise", 0.0, 0.5)
    straight_within: float = _f(0.5, "this little beyond the distance, step straight in toward the box when the "
                                     "way and the view from the ring are clear (0: always a ring cell)", 0.0, 5.0)
    stall_s: float = _d(30.0, "an approach cell the robot came no nearer to (by 0.25 m) for this long counts as "
                             "failed", 0.1, 600.0)
    min_ring: float = _f(0.2, "no ring for an approach cell lies nearer the footprint than this (m)", 0.0, 5.0)
    second_margin: float = _f(0.1, "a second ring lies at most this far inside the distance (m)", 0.0, 5.0)
    strict_within: float = _f(1.0, "on the rings out to this, cells that see the footprint past every wall are "
                                   "tried first (m; the success distance)", 0.0, 5.0)
    creep_within: float = _f(1.0, "reached a cell of a ring out to this short of the ring: creep on rather than "
                                  "drive to another cell (m)", 0.0, 5.0)
    straight_step: float = _f(0.25, "the straight way in is checked this far past the ring: a step may end up to a "
                                    "step inside it (the robot's forward step, m)", 0.0, 2.0)
    min_points: int = _f(10, "with measure 'points', a node with fewer points is measured by its box", 1, 100000)
    face_tolerance: float = _f(0.5, "the turn in place toward the target counts as reached this near where the "
                                    "robot stands (m)", 0.0, 5.0)
    last_resort_m: float = _f(3.0, "a last resort (explore.last_resort) settles on rings out to this from the "
                                   "footprint, else stops where it stands facing the target (m)", 0.0, 20.0)


class ReturnSettings(_Section):
    """ReturnToStart: going back to the pose where the mission started."""

    tolerance: float = _f(0.5, "back at the start within this (m)", 0.05, 5.0)
    timeout_s: float = _d(1500.0, "not back in this long: the behaviour fails", 0.1, MAX_DURATION_S)


class DecisionsConfig(BaseModel):
    """decisions.*: one section per decision (each behaviour names the section it reads)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False, frozen=True)

    parse: ParseSettings = Field(default_factory=ParseSettings)
    target: TargetSettings = Field(default_factory=TargetSettings)
    explore: ExploreSettings = Field(default_factory=ExploreSettings)
    verify: VerifySettings = Field(default_factory=VerifySettings)
    approach: ApproachSettings = Field(default_factory=ApproachSettings)
    return_home: ReturnSettings = Field(default_factory=ReturnSettings)

    def in_clock(self, scale: float) -> DecisionsConfig:
        """This configuration with each duration in robot time (``robot_time_fields``) times
        ``scale``, the mission clock's seconds per second of robot time (1 on a robot; on the
        simulator's clocks, where one driver tick carries a whole discrete action,
        ``hiconav.mission.stepped_time_scale``)."""
        if scale == 1.0:
            return self
        sections = {}
        for name in type(self).model_fields:
            section = getattr(self, name)
            fields = robot_time_fields(type(section))
            sections[name] = section.model_copy(update={k: getattr(section, k) * scale for k in fields})
        return self.model_copy(update=sections)


__all__ = ["ROBOT_TIME", "ApproachSettings", "DecisionsConfig", "ExploreSettings", "ParseSettings", "ReturnSettings",
           "TargetSettings", "VerifySettings", "robot_time_fields"]
