"""The one house model of the simulator: rooms, walls, objects, render boxes, navigable grid.

Loaders (``procthor.py``, ``gibson.py``) convert each data set into this model; the renderer,
the agent, episodes and metrics only ever see this model. This module is pure geometry (numpy,
scipy.ndimage): it must not read files, render, or know about a data set's conventions.

Frames: world x east, y north, z up (metres, REP-103), floor at z = 0. Yaw is counter-clockwise
from +x (radians). Grid cell (row i, col j) covers x in [ox + j*res, ox + (j+1)*res) and
y in [oy + i*res, oy + (i+1)*res) (``hiconav.types`` convention).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from hiconav.geometry import GridFrame
from hiconav.types import freeze

# Instance id of everything that is not an object (walls, floor, ceiling, background).
NO_INSTANCE = -1


@dataclass(frozen=True)
class NavGrid(GridFrame):
    """Navigable floor at a fixed resolution (NOT inflated by the robot radius).

    navigable: (H, W) bool, True where the floor is free of walls and objects.
    origin: (2,) world xy (m) of the outer corner of cell (0, 0). resolution: m per cell.
    """

    navigable: np.ndarray
    origin: np.ndarray
    resolution: float = 0.05

    def __post_init__(self) -> None:
        freeze(self.navigable)
        freeze(self.origin)

    @property
    def shape(self) -> tuple[int, int]:
        return (int(self.navigable.shape[0]), int(self.navigable.shape[1]))


@dataclass(frozen=True)
class SimObject:
    """One object instance: an oriented 3D box.

    center: (3,) world metres (box centre); size: (3,) metres along the box's own x, y, z
    (z is vertical); yaw: rad, rotation of the box's x axis from world +x (CCW).
    ``category``: lowercase snake case (bed, sofa, chair, tv, plant, dining_table, ...);
    ``source_type``: the data set's own type name (e.g. ProcTHOR "HousePlant"); ``source_id``:
    the data set's own id of the instance (ProcTHOR's object "id", e.g. "Chair|2|3"; "" if none).
    """

    instance_id: int
    category: str
    center: np.ndarray
    size: np.ndarray
    yaw: float
    source_type: str
    parent_id: int | None = None
    default_size: bool = False  # True when the size is a fallback (Objaverse assets)
    source_id: str = ""

    def __post_init__(self) -> None:
        freeze(self.center)
        freeze(self.size)

    @property
    def bottom(self) -> float:
        return float(self.center[2] - self.size[2] / 2.0)

    @property
    def top(self) -> float:
        return float(self.center[2] + self.size[2] / 2.0)

    def corners_xy(self) -> np.ndarray:
        """(4, 2) world xy of the footprint corners (counter-clockwise)."""
        return box_corners_xy(self.center[:2], self.size[:2], self.yaw)

    def contains(self, points: np.ndarray) -> np.ndarray:
        """(N, 3) world points -> (N,) bool inside the oriented box."""
        p = np.asarray(points, dtype=np.float64) - self.center
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        lx = c * p[:, 0] + s * p[:, 1]
        ly = -s * p[:, 0] + c * p[:, 1]
        h = self.size / 2.0
        return (np.abs(lx) <= h[0]) & (np.abs(ly) <= h[1]) & (np.abs(p[:, 2]) <= h[2])


@dataclass(frozen=True)
class Room:
    """A room: id, type (Kitchen, LivingRoom, ...) and floor polygon (N, 2) world xy."""

    id: str
    room_type: str
    polygon: np.ndarray

    def __post_init__(self) -> None:
        freeze(self.polygon)


@dataclass(frozen=True)
class Box:
    """A render primitive: oriented box with a colour (RGB in [0, 1]) and an instance id.

    center: (3,) world m; size: (3,) m (x, y along yaw, z vertical); material: a name that
    selects the procedural texture ("wall", "floor", "object", ...).
    """

    center: tuple[float, float, float]
    size: tuple[float, float, float]
    yaw: float
    color: tuple[float, float, float]
    instance_id: int = NO_INSTANCE
    material: str = "object"


@dataclass(frozen=True)
class Wall:
    """A wall segment between ``start`` and ``end`` (world xy), from z = 0 to ``height``.

    holes: (t0, t1, z0, z1) rectangles in wall coordinates (distance along the wall from
    ``start``, height above the floor): doors (z0 == 0) and windows.
    """

    start: tuple[float, float]
    end: tuple[float, float]
    height: float
    thickness: float
    holes: tuple[tuple[float, float, float, float], ...] = ()
    color: tuple[float, float, float] = (0.85, 0.85, 0.82)
    ids: tuple[str, ...] = ()

    @property
    def length(self) -> float:
        return math.hypot(self.end[0] - self.start[0], self.end[1] - self.start[1])

    def boxes(self) -> list[Box]:
        """Split the wall into solid boxes around its holes (render and nav geometry)."""
        length = self.length
        if length <= 1e-6:
            return []
        ux, uy = (self.end[0] - self.start[0]) / length, (self.end[1] - self.start[1]) / length
        yaw = math.atan2(uy, ux)
        # Breakpoints along the wall; each interval is solid except where holes cut it.
        ts = sorted({0.0, length, *[min(max(h[0], 0.0), length) for h in self.holes],
                     *[min(max(h[1], 0.0), length) for h in self.holes]})
        out: list[Box] = []
        for t0, t1 in itertools.pairwise(ts):
            if t1 - t0 < 1e-6:
                continue
            tm = 0.5 * (t0 + t1)
            # Vertical solid intervals of [0, height] minus the holes covering this interval.
            cuts = sorted((max(h[2], 0.0), min(h[3], self.height)) for h in self.holes
                          if h[0] <= tm <= h[1] and h[3] > h[2])
            z = 0.0
            spans = []
            for z0, z1 in cuts:
                if z0 > z:
                    spans.append((z, z0))
                z = max(z, z1)
            if z < self.height:
                spans.append((z, self.height))
            cx = self.start[0] + ux * tm
            cy = self.start[1] + uy * tm
            for z0, z1 in spans:
                if z1 - z0 < 1e-6:
                    continue
                out.append(Box((cx, cy, 0.5 * (z0 + z1)), (t1 - t0, self.thickness, z1 - z0),
                               yaw, self.color, NO_INSTANCE, "wall"))
        return out


@dataclass
class House:
    """One floor of one house, in the world frame.

    objects: every object instance (instance_id == index); nav: the navigable grid;
    rooms: room polygons (may be empty for scanned houses); boxes: render geometry of walls,
    clutter and objects (objects keep their instance id); footprints: instance id -> (N, 2)
    int grid cells (row, col) covered by the object's footprint (goal cells for ObjectNav);
    wall_height: ceiling height (m); sight_walls: (H, W) bool cells of the walls that stand at
    the camera's height (``SIGHT_HEIGHT``): a goal view point must see its object past them
    (None: nothing blocks the view).

    Where the robot's centre may stand differs by data set (``hiconav.sim.geodesic.centre_free``):
    ``centre_free`` None means the navigable grid is the floor free of walls and objects and the
    centre keeps the robot's radius from every blocked cell (ProcTHOR); a mask means the data set
    gives the centre's free space itself (Gibson's channel 0 is Habitat's navmesh, already shrunk
    by Habitat's agent radius). ``success_rule``: "view_points" (success within 1 m geodesic of a
    goal via a view point that sees it) or "semexp" (SemExp's protocol for the Gibson maps: the
    goal category's cells dilated by the success distance; see ``geodesic.GoalDistance``).
    """

    name: str
    objects: list[SimObject]
    nav: NavGrid
    rooms: list[Room] = field(default_factory=list)
    boxes: list[Box] = field(default_factory=list)
    footprints: dict[int, np.ndarray] = field(default_factory=dict)
    quads: QuadSet | None = None  # extra render faces (Gibson walls and extruded objects)
    wall_height: float = 2.6
    floor_color: tuple[float, float, float] = (0.55, 0.45, 0.35)
    ceiling_color: tuple[float, float, float] = (0.92, 0.92, 0.9)
    source: str = ""
    start_hint: tuple[float, float, float] | None = None  # (x, y, yaw) from the data set
    floor_height: float = 0.0  # source-frame height of this floor (Gibson episodes)
    sight_walls: np.ndarray | None = None
    centre_free: np.ndarray | None = None  # (H, W) bool robot-centre cells given by the data set
    success_rule: str = "view_points"
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def instance_categories(self) -> dict[int, str]:
        """Instance id -> category of every object."""
        return {o.instance_id: o.category for o in self.objects}

    @property
    def categories(self) -> set[str]:
        return {o.category for o in self.objects}

    def object(self, instance_id: int) -> SimObject:
        return self.objects[instance_id]

    def instances_of(self, category: str) -> list[SimObject]:
        return [o for o in self.objects if o.category == category]

    def instance_by_source_id(self, source_id: str) -> int | None:
        """The instance id of the object whose data-set id is ``source_id`` (ProcTHOR's object
        "id"), or None when no object has it."""
        index = self._cache.get("source_ids")
        if index is None:
            index = {}
            for o in self.objects:
                if o.source_id:
                    index.setdefault(o.source_id, o.instance_id)
            self._cache["source_ids"] = index
        return index.get(source_id)

    def footprint(self, instance_id: int) -> np.ndarray:
        """(N, 2) int cells (row, col) under the object (at least the cell of its centre)."""
        cells = self.footprints.get(instance_id)
        if cells is None:
            cells = box_footprint_cells(self.nav, self.objects[instance_id])
            self.footprints[instance_id] = cells
        return cells


def box_corners_xy(center: np.ndarray, size: np.ndarray, yaw: float) -> np.ndarray:
    """(4, 2) corners of an oriented rectangle (centre (2,), size (2,), yaw rad), CCW."""
    c, s = math.cos(yaw), math.sin(yaw)
    hx, hy = size[0] / 2.0, size[1] / 2.0
    local = np.array([[-hx, -hy], [hx, -hy], [hx, hy], [-hx, hy]])
    rot = np.array([[c, -s], [s, c]])
    return local @ rot.T + np.asarray(center, dtype=np.float64)[:2]


def rect_mask(nav_shape: tuple[int, int], origin: np.ndarray, res: float, center: np.ndarray,
              size: np.ndarray, yaw: float, pad: float = 0.0) -> tuple[slice, slice, np.ndarray]:
    """Cells whose centre lies in an oriented rectangle grown by ``pad`` metres.

    Returns (row slice, col slice, window mask) so callers can update a grid in place.
    """
    corners = box_corners_xy(center, np.asarray(size[:2]) + 2 * pad, yaw)
    lo = np.floor((corners.min(axis=0) - origin) / res).astype(int)
    hi = np.ceil((corners.max(axis=0) - origin) / res).astype(int) + 1
    h, w = nav_shape
    c0, r0 = max(lo[0], 0), max(lo[1], 0)
    c1, r1 = min(hi[0], w), min(hi[1], h)
    if c1 <= c0 or r1 <= r0:
        return slice(0, 0), slice(0, 0), np.zeros((0, 0), dtype=bool)
    xs = origin[0] + (np.arange(c0, c1) + 0.5) * res
    ys = origin[1] + (np.arange(r0, r1) + 0.5) * res
    dx = xs[None, :] - center[0]
    dy = ys[:, None] - center[1]
    c, s = math.cos(yaw), math.sin(yaw)
    lx = c * dx + s * dy
    ly = -s * dx + c * dy
    mask = (np.abs(lx) <= size[0] / 2.0 + pad) & (np.abs(ly) <= size[1] / 2.0 + pad)
    return slice(r0, r1), slice(c0, c1), mask


def box_footprint_cells(nav: NavGrid, obj: SimObject) -> np.ndarray:
    """(N, 2) int cells (row, col) whose centre lies in the object's footprint.

    Each side counts as at least one cell wide: a painting 3 cm thick and 94 cm long lies between
    two columns of cell centres, and its footprint would be the one cell at its middle, so a robot
    half a metre from the painting's end would stand over a metre from its "footprint".
    Objects smaller than a cell both ways still get the cell that contains their centre.
    """
    size = np.maximum(np.asarray(obj.size[:2], dtype=np.float64), nav.resolution * (1.0 + 1e-6))
    rs, cs, mask = rect_mask(nav.shape, nav.origin, nav.resolution, obj.center, size, obj.yaw)
    rr, cc = np.nonzero(mask)
    cells = np.stack([rr + (rs.start or 0), cc + (cs.start or 0)], axis=1).astype(np.int64)
    if len(cells) == 0:
        rc = nav.world_to_cell(obj.center[:2])
        if nav.in_bounds(rc):
            cells = rc[None, :].astype(np.int64)
        else:
            cells = np.zeros((0, 2), dtype=np.int64)
    return freeze(cells)


def rasterize_polygon(shape: tuple[int, int], origin: np.ndarray, res: float,
                      polygon: np.ndarray) -> np.ndarray:
    """(H, W) bool: cells whose centre lies inside ``polygon`` ((N, 2) world xy).

    A centre on the boundary belongs to the polygon on its +x / +y side (the centres are tested
    1 um up and right): matplotlib leaves boundary points out of every polygon, so where two
    rooms meet exactly on a row or column of cell centres, a seam without floor split them, and
    the doorway in that wall was a wall on the navigable grid while the renderer showed it open
    (ProcTHOR val/52: the robot rocked in front of a door it saw but could not pass)."""
    from matplotlib.path import Path as MplPath

    h, w = shape
    xs = origin[0] + (np.arange(w) + 0.5) * res
    ys = origin[1] + (np.arange(h) + 0.5) * res
    poly = np.asarray(polygon, dtype=np.float64)
    lo = np.floor((poly.min(axis=0) - origin) / res).astype(int)
    hi = np.ceil((poly.max(axis=0) - origin) / res).astype(int) + 1
    c0, r0 = max(lo[0], 0), max(lo[1], 0)
    c1, r1 = min(hi[0], w), min(hi[1], h)
    out = np.zeros(shape, dtype=bool)
    if c1 <= c0 or r1 <= r0:
        return out
    gx, gy = np.meshgrid(xs[c0:c1], ys[r0:r1])
    inside = MplPath(poly).contains_points(np.stack([gx.ravel() + 1e-6, gy.ravel() + 1e-6], axis=1))
    out[r0:r1, c0:c1] = inside.reshape(gy.shape)
    return out


def triangulate_polygon(polygon: np.ndarray) -> np.ndarray:
    """(T, 3) int vertex indices triangulating a simple polygon ((N, 2) world xy) by ear clipping.

    Works for convex and concave polygons (ProcTHOR rooms are rectilinear, often L-shaped);
    collinear corners are dropped. Triangles are counter-clockwise (seen from +z) whatever the
    polygon's own orientation. Raises ValueError for self-intersecting or degenerate polygons.
    O(N^3) worst case: meant for room outlines of tens of corners.
    """
    pts = np.asarray(polygon, dtype=np.float64)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise ValueError(f"a polygon needs (N >= 3, 2) corners, got shape {pts.shape}")
    idx = list(range(len(pts)))
    if len(pts) > 3 and np.allclose(pts[0], pts[-1]):
        idx.pop()  # closed ring: drop the repeated first corner
    x, y = pts[:, 0], pts[:, 1]
    area2 = float(np.sum(x[idx] * np.roll(y[idx], -1) - np.roll(x[idx], -1) * y[idx]))
    if area2 < 0:
        idx.reverse()  # make it counter-clockwise
    eps = 1e-9 * max(1.0, float(np.abs(pts).max()) ** 2)

    def cross(a: int, b: int, c: int) -> float:
        return float((x[b] - x[a]) * (y[c] - y[a]) - (y[b] - y[a]) * (x[c] - x[a]))

    tris: list[tuple[int, int, int]] = []
    guard = 0
    while len(idx) > 3:
        n = len(idx)
        for k in range(n):
            a, b, c = idx[k - 1], idx[k], idx[(k + 1) % n]
            turn = cross(a, b, c)
            if abs(turn) <= eps:  # collinear corner: no area, drop it
                idx.pop(k)
                break
            if turn < 0:  # reflex corner: not an ear
                continue
            # An ear holds no other corner inside or on its boundary.
            blocked = False
            for j in idx:
                if j in (a, b, c) or (pts[j] == pts[a]).all() or (pts[j] == pts[b]).all() \
                        or (pts[j] == pts[c]).all():
                    continue
                if cross(a, b, j) >= -eps and cross(b, c, j) >= -eps and cross(c, a, j) >= -eps:
                    blocked = True
                    break
            if not blocked:
                tris.append((a, b, c))
                idx.pop(k)
                break
        else:
            raise ValueError("polygon is not simple (no ear found): self-intersecting?")
        guard += 1
        if guard > 4 * len(pts):  # pragma: no cover - defensive
            raise ValueError("ear clipping did not terminate")
    if len(idx) == 3 and abs(cross(*idx)) > eps:
        tris.append(tuple(idx))
    if not tris:
        raise ValueError("polygon has zero area")
    return np.asarray(tris, dtype=np.int64)


def floor_mask(house: House) -> np.ndarray:
    """(H, W) bool cells of the house grid that have a floor (navigable or under an object).

    The union of the room polygons where the house has rooms; otherwise (scanned houses) the
    navigable cells plus every object footprint. Outside it there is no floor to render.
    """
    nav = house.nav
    if house.rooms:
        mask = np.zeros(nav.shape, dtype=bool)
        for r in house.rooms:
            mask |= rasterize_polygon(nav.shape, nav.origin, nav.resolution, r.polygon)
        return mask
    mask = np.array(nav.navigable, dtype=bool)
    for o in house.objects:
        cells = house.footprint(o.instance_id)
        ok = nav.in_bounds(cells)
        mask[cells[ok, 0], cells[ok, 1]] = True
    return mask


def runs_to_boxes(mask: np.ndarray, origin: np.ndarray, res: float, z0: float, z1: float,
                  color: tuple[float, float, float], instance_id: int = NO_INSTANCE,
                  material: str = "object") -> list[Box]:
    """Extrude a (H, W) bool cell mask from z0 to z1 as boxes, one per horizontal run.

    Runs of equal extent in consecutive rows are merged, so rectangles become one box.
    """
    boxes: list[Box] = []
    open_runs: dict[tuple[int, int], int] = {}  # (c0, c1) -> first row
    h = mask.shape[0]

    def emit(c0: int, c1: int, r0: int, r1: int) -> None:
        cx = origin[0] + 0.5 * (c0 + c1) * res
        cy = origin[1] + 0.5 * (r0 + r1) * res
        boxes.append(Box((cx, cy, 0.5 * (z0 + z1)), ((c1 - c0) * res, (r1 - r0) * res, z1 - z0),
                         0.0, color, instance_id, material))

    for r in range(h + 1):
        runs: set[tuple[int, int]] = set()
        if r < h:
            row = mask[r].astype(np.int8)
            d = np.diff(np.concatenate([[0], row, [0]]))
            starts = np.nonzero(d == 1)[0]
            ends = np.nonzero(d == -1)[0]
            runs = set(zip(starts.tolist(), ends.tolist()))
        for key in list(open_runs):
            if key not in runs:
                emit(key[0], key[1], open_runs.pop(key), r)
        for key in runs:
            if key not in open_runs:
                open_runs[key] = r
    return boxes


BLOCK_BELOW = 1.2  # m: geometry whose bottom is below this blocks the robot's disc
SIGHT_HEIGHT = 0.88  # m: camera height of the ObjectNav robot; walls spanning it block the view


def assemble_house(name: str, rooms: list[Room], walls: list[Wall], objects: list[SimObject],
                   *, resolution: float = 0.05, pad: float = 0.3, source: str = "",
                   colors: list[tuple[float, float, float]] | None = None) -> House:
    """Build a ``House`` from room polygons, walls and objects (render boxes + nav grid).

    The navigable grid is the union of the room floors minus every wall piece and object box
    whose bottom is below ``BLOCK_BELOW`` (cells whose centre lies in the box footprint).
    ``colors``: optional per-object RGB; default a stable colour per category.
    """
    from hiconav.sim.procthor import category_color

    if not rooms:
        raise ValueError("a house needs at least one room polygon")
    boxes: list[Box] = []
    for w in walls:
        boxes.extend(w.boxes())
    rng = np.random.default_rng(len(objects))
    for k, o in enumerate(objects):
        if colors is not None:
            color = colors[k]
        else:
            base = np.array(category_color(o.category))
            color = tuple(np.clip(base * (0.85 + 0.3 * rng.random()), 0.0, 1.0))
        boxes.append(Box(tuple(float(v) for v in o.center), tuple(float(v) for v in o.size),
                         float(o.yaw), tuple(float(v) for v in color), o.instance_id, "object"))
    all_pts = np.concatenate([r.polygon for r in rooms])
    origin = np.floor((all_pts.min(axis=0) - pad) / resolution) * resolution
    extent = all_pts.max(axis=0) + pad - origin
    shape = (math.ceil(extent[1] / resolution), math.ceil(extent[0] / resolution))
    floor = np.zeros(shape, dtype=bool)
    for r in rooms:
        floor |= rasterize_polygon(shape, origin, resolution, r.polygon)
    blocked = np.zeros(shape, dtype=bool)
    sight = np.zeros(shape, dtype=bool)
    for b in boxes:
        blocks = b.center[2] - b.size[2] / 2.0 < BLOCK_BELOW
        hides = b.material == "wall" and abs(b.center[2] - SIGHT_HEIGHT) <= b.size[2] / 2.0
        if blocks or hides:
            rs, cs, m = rect_mask(shape, origin, resolution, np.array(b.center),
                                  np.array(b.size), b.yaw)
            if m.size:
                if blocks:
                    blocked[rs, cs] |= m
                if hides:
                    sight[rs, cs] |= m
    nav = NavGrid(floor & ~blocked, origin.astype(np.float64), resolution)
    wall_height = max((w.height for w in walls), default=2.6)
    return House(name=name, objects=list(objects), nav=nav, rooms=list(rooms), boxes=boxes,
                 wall_height=float(wall_height), source=source, sight_walls=sight)


@dataclass(frozen=True)
class QuadSet:
    """Render quads (no thickness): corners (Q, 4, 3) world m (counter-clockwise seen from the
    side the normal points to), normals (Q, 3), colors (Q, 3) RGB [0, 1], instance_ids (Q,)
    int (-1 = none), materials (Q,) names as in ``Box.material``."""

    corners: np.ndarray
    normals: np.ndarray
    colors: np.ndarray
    instance_ids: np.ndarray
    materials: tuple[str, ...]

    def __len__(self) -> int:
        return len(self.corners)

    @staticmethod
    def concat(sets: list[QuadSet]) -> QuadSet:
        sets = [s for s in sets if len(s)]
        if not sets:
            return QuadSet(np.zeros((0, 4, 3)), np.zeros((0, 3)), np.zeros((0, 3)),
                           np.zeros(0, dtype=np.int64), ())
        return QuadSet(np.concatenate([s.corners for s in sets]),
                       np.concatenate([s.normals for s in sets]),
                       np.concatenate([s.colors for s in sets]),
                       np.concatenate([s.instance_ids for s in sets]),
                       tuple(m for s in sets for m in s.materials))


def _runs_along_rows(faces: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """For a (H, W) bool face mask: runs of True along rows inside each column.

    Returns (col, row_start, row_end) arrays, rows [start, end).
    """
    padded = np.zeros((faces.shape[0] + 2, faces.shape[1]), dtype=np.int8)
    padded[1:-1] = faces
    d = np.diff(padded, axis=0).T  # (W, H + 1), sorted by column then row
    starts = np.argwhere(d == 1)
    ends = np.argwhere(d == -1)
    return starts[:, 0], starts[:, 1], ends[:, 1]


def mask_side_quads(mask: np.ndarray, origin: np.ndarray, res: float, z0: float, z1: float,
                    color: tuple[float, float, float], instance_id: int = NO_INSTANCE,
                    material: str = "wall", top: bool = False) -> QuadSet:
    """Vertical faces on the boundary of a (H, W) bool cell mask, extruded from z0 to z1.

    Faces point out of the mask; collinear faces of consecutive cells are merged. With
    ``top`` the mask also gets horizontal top faces at z1 (rectangles of merged runs).
    """
    m = np.asarray(mask, dtype=bool)
    ox, oy = float(origin[0]), float(origin[1])
    quads: list[np.ndarray] = []
    normals: list[np.ndarray] = []
    pad = np.pad(m, 1, constant_values=False)
    inner = pad[1:-1, 1:-1]
    # East (+x) and west (-x) faces: boundaries between columns; runs along rows.
    for sign in (1, -1):
        nb = pad[1:-1, 2:] if sign > 0 else pad[1:-1, :-2]
        cols, r0, r1 = _runs_along_rows(inner & ~nb)
        x = ox + (cols + (1 if sign > 0 else 0)) * res
        y0, y1 = oy + r0 * res, oy + r1 * res
        if sign > 0:
            q = np.stack([np.stack([x, y0, np.full_like(x, z0)], 1),
                          np.stack([x, y1, np.full_like(x, z0)], 1),
                          np.stack([x, y1, np.full_like(x, z1)], 1),
                          np.stack([x, y0, np.full_like(x, z1)], 1)], 1)
        else:
            q = np.stack([np.stack([x, y1, np.full_like(x, z0)], 1),
                          np.stack([x, y0, np.full_like(x, z0)], 1),
                          np.stack([x, y0, np.full_like(x, z1)], 1),
                          np.stack([x, y1, np.full_like(x, z1)], 1)], 1)
        quads.append(q)
        normals.append(np.tile([float(sign), 0.0, 0.0], (len(q), 1)))
    # North (+y) and south (-y) faces: boundaries between rows; runs along columns.
    for sign in (1, -1):
        nb = pad[2:, 1:-1] if sign > 0 else pad[:-2, 1:-1]
        rows, c0, c1 = _runs_along_rows((inner & ~nb).T)
        y = oy + (rows + (1 if sign > 0 else 0)) * res
        x0, x1 = ox + c0 * res, ox + c1 * res
        if sign > 0:
            q = np.stack([np.stack([x1, y, np.full_like(y, z0)], 1),
                          np.stack([x0, y, np.full_like(y, z0)], 1),
                          np.stack([x0, y, np.full_like(y, z1)], 1),
                          np.stack([x1, y, np.full_like(y, z1)], 1)], 1)
        else:
            q = np.stack([np.stack([x0, y, np.full_like(y, z0)], 1),
                          np.stack([x1, y, np.full_like(y, z0)], 1),
                          np.stack([x1, y, np.full_like(y, z1)], 1),
                          np.stack([x0, y, np.full_like(y, z1)], 1)], 1)
        quads.append(q)
        normals.append(np.tile([0.0, float(sign), 0.0], (len(q), 1)))
    if top:
        for b in runs_to_boxes(m, origin, res, z0, z1, color):
            cx, cy, _ = b.center
            hx, hy = b.size[0] / 2, b.size[1] / 2
            quads.append(np.array([[[cx - hx, cy - hy, z1], [cx + hx, cy - hy, z1],
                                    [cx + hx, cy + hy, z1], [cx - hx, cy + hy, z1]]]))
            normals.append(np.array([[0.0, 0.0, 1.0]]))
    corners = np.concatenate(quads) if quads else np.zeros((0, 4, 3))
    nrm = np.concatenate(normals) if normals else np.zeros((0, 3))
    n = len(corners)
    return QuadSet(corners, nrm, np.tile(np.asarray(color, dtype=np.float64), (n, 1)),
                   np.full(n, instance_id, dtype=np.int64), (material,) * n)
