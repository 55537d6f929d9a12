"""Shared value types of hiconav: poses, camera, frames, detections, goals, commands.

Everything here is a frozen dataclass so that it can cross actor boundaries without copies or
locks. Arrays stored in these types are made read-only on construction (``freeze``); code that
needs to modify one must copy it first. This module must not import anything heavier than numpy.

Frames and conventions (used everywhere in the project):
- World frame: x east, y north, z up (metres), REP-103. The floor is z = 0.
- Robot base: Pose2D (x, y, yaw) in the world frame, yaw counter-clockwise from +x (radians).
- Camera frame: OpenCV (x right, y down, z forward). ``Frame.T_world_cam`` maps camera-frame
  points to the world frame (4x4, float64).
- Grids: cell (row i, col j) covers x in [ox + j*res, ox + (j+1)*res), y in [oy + i*res, ...).
"""

from __future__ import annotations

import enum
import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from hiconav.errors import FrameError


def freeze(array: np.ndarray | None) -> np.ndarray | None:
    """Return ``array`` marked read-only (no copy) so it can be shared between threads."""
    if array is None:
        return None
    array = np.asarray(array)
    if array.flags.writeable:
        array.flags.writeable = False
    return array


def _finite(value: Any) -> bool:
    try:
        return math.isfinite(float(value))
    except (TypeError, ValueError):
        return False


def check_intrinsics(k: Any, where: str = "intrinsics") -> None:
    """Raise ``FrameError`` naming the field unless ``k`` has a positive whole width and height,
    finite positive focal lengths and a finite principal point (a zero or NaN focal length would
    put non-finite points into every map and object built from the frame)."""
    for name in ("width", "height"):
        v = getattr(k, name, None)
        if not (_finite(v) and float(v) > 0 and float(v).is_integer()):
            raise FrameError(f"{name} must be a positive whole number of pixels, got {v!r}", field=f"{where}.{name}")
    for name in ("fx", "fy"):
        v = getattr(k, name, None)
        if not (_finite(v) and float(v) > 0):
            raise FrameError(f"focal length {name} must be finite and > 0 pixels, got {v!r}", field=f"{where}.{name}")
    for name in ("cx", "cy"):
        v = getattr(k, name, None)
        if not _finite(v):
            raise FrameError(f"principal point {name} must be finite, got {v!r}", field=f"{where}.{name}")


@functools.lru_cache(maxsize=8192)
def label_key(label: str) -> str:
    """The key two labels are compared by: lowercase snake case, spaces and hyphens as
    underscores, runs of them as one ("Floor Lamp", "floor-lamp", "floor_lamp" -> "floor_lamp").

    Every label comparison in the core (memory, exploration, reasoning) goes through this one
    rule, so that a label the detector wrote and a word the decomposition read meet. Synonyms
    ("couch" -> "sofa") are the detector's business (``hiconav.perception.detector.normalise_label``),
    not the comparison's. Memoised: called for every object on every scoring pass.
    """
    return "_".join(label.strip().lower().replace("-", " ").replace("_", " ").split())


def wrap_angle(angle: float) -> float:
    """Wrap an angle to [-pi, pi)."""
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


@dataclass(frozen=True)
class Pose2D:
    """Robot base pose in the world frame: position (m) and yaw (rad, CCW from +x)."""

    x: float
    y: float
    yaw: float

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y], dtype=np.float64)

    def distance_to(self, other: Pose2D) -> float:
        return math.hypot(other.x - self.x, other.y - self.y)


@dataclass(frozen=True)
class CameraIntrinsics:
    """Pinhole intrinsics of a (width x height) image; ``K`` is the 3x3 matrix."""

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float

    def __post_init__(self) -> None:
        check_intrinsics(self)

    @staticmethod
    def from_hfov(width: int, height: int, hfov_deg: float) -> CameraIntrinsics:
        """Square pixels with the given horizontal field of view (Habitat's convention)."""
        fx = (width / 2.0) / math.tan(math.radians(hfov_deg) / 2.0)
        return CameraIntrinsics(width, height, fx, fx, width / 2.0, height / 2.0)

    @property
    def K(self) -> np.ndarray:
        return np.array([[self.fx, 0, self.cx], [0, self.fy, self.cy], [0, 0, 1]], dtype=np.float64)

    @property
    def hfov(self) -> float:
        """Horizontal field of view in radians."""
        return 2.0 * math.atan2(self.width / 2.0, self.fx)


