"""RecorderActor: writes a mission to Rerun (an .rrd file, or a live viewer with ``spawn=True``).

A node like the others: it receives copies of the messages (observations, world snapshots,
exploration plans, hypotheses, tree status, reasoning events) and logs them on the mission clock
(timeline "clock", virtual seconds in stepped mode) and on the "step" timeline:

- ``camera/rgb`` with ``camera/rgb/detections`` (2D boxes and labels), ``camera/depth``;
- ``map``: the occupancy grid (north up), ``map/frontiers`` coloured by utility, ``map/wtrp``
  (the WTRP visiting order as a path from the robot), ``map/robot`` and ``map/path``;
- ``world/objects`` (memory graph object nodes as 3D boxes) and ``world/anchors`` (anchor poses);
- ``tree`` (status and tip per tick), ``reasoning`` (prompts, replies, latency).

A blueprint lays these out. The recorder never sends anything and never blocks the others
(in real time it is an actor of its own; its mailbox is latest-wins for frames and snapshots).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from hiconav.actors.node import Node
from hiconav.actors.runtime import NodeActor

from hiconav.errors import HiconavError
from hiconav.messages import EpisodeEnded, HypothesisMsg, Observation, PlanMsg, TreeStatus, WorldSnapshot


class RecorderActor(NodeActor):
    """pykka actor of the Rerun recorder."""


def _grid_image(grid: Any) -> np.ndarray:
    state = np.asarray(grid.state)
    img = np.full(state.shape + (3,), 60, dtype=np.uint8)
    img[state == 0] = (225, 225, 225)
    img[state == 1] = (30, 30, 30)
    if getattr(grid, "inflated", None) is not None:
        infl = np.asarray(grid.inflated) & (state != 1)
        img[infl] = (170, 150, 150)
    return img[::-1].copy()  # row 0 is the southern edge: flip so that north is up


def _utility_colors(values: np.ndarray) -> np.ndarray:
    v = np.asarray(values, dtype=np.float64)
    if v.size == 0:
        return np.zeros((0, 3), dtype=np.uint8)
    lo, hi = float(np.min(v)), float(np.max(v))
    t = (v - lo) / (hi - lo) if hi > lo else np.ones_like(v)
    return np.stack([255 * t, 80 + 100 * (1 - t), 255 * (1 - t)], axis=1).astype(np.uint8)


def blueprint() -> Any:
    import rerun.blueprint as rrb

    return rrb.Blueprint(
        rrb.Horizontal(
            rrb.Vertical(rrb.Spatial2DView(name="camera", origin="camera/rgb"),
                         rrb.Spatial2DView(name="depth", origin="camera/depth")),
            rrb.Spatial2DView(name="map (frontiers by utility, WTRP order)", origin="map"),
            rrb.Vertical(rrb.Spatial3DView(name="memory graph", origin="world"),
                         rrb.TextLogView(name="mission tree", origin="tree"),
                         rrb.TextLogView(name="reasoning", origin="reasoning")),
            column_shares=[1, 1, 1],
        ),
        collapse_panels=True,
    )


class RecorderNode(Node):
    name = "recorder"
    actor_class = RecorderActor

    def __init__(self, path: str | Path | None = None, *, spawn: bool = False, rate_hz: float = 10.0,
                 image_every: int = 1, depth_every: int = 5, jpeg_quality: int = 70) -> None:
        super().__init__(rate_hz)
        self.path = None if path is None else Path(path)
        self.spawn = spawn
        self.image_every = max(1, image_every)
        self.depth_every = max(1, depth_every)
        self.jpeg_quality = jpeg_quality
        self.rec: Any = None
        self.trajectory: list[tuple[float, float]] = []
        self._n_obs = 0
        self._tree_last: tuple[str, str] | None = None
        self.latest_wins(Observation, WorldSnapshot, PlanMsg)
        self._queue: list[Any] = []
        for t in (TreeStatus, HypothesisMsg, EpisodeEnded):
            self.on(t, lambda m, now: self._queue.append(m))

    def start(self, now: float) -> None:
        import rerun as rr

        self.rr = rr
        self.rec = rr.RecordingStream("hiconav_mission")
        if self.path is not None:
            if not self.path.parent.exists():
                raise HiconavError(f"folder {self.path.parent} does not exist", field="record")
            self.rec.save(str(self.path), default_blueprint=blueprint())
        if self.spawn:
            self.rec.spawn(default_blueprint=blueprint())
        self.rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)

    def stop(self, now: float) -> None:
        if self.rec is not None:
            self.tick(now)
            self.rec.flush()
            if hasattr(self.rec, "disconnect"):
                self.rec.disconnect()

    def log_text(self, entity: str, text: str, now: float, level: str = "INFO") -> None:
        if self.rec is None:
            return
        self.rec.set_time("clock", duration=float(now))
        self.rec.log(entity, self.rr.TextLog(text, level=level))

    def tick(self, now: float) -> None:
        if self.rec is None:
            return
        rr, rec = self.rr, self.rec
        rec.set_time("clock", duration=float(now))
        obs: Observation | None = self.take(Observation)
        if obs is not None:
            self._n_obs += 1
            f = obs.frame
            rec.set_time("step", sequence=int(f.seq))
            if self._n_obs % self.image_every == 0:
                rec.log("camera/rgb", rr.Image(np.asarray(f.rgb)).compress(jpeg_quality=self.jpeg_quality))
                if obs.detections:
                    boxes = np.stack([np.asarray(d.box_xyxy, dtype=np.float32) for d in obs.detections])
                    labels = [f"{d.label} {d.score:.2f}" for d in obs.detections]
                    rec.log("camera/rgb/detections", rr.Boxes2D(array=boxes, array_format=rr.Box2DFormat.XYXY,
                                                                 labels=labels))
                else:
                    rec.log("camera/rgb/detections", rr.Clear(recursive=False))
            if self._n_obs % self.depth_every == 0:
                depth = np.nan_to_num(np.asarray(f.depth, dtype=np.float32), nan=0.0)
                rec.log("camera/depth", rr.DepthImage(depth[::2, ::2], meter=1.0))
        snap: WorldSnapshot | None = self.take(WorldSnapshot)
        plan: PlanMsg | None = self.take(PlanMsg)
        if snap is not None:
            self._log_world(snap, plan)
        for msg in self._queue:
            if isinstance(msg, TreeStatus):
                key = (msg.status, msg.tip)
                if key != self._tree_last:
                    rec.log("tree", rr.TextLog(f"tick {msg.tick}: {msg.status} at {msg.tip}",
                                               level="INFO" if msg.status == "RUNNING" else "WARN"))
                    self._tree_last = key
                if msg.ascii:
                    rec.log("tree/ascii", rr.TextDocument(msg.ascii))
            elif isinstance(msg, HypothesisMsg):
                h = msg.hypothesis
                rec.log("reasoning", rr.TextLog(
                    f"hypothesis ({getattr(h, 'source', '?')}) anchor {h.anchor_id} object {h.object_id} "
                    f"conf {h.confidence:.2f} latency {msg.stamp - msg.requested:.2f}s: {h.evidence}"))
            elif isinstance(msg, EpisodeEnded):
                rec.log("tree", rr.TextLog(f"episode ended: {msg.reason} after {msg.steps} steps", level="WARN"))
        self._queue.clear()

    def _px(self, grid: Any, xy: np.ndarray) -> np.ndarray:
        xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
        col = (xy[:, 0] - grid.origin[0]) / grid.resolution
        row = (xy[:, 1] - grid.origin[1]) / grid.resolution
        return np.stack([col, np.asarray(grid.state).shape[0] - row], axis=1)

    def _log_world(self, snap: WorldSnapshot, plan: PlanMsg | None) -> None:
        rr, rec = self.rr, self.rec
        grid = snap.grid
        pose = snap.pose
        self.trajectory.append((pose.x, pose.y))
        rec.log("map", rr.Image(_grid_image(grid)))
        rec.log("map/path", rr.LineStrips2D([self._px(grid, np.asarray(self.trajectory))], colors=[(40, 160, 40)]))
        heading = np.array([[pose.x, pose.y], [pose.x + 0.5 * np.cos(pose.yaw), pose.y + 0.5 * np.sin(pose.yaw)]])
        rec.log("map/robot", rr.LineStrips2D([self._px(grid, heading)], colors=[(220, 40, 40)], radii=1.5))
        if plan is not None and plan.frontiers:
            pts = np.stack([np.asarray(f.viewpoint, dtype=np.float64) for f in plan.frontiers])
            util = getattr(plan.plan, "utilities", None)
            if isinstance(util, dict):  # frontier id -> utility
                values = np.array([float(util.get(f.id, 0.0)) for f in plan.frontiers])
            elif util is not None and len(util) == len(pts):
                values = np.asarray(util, dtype=np.float64)
            else:
                values = np.zeros(len(pts))
            rec.log("map/frontiers", rr.Points2D(self._px(grid, pts), colors=_utility_colors(values), radii=3.0,
                                                 labels=[str(f.id) for f in plan.frontiers]))
            by_id = {f.id: np.asarray(f.viewpoint, dtype=np.float64) for f in plan.frontiers}
            order = [by_id[i] for i in getattr(plan.plan, "order", ()) if i in by_id]
            if order:
                route = np.vstack([[pose.x, pose.y], *order])
                rec.log("map/wtrp", rr.LineStrips2D([self._px(grid, route)], colors=[(250, 170, 0)]))
        memory = snap.memory
        if memory is not None and getattr(memory, "objects", None):
            objs = memory.objects
            mins = np.stack([np.asarray(o.box_min, dtype=np.float32) for o in objs])
            maxs = np.stack([np.asarray(o.box_max, dtype=np.float32) for o in objs])
            rec.log("world/objects", rr.Boxes3D(centers=(mins + maxs) / 2, sizes=np.maximum(maxs - mins, 0.01),
                                                labels=[f"{o.label}#{o.id}" for o in objs]))
        if memory is not None and getattr(memory, "anchors", None):
            pos = np.array([[a.base_pose.x, a.base_pose.y, 0.88] for a in memory.anchors], dtype=np.float32)
            rec.log("world/anchors", rr.Points3D(pos, radii=0.08, colors=[(250, 200, 0)],
                                                 labels=[f"anchor {a.id}" for a in memory.anchors]))
        rec.log("world/robot", rr.Points3D([[pose.x, pose.y, 0.2]], radii=0.18, colors=[(220, 40, 40)]))
