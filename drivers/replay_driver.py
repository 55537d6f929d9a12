"""Recorded runs: ``FrameRecorder`` writes frames to a folder, ``ReplayDriver`` plays them back
through the ``Driver`` protocol for offline debugging, ``ReplayFrameSource`` serves them to a
real-robot driver.

Folder format (version 1): ``index.json`` = ``{"version": 1, "frames": [{"file", "seq",
"stamp", "pose": [x, y, yaw], "intrinsics": {width, height, fx, fy, cx, cy}}]}`` and one
``frame_NNNNNN.npz`` per frame with ``rgb`` (H, W, 3) uint8, ``depth`` (H, W) float32 m,
``T_world_cam`` (4, 4) float64 and, when recorded in the simulator, ``instances`` (H, W) int32.

A replay cannot move anything: commands are logged (``ReplayDriver.commands``) and, in "step"
mode, each command advances to the next recorded frame, as a simulator step would.
"""

from __future__ import annotations

import json
import math
import os
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from hiconav.drivers.base import DRIVERS, DriverHealth, FailsafeState
from hiconav.drivers.profiles import RobotProfile

from hiconav.errors import DataError
from hiconav.types import CameraIntrinsics, DiscreteAction, Frame, Pose2D, VelocityCommand, wrap_angle

__all__ = ["FrameRecorder", "ReplayDriver", "ReplayFrameSource", "read_index"]

INDEX = "index.json"
VERSION = 1


class FrameRecorder:
    """Write frames to ``folder`` (created). ``compress`` trades speed for disk (np.savez_compressed)."""

    def __init__(self, folder: str | Path, *, compress: bool = False, flush_every: int = 20) -> None:
        self.folder = Path(folder)
        self.folder.mkdir(parents=True, exist_ok=True)
        self.compress = compress
        self.flush_every = flush_every
        self._entries: list[dict[str, Any]] = []
        self._lock = threading.Lock()

    def write(self, frame: Frame) -> Path:
        with self._lock:
            n = len(self._entries)
            name = f"frame_{n:06d}.npz"
            arrays = dict(rgb=np.asarray(frame.rgb), depth=np.asarray(frame.depth, dtype=np.float32),
                          T_world_cam=np.asarray(frame.T_world_cam, dtype=np.float64))
            if frame.instances is not None:
                arrays["instances"] = np.asarray(frame.instances, dtype=np.int32)
            (np.savez_compressed if self.compress else np.savez)(self.folder / name, **arrays)
            k = frame.intrinsics
            p = frame.base_pose
            self._entries.append({"file": name, "seq": int(frame.seq), "stamp": float(frame.stamp),
                                  "pose": [p.x, p.y, p.yaw],
                                  "intrinsics": {"width": k.width, "height": k.height, "fx": k.fx, "fy": k.fy,
                                                 "cx": k.cx, "cy": k.cy}})
            if len(self._entries) % self.flush_every == 0:
                self._flush()
            return self.folder / name

    def _flush(self) -> None:
        tmp = self.folder / (INDEX + ".tmp")
        tmp.write_text(json.dumps({"version": VERSION, "frames": self._entries}, indent=1))
        os.replace(tmp, self.folder / INDEX)

    def close(self) -> None:
        with self._lock:
            self._flush()

    def __enter__(self) -> FrameRecorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def read_index(folder: str | Path) -> list[dict[str, Any]]:
    """The validated frame entries of a recorded folder (DataError naming file and field)."""
    path = Path(folder) / INDEX
    if not path.is_file():
        raise DataError(f"no {INDEX} in {folder}: not a recorded folder", file=str(path))
    try:
        data = json.loads(path.read_text())
    except json.JSONDecodeError as exc:
        raise DataError(f"not valid JSON: {exc.msg}", file=str(path), line=exc.lineno) from None
    if not isinstance(data, dict) or data.get("version") != VERSION:
        raise DataError(f"unsupported recording version {data.get('version') if isinstance(data, dict) else None!r}; "
                        f"expected {VERSION}", file=str(path), field="version")
    frames = data.get("frames")
    if not isinstance(frames, list) or not frames:
        raise DataError("the recording holds no frames", file=str(path), field="frames")
    for i, entry in enumerate(frames):
        for key in ("file", "stamp", "pose", "intrinsics"):
            if key not in entry:
                raise DataError(f"frame entry lacks {key!r}", file=str(path), field=f"frames[{i}].{key}")
        if len(entry["pose"]) != 3:
            raise DataError("pose must be [x, y, yaw]", file=str(path), field=f"frames[{i}].pose")
    return frames