def camera_pose_from_base(base: Pose2D, height: float, tilt: float = 0.0) -> np.ndarray:
    """T_world_cam (4x4) of a forward-looking camera at ``height`` m above the base.

    ``tilt`` is the pitch in radians, positive looking up. The camera's optical axis (+z_cam)
    points along the base yaw; +x_cam points to the robot's right; +y_cam points down.
    """
    c, s = math.cos(base.yaw), math.sin(base.yaw)
    forward = np.array([c, s, 0.0])
    right = np.array([s, -c, 0.0])
    up = np.array([0.0, 0.0, 1.0])
    ct, st = math.cos(tilt), math.sin(tilt)
    z_cam = ct * forward + st * up
    y_cam = -(ct * up - st * forward)
    x_cam = right
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2] = x_cam, y_cam, z_cam
    T[:3, 3] = [base.x, base.y, height]
    return T


@dataclass(frozen=True)
class Frame:
    """One RGB-D observation.

    rgb: (H, W, 3) uint8 (or float in [0, 1]); depth: (H, W) float32 metres along the optical
    axis (0 or NaN = no return); instances: (H, W) int32 ground-truth instance ids (simulator
    only, -1 = none; only the oracle detector may read it). T_world_cam: (4, 4) float64
    camera-to-world.

    Checked where it enters (``FrameError`` naming the field, see ``check_frame``): rgb (H, W, 3)
    of the depth's (H, W), uint8 or finite float in [0, 1]; intrinsics (``check_intrinsics``);
    T_world_cam (4, 4) finite; base pose and stamp finite. A field given as None is left to the
    consumer that needs it (the grid names a missing depth or pose); depth values are not checked
    here (NaN / inf / <= 0 mean "no return" and are masked by the consumers, counted).
    """

    rgb: np.ndarray
    depth: np.ndarray
    intrinsics: CameraIntrinsics
    T_world_cam: np.ndarray
    base_pose: Pose2D
    stamp: float
    instances: np.ndarray | None = None
    seq: int = 0

    def __post_init__(self) -> None:
        check_frame(self)
        for name in ("rgb", "depth", "T_world_cam", "instances"):
            freeze(getattr(self, name))


def check_frame(frame: Frame, where: str = "frame") -> None:
    """Raise ``FrameError`` naming the field of the first thing wrong with ``frame`` (see ``Frame``)."""
    depth = None if frame.depth is None else np.asarray(frame.depth)
    if frame.rgb is not None:
        rgb = np.asarray(frame.rgb)
        if rgb.ndim != 3 or rgb.shape[2] != 3:
            raise FrameError(f"rgb has shape {rgb.shape}, expected (H, W, 3)", field=f"{where}.rgb")
        if depth is not None and depth.ndim == 2 and rgb.shape[:2] != depth.shape:
            raise FrameError(f"rgb is {rgb.shape[:2]} pixels but depth is {depth.shape}: they must match",
                             field=f"{where}.rgb")
        if rgb.dtype != np.uint8:
            if not np.issubdtype(rgb.dtype, np.floating):
                raise FrameError(f"rgb has dtype {rgb.dtype}, expected uint8 (or float in [0, 1])",
                                 field=f"{where}.rgb")
            if rgb.size and not (np.all(np.isfinite(rgb)) and float(rgb.min()) >= 0.0 and float(rgb.max()) <= 1.0):
                raise FrameError("float rgb must be finite and in [0, 1]", field=f"{where}.rgb")
    if frame.intrinsics is not None:
        check_intrinsics(frame.intrinsics, f"{where}.intrinsics")
    if frame.T_world_cam is not None:
        T = np.asarray(frame.T_world_cam)
        if T.shape != (4, 4) or not np.issubdtype(T.dtype, np.number) or not np.all(np.isfinite(T)):
            raise FrameError(f"T_world_cam must be a finite (4, 4) matrix, got shape {T.shape}",
                             field=f"{where}.T_world_cam")
    bp = frame.base_pose
    if bp is not None:
        for name in ("x", "y", "yaw"):
            if not _finite(getattr(bp, name, None)):
                raise FrameError(f"base pose {name} is not finite: {bp}", field=f"{where}.base_pose.{name}")
    if not _finite(frame.stamp):
        raise FrameError(f"stamp must be a finite time in seconds, got {frame.stamp!r}", field=f"{where}.stamp")


@dataclass(frozen=True)
class Detection:
    """One detected object in an image.

    box_xyxy: (4,) float pixels; mask: (H, W) bool or None; embedding: (D,) float32 or None.
    ``source`` names the detector ("oracle", "owlvit", ...) so fallbacks stay visible.
    """

    label: str
    score: float
    box_xyxy: np.ndarray
    mask: np.ndarray | None = None
    embedding: np.ndarray | None = None
    source: str = "unknown"
    instance_id: int | None = None  # oracle only: the simulator's instance, for diagnostics

    def __post_init__(self) -> None:
        freeze(self.box_xyxy)
        freeze(self.mask)
        freeze(self.embedding)


class DiscreteAction(enum.Enum):
    """Habitat-style discrete actions."""

    STOP = "stop"
    MOVE_FORWARD = "move_forward"
    TURN_LEFT = "turn_left"
    TURN_RIGHT = "turn_right"
    LOOK_UP = "look_up"
    LOOK_DOWN = "look_down"


@dataclass(frozen=True)
class VelocityCommand:
    """Body-frame velocity: v forward (m/s), omega yaw rate (rad/s, CCW positive)."""

    v: float
    omega: float
    stamp: float = 0.0

    @staticmethod
    def zero(stamp: float = 0.0) -> VelocityCommand:
        return VelocityCommand(0.0, 0.0, stamp)


@dataclass(frozen=True)
class Goal:
    """A navigation goal for the control layer: a world position, optional facing yaw."""

    x: float
    y: float
    yaw: float | None = None
    tolerance: float = 0.25
    kind: str = "frontier"  # "frontier" | "object" | "approach"
    ref_id: int | None = None  # frontier id or object node id
    # the path may cross unknown cells: the last short creep toward an object whose nearby floor
    # the camera never saw (it sees no floor nearer than ~1.4 m; see ``Approach``)
    through_unknown: bool = False
    # drive straight at the point without a plan (discrete control), until within the tolerance,
    # half a step from it, or a forward step is blocked: the last centimetres of a creep, where the
    # map's cells and margins are coarser than the gap left (see ``Navigator``)
    straight: bool = False

    @property
    def xy(self) -> np.ndarray:
        return np.array([self.x, self.y], dtype=np.float64)


@dataclass(frozen=True)
class Frontier:
    """A frontier cluster: free cells next to unknown space.

    centroid / viewpoint: (2,) world metres; cells: (N, 2) int (row, col) grid cells.
    ``viewpoint`` is a reachable free cell from which to observe the frontier.
    """

    id: int
    centroid: np.ndarray
    viewpoint: np.ndarray
    size: int
    cells: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=np.int32))

    def __post_init__(self) -> None:
        freeze(self.centroid)
        freeze(self.viewpoint)
        freeze(self.cells)


@dataclass(frozen=True)
class TaskSpec:
    """The decomposed instruction: target objects O_t and related objects O_r."""

    instruction: str
    targets: tuple[str, ...]
    related: tuple[str, ...] = ()
    attributes: dict[str, tuple[str, ...]] = field(default_factory=dict)
    relations: tuple[tuple[str, str, str], ...] = ()  # (subject, relation, object)
    source: str = "offline"  # "offline" | "vlm"

    def to_json(self) -> dict[str, Any]:
        return {
            "instruction": self.instruction,
            "targets": list(self.targets),
            "related": list(self.related),
            "attributes": {k: list(v) for k, v in self.attributes.items()},
            "relations": [list(r) for r in self.relations],
            "source": self.source,
        }