class _FrameStore:
    """Lazy loader of recorded frames with a small LRU cache."""

    def __init__(self, folder: str | Path, cache: int = 8) -> None:
        self.folder = Path(folder)
        self.entries = read_index(self.folder)
        self._cache: OrderedDict[int, Frame] = OrderedDict()
        self._size = cache
        self._lock = threading.Lock()

    def __len__(self) -> int:
        return len(self.entries)

    def load(self, i: int) -> Frame:
        with self._lock:
            if i in self._cache:
                self._cache.move_to_end(i)
                return self._cache[i]
        e = self.entries[i]
        path = self.folder / e["file"]
        try:
            with np.load(path) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, ValueError) as exc:
            raise DataError(f"cannot read recorded frame: {exc}", file=str(path)) from exc
        for key in ("rgb", "depth", "T_world_cam"):
            if key not in arrays:
                raise DataError(f"recorded frame lacks array {key!r}", file=str(path), field=key)
        frame = Frame(rgb=arrays["rgb"], depth=arrays["depth"], intrinsics=CameraIntrinsics(**e["intrinsics"]),
                      T_world_cam=arrays["T_world_cam"], base_pose=Pose2D(*map(float, e["pose"])),
                      stamp=float(e["stamp"]), instances=arrays.get("instances"), seq=int(e.get("seq", i)))
        with self._lock:
            self._cache[i] = frame
            while len(self._cache) > self._size:
                self._cache.popitem(last=False)
        return frame


class ReplayDriver:
    """Plays a recorded folder through the ``Driver`` protocol.

    mode "step": every ``send`` advances one frame (a recorded run replays action by action);
    mode "realtime": the frame shown is the one whose recorded stamp offset has elapsed on
    ``clock`` since the first ``latest_frame`` call. ``loop`` restarts at the end.
    """

    def __init__(self, folder: str | Path, profile: RobotProfile | None = None, *, mode: str = "step",
                 loop: bool = False, clock: Callable[[], float] = time.monotonic) -> None:
        if mode not in ("step", "realtime"):
            raise ValueError(f"mode must be 'step' or 'realtime', got {mode!r}")
        self.profile = profile
        self.store = _FrameStore(folder)
        self.mode = mode
        self.loop = loop
        self._clock = clock
        self._index = 0
        self._started: float | None = None
        self._finished = False
        self._closed = False
        self.commands: list[tuple[float, VelocityCommand | DiscreteAction]] = []
        stamps = [float(e["stamp"]) for e in self.store.entries]
        self._offsets = np.asarray(stamps) - stamps[0]

    def __len__(self) -> int:
        return len(self.store)

    @property
    def index(self) -> int:
        return self._index

    def latest_frame(self) -> Frame | None:
        if self._closed:
            return None
        if self.mode == "realtime":
            now = self._clock()
            if self._started is None:
                self._started = now
            elapsed = now - self._started
            span = float(self._offsets[-1])
            if self.loop and span > 0:
                elapsed = math.fmod(elapsed, span + 1e-9)
            i = int(np.searchsorted(self._offsets, elapsed, side="right") - 1)
            self._finished = not self.loop and elapsed > span
            self._index = max(0, min(i, len(self) - 1))
        return self.store.load(self._index)

    def send(self, command: VelocityCommand | DiscreteAction) -> None:
        self.commands.append((self._clock(), command))
        if self.mode == "step":
            if self._index + 1 < len(self):
                self._index += 1
            elif self.loop:
                self._index = 0
            else:
                self._finished = True

    def stop(self) -> None:
        self.commands.append((self._clock(), VelocityCommand.zero()))

    def health(self) -> DriverHealth:
        reason = "end of recording" if self._finished else f"replay frame {self._index + 1}/{len(self)}"
        return DriverHealth(link_ok=not self._closed, pose_age_s=0.0,
                            failsafe=FailsafeState.CLOSED if self._closed else FailsafeState.OK,
                            reason=reason, paused=self._finished or self._closed, stamp=self._clock())

    def close(self) -> None:
        self._closed = True


class ReplayFrameSource:
    """Recorded frames for a live driver: the frame recorded nearest to the asked pose
    (distance + 0.5 m per radian of yaw difference). The frame keeps its recorded pose and
    camera transform (the image belongs to them); only the stamp becomes the driver's."""

    def __init__(self, folder: str | Path) -> None:
        self.store = _FrameStore(folder)
        self._poses = np.array([e["pose"] for e in self.store.entries], dtype=np.float64)

    def frame_at(self, pose: Pose2D, stamp: float) -> Frame | None:
        d = np.hypot(self._poses[:, 0] - pose.x, self._poses[:, 1] - pose.y)
        dyaw = np.abs([wrap_angle(float(y) - pose.yaw) for y in self._poses[:, 2]])
        i = int(np.argmin(d + 0.5 * dyaw))
        import dataclasses

        return dataclasses.replace(self.store.load(i), stamp=stamp)


def _make_replay(profile: RobotProfile, **options: Any) -> ReplayDriver:
    folder = options.pop("folder", None) or profile.frames.path
    if not folder:
        raise DataError("the replay driver needs a recorded folder (frames.path or folder=)", field="frames.path")
    return ReplayDriver(folder, profile, **options)


DRIVERS.add("replay", _make_replay)
