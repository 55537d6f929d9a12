"""RGB, metric depth and instance-id rendering of a ``House`` with OpenGL (moderngl, headless
EGL): one draw call, one pass, three render targets.

Outputs for a camera ``T_world_cam`` (4x4, OpenCV camera: x right, y down, z forward) and
pinhole ``CameraIntrinsics``:
- rgb: (H, W, 3) uint8: per-category/material colour (with a per-instance brightness jitter),
  flat Lambert shading from a fixed sun direction plus ambient, and procedural texture
  (hashed 5 cm grain, wood planks on floors, plaster waves on walls; no trigonometry, which
  is slow in software rasterisers), so the image is not trivially segmentable by colour;
- depth: (H, W) float32 metres along the optical axis (camera z); 0 where there is no surface
  or the surface is outside [min_depth, max_depth];
- instances: (H, W) int32 object instance id, -1 for walls, floor, ceiling and background.

Geometry: the house's boxes and quads, plus floor (z = 0) and ceiling (z = wall_height) over
exactly the house's floor (``floor_triangles``: ProcTHOR room polygons, ear-clipped; Gibson
floor cells), so through an exterior door or past a wall end the camera sees background:
rgb black, depth 0, instance -1 (no slab beyond the house that the mapper would call free).

Speed (Mesa llvmpipe on 2 cores: ~5-9 ms a frame, mostly per-pixel raster work): one static
vertex buffer per house; every frame the triangles that can show (inside the frustum, facing
the camera; tested in numpy) are re-ordered nearest first (an index buffer) so the early depth
test skips hidden fragments; shading is per vertex and the texture is trig-free. One pass
writes three targets (RGBA8, R32F depth, R32I instance id + 1, cleared to 0 = none); they are
read back as plain copies (RGBA into a reused buffer, cv2 drops alpha; no float->int pass).

Pixel (row v, col u) shows the ray through the OpenCV pixel centre (u, v), so
``backproject(depth, K)`` recovers the surface exactly. Rows come out top-first (the projection
flips y), so the read-back needs no flip. This module renders only: it must not move the robot
or decide anything about episodes.

Requires libEGL and Mesa's drivers (Debian: libegl1, libgl1-mesa-dri); on a machine with an
NVIDIA driver EGL uses the GPU.
"""

from __future__ import annotations

import threading

import cv2
import numpy as np
from scipy import ndimage

from hiconav.errors import HiconavError
from hiconav.sim.house import Box, House, QuadSet, floor_mask, runs_to_boxes, triangulate_polygon
from hiconav.types import CameraIntrinsics

NEAR, FAR = 0.02, 200.0  # clip planes (m); depth validity is [min_depth, max_depth]
MATERIALS = {"object": 0.0, "wall": 1.0, "floor": 2.0, "ceiling": 3.0}
SCAN_FLOOR_BLOCK = 4  # cells: scanned floors are drawn in blocks of 4 x 4 cells (20 cm)


class RenderError(HiconavError):
    """The OpenGL context or a render resource could not be created."""


_VERTEX = """
#version 330
uniform mat4 mvp;
uniform vec3 sun;
in vec3 in_pos;
in vec3 in_normal;
in vec3 in_color;
in float in_inst;
in float in_mat;
out vec3 v_world;
out vec3 v_color;
out float v_z;
flat out int v_inst;
flat out float v_mat;
void main() {
    gl_Position = mvp * vec4(in_pos, 1.0);
    v_z = gl_Position.w;  // = camera-frame z (optical axis distance)
    v_world = in_pos;
    // Faces are flat, so Lambert shading (sun + ambient + a side tint) is per vertex.
    float shade = 0.5 + 0.5 * max(dot(in_normal, sun), 0.0) + 0.12 * abs(in_normal.x);
    v_color = in_color * shade;
    v_inst = int(in_inst + 0.5);  // instance id + 1 (exact small integer)
    v_mat = in_mat;
}
"""

_FRAGMENT = """
#version 330
uniform float min_depth;
uniform float max_depth;
uniform float noise_amp;
in vec3 v_world;
in vec3 v_color;
in float v_z;
flat in int v_inst;
flat in float v_mat;
layout(location = 0) out vec4 f_color;
layout(location = 1) out float f_depth;
layout(location = 2) out int f_inst;

// Trigonometry-free value hash (Hoskins' hash13) and triangle wave: software rasterisers
// (llvmpipe) pay dearly for sin() per fragment.
float hash13(vec3 q) {
    vec3 r = fract(q * vec3(0.1031, 0.1030, 0.0973));
    r += dot(r, r.yzx + 33.33);
    return fract((r.x + r.y) * r.z);
}
float tri(float x) { return abs(fract(x) - 0.5) * 2.0; }

void main() {
    vec3 p = v_world;
    float grain = hash13(floor(p * 20.0));  // one value per 5 cm cell of the surface
    float tex;
    if (v_mat > 2.5) {          // ceiling: faint grain
        tex = 0.5 + 0.3 * (grain - 0.5);
    } else if (v_mat > 1.5) {   // floor: wood planks along x
        float plank = hash13(vec3(floor(p.y * 6.0), 7.0, 3.0));
        tex = 0.45 * plank + 0.25 * grain + 0.3 * tri(p.x * 1.5 + plank);
    } else if (v_mat > 0.5) {   // wall: plaster
        tex = 0.4 * grain + 0.6 * tri(p.x * 0.37 + p.y * 0.29) * tri(p.z * 0.5);
    } else {                    // object: fabric/wood mix
        tex = 0.5 * grain + 0.5 * tri(dot(p, vec3(1.13, 0.84, 1.54)) + float(v_inst) * 0.37);
    }
    vec3 c = v_color * (1.0 + noise_amp * (2.0 * tex - 1.0));
    f_color = vec4(clamp(c, 0.0, 1.0), 1.0);
    f_depth = (v_z >= min_depth && v_z <= max_depth) ? v_z : 0.0;
    f_inst = v_inst;  // instance id + 1; 0 = none (cleared value)
}
"""

# Unit cube: 6 faces x 2 triangles, positions in [-0.5, 0.5], outward normals.
_FACES = [
    ((1, 0, 0), [(0.5, -0.5, -0.5), (0.5, 0.5, -0.5), (0.5, 0.5, 0.5), (0.5, -0.5, 0.5)]),
    ((-1, 0, 0), [(-0.5, 0.5, -0.5), (-0.5, -0.5, -0.5), (-0.5, -0.5, 0.5), (-0.5, 0.5, 0.5)]),
    ((0, 1, 0), [(0.5, 0.5, -0.5), (-0.5, 0.5, -0.5), (-0.5, 0.5, 0.5), (0.5, 0.5, 0.5)]),
    ((0, -1, 0), [(-0.5, -0.5, -0.5), (0.5, -0.5, -0.5), (0.5, -0.5, 0.5), (-0.5, -0.5, 0.5)]),
    ((0, 0, 1), [(-0.5, -0.5, 0.5), (0.5, -0.5, 0.5), (0.5, 0.5, 0.5), (-0.5, 0.5, 0.5)]),
    ((0, 0, -1), [(-0.5, 0.5, -0.5), (0.5, 0.5, -0.5), (0.5, -0.5, -0.5), (-0.5, -0.5, -0.5)]),
]
_CUBE_POS = np.array([[q[i] for i in (0, 1, 2, 0, 2, 3)] for _, q in _FACES],
                     dtype=np.float64).reshape(36, 3)
_CUBE_NRM = np.repeat(np.array([n for n, _ in _FACES], dtype=np.float64), 6, axis=0)

# Thread id -> its EGL context. Contexts of finished threads are kept (a few MB each); a
# process renders from a handful of long-lived threads (main, simulator actor).
_THREAD_CONTEXTS: dict[int, object] = {}


def gl_context():
    """The calling thread's headless EGL context (created on first use).

    An EGL context is current in one thread only, so every thread that renders gets its own;
    a ``Renderer`` must be used from the thread that created it.
    """
    tid = threading.get_ident()
    ctx = _THREAD_CONTEXTS.get(tid)
    if ctx is None:
        try:
            import moderngl
        except ImportError as exc:  # pragma: no cover - dependency missing
            raise RenderError(f"moderngl is not installed ({exc}); pip install moderngl") from exc
        try:
            ctx = moderngl.create_standalone_context(backend="egl", require=330)
        except Exception as exc:
            raise RenderError(
                f"cannot create a headless OpenGL 3.3 context through EGL: {exc}. The renderer "
                "needs libEGL and Mesa's drivers (Debian: apt install libegl1 "
                "libgl1-mesa-dri) or an NVIDIA driver with EGL.") from exc
        _THREAD_CONTEXTS[tid] = ctx
    return ctx


def boxes_to_vertices(boxes: list[Box]) -> np.ndarray:
    """(36 * N, 11) float32 vertices: position (3), normal (3), colour (3), inst + 1, material."""
    if not boxes:
        return np.zeros((0, 11), dtype=np.float32)
    centers = np.array([b.center for b in boxes], dtype=np.float64)
    sizes = np.array([b.size for b in boxes], dtype=np.float64)
    yaws = np.array([b.yaw for b in boxes], dtype=np.float64)
    c, s = np.cos(yaws)[:, None], np.sin(yaws)[:, None]
    local = _CUBE_POS[None] * sizes[:, None, :]  # (N, 36, 3)
    px = c * local[..., 0] - s * local[..., 1] + centers[:, 0:1]
    py = s * local[..., 0] + c * local[..., 1] + centers[:, 1:2]
    pz = local[..., 2] + centers[:, 2:3]
    nx = c * _CUBE_NRM[None, :, 0] - s * _CUBE_NRM[None, :, 1]
    ny = s * _CUBE_NRM[None, :, 0] + c * _CUBE_NRM[None, :, 1]
    nz = np.broadcast_to(_CUBE_NRM[None, :, 2], nx.shape)
    n = len(boxes)
    out = np.empty((n, 36, 11), dtype=np.float32)
    out[..., 0], out[..., 1], out[..., 2] = px, py, pz
    out[..., 3], out[..., 4], out[..., 5] = nx, ny, nz
    out[..., 6:9] = np.array([b.color for b in boxes], dtype=np.float32)[:, None, :]
    out[..., 9] = np.array([b.instance_id + 1 for b in boxes], dtype=np.float32)[:, None]
    out[..., 10] = np.array([MATERIALS.get(b.material, 0.0) for b in boxes],
                            dtype=np.float32)[:, None]
    return out.reshape(-1, 11)


def quads_to_vertices(quads: QuadSet) -> np.ndarray:
    """(6 * Q, 11) float32 vertices of a ``QuadSet`` (two triangles per quad)."""
    n = len(quads)
    if n == 0:
        return np.zeros((0, 11), dtype=np.float32)
    out = np.empty((n, 6, 11), dtype=np.float32)
    out[..., 0:3] = quads.corners[:, [0, 1, 2, 0, 2, 3], :]
    out[..., 3:6] = quads.normals[:, None, :]
    out[..., 6:9] = quads.colors[:, None, :]
    out[..., 9] = (quads.instance_ids + 1)[:, None]
    out[..., 10] = np.array([MATERIALS.get(m, 0.0) for m in quads.materials],
                            dtype=np.float32)[:, None]
    return out.reshape(-1, 11)


def floor_triangles(house: House) -> np.ndarray:
    """(T, 3, 2) world xy triangles of the house's floor, counter-clockwise seen from above.

    Houses with rooms (ProcTHOR): the room floor polygons, ear-clipped. Houses without
    (Gibson scans): ``floor_mask`` grown by one cell, then by up to ``SCAN_FLOOR_BLOCK`` - 1
    more to whole blocks of that many cells, as one rectangle per merged run of blocks. In a
    scan every cell outside ``floor_mask`` is wall/clutter whose full-height faces border the
    floor, so the overhang lies hidden under them; it removes cracks at their foot and cuts
    the floor of a scan from ~300 ragged rectangles to ~70. Nothing is drawn outside: there
    the camera sees background (no depth, no instance).
    """
    if house.rooms:
        tris = []
        for r in house.rooms:
            try:
                tris.append(r.polygon[triangulate_polygon(r.polygon)])
            except ValueError as exc:
                raise RenderError(f"{house.name} ({house.source}): floor polygon of room "
                                  f"'{r.id}' cannot be triangulated: {exc}") from exc
        return np.concatenate(tris).astype(np.float64)
    nav = house.nav
    mask = ndimage.binary_dilation(floor_mask(house), structure=np.ones((3, 3), dtype=bool))
    B = SCAN_FLOOR_BLOCK
    h, w = mask.shape
    padded = np.zeros((-(-h // B) * B, -(-w // B) * B), dtype=bool)
    padded[:h, :w] = mask
    blocks = padded.reshape(padded.shape[0] // B, B, padded.shape[1] // B, B).any(axis=(1, 3))
    rects = runs_to_boxes(blocks, nav.origin, nav.resolution * B, 0.0, 0.0, house.floor_color)
    if not rects:
        return np.zeros((0, 3, 2))
    c = np.array([b.center[:2] for b in rects])
    h = np.array([b.size[:2] for b in rects]) / 2.0
    x0, y0 = c[:, 0] - h[:, 0], c[:, 1] - h[:, 1]
    x1, y1 = c[:, 0] + h[:, 0], c[:, 1] + h[:, 1]
    q = np.stack([np.stack([x0, y0], 1), np.stack([x1, y0], 1), np.stack([x1, y1], 1),
                  np.stack([x0, y1], 1)], 1)  # (R, 4, 2) CCW
    return q[:, [0, 1, 2, 0, 2, 3]].reshape(-1, 3, 2)


def _flat_triangles(tris_xy: np.ndarray, z: float, up: bool,
                    color: tuple[float, float, float], material: str) -> np.ndarray:
    """(3 * T, 11) vertices of horizontal triangles at height z, facing +z (up) or -z."""
    n = len(tris_xy)
    out = np.empty((n, 3, 11), dtype=np.float32)
    xy = tris_xy if up else tris_xy[:, ::-1]  # seen from below, the winding reverses
    out[..., 0:2] = xy
    out[..., 2] = z
    out[..., 3:6] = (0.0, 0.0, 1.0 if up else -1.0)
    out[..., 6:9] = color
    out[..., 9] = 0.0  # instance id + 1: none
    out[..., 10] = MATERIALS[material]
    return out.reshape(-1, 11)


def house_vertices(house: House) -> np.ndarray:
    """All render geometry of a house: its boxes and quads plus floor and ceiling.

    Floor (z = 0) and ceiling (z = wall_height) cover exactly the ``floor_triangles``.
    """
    tris = floor_triangles(house)
    parts = [boxes_to_vertices(list(house.boxes)),
             _flat_triangles(tris, 0.0, True, house.floor_color, "floor"),
             _flat_triangles(tris, house.wall_height, False, house.ceiling_color, "ceiling")]
    if house.quads is not None and len(house.quads):
        parts.append(quads_to_vertices(house.quads))
    return np.concatenate(parts)


def projection(intr: CameraIntrinsics, near: float = NEAR, far: float = FAR) -> np.ndarray:
    """(4, 4) OpenCV camera -> GL clip matrix; NDC y grows with image rows (top row first)."""
    W, H = intr.width, intr.height
    P = np.zeros((4, 4))
    P[0, 0] = 2.0 * intr.fx / W
    P[0, 2] = 2.0 * (intr.cx + 0.5) / W - 1.0
    P[1, 1] = 2.0 * intr.fy / H
    P[1, 2] = 2.0 * (intr.cy + 0.5) / H - 1.0
    P[2, 2] = (far + near) / (far - near)
    P[2, 3] = -2.0 * far * near / (far - near)
    P[3, 2] = 1.0
    return P


class Renderer:
    """Renders one house at a fixed image size; reuse it for every frame of that house."""

    def __init__(self, width: int = 640, height: int = 480, *, min_depth: float = 0.5,
                 max_depth: float = 5.0, noise: float = 0.12) -> None:
        self.width, self.height = int(width), int(height)
        self.min_depth, self.max_depth = float(min_depth), float(max_depth)
        ctx = gl_context()
        self.ctx = ctx
        self.thread = threading.get_ident()
        self.program = ctx.program(vertex_shader=_VERTEX, fragment_shader=_FRAGMENT)
        sun = np.array([0.35, 0.25, 0.9])
        for name, value in (("min_depth", self.min_depth), ("max_depth", self.max_depth),
                            ("noise_amp", float(noise)),
                            ("sun", tuple(sun / np.linalg.norm(sun)))):
            if name in self.program:  # a uniform the compiler optimised away is absent
                self.program[name].value = value
        size = (self.width, self.height)
        self._color = ctx.texture(size, 4, dtype="f1")
        self._depth = ctx.texture(size, 1, dtype="f4")
        self._inst = ctx.texture(size, 1, dtype="i4")  # integer target: no float->int
        self._rgba = np.empty((self.height, self.width, 4), dtype=np.uint8)  # read-back buffer
        self._zbuf = ctx.depth_renderbuffer(size)
        self.fbo = ctx.framebuffer([self._color, self._depth, self._inst], self._zbuf)
        self.vbo = None
        self.vao = None
        self.house_name: str | None = None
        self.n_vertices = 0

    def set_house(self, house: House) -> None:
        """Upload the house's geometry (once per house)."""
        self.release_geometry()
        verts = house_vertices(house)
        self.vbo = self.ctx.buffer(verts.tobytes())
        # Triangles are drawn nearest first (index buffer re-sorted every frame) so that the
        # early depth test rejects hidden fragments before shading.
        tri = verts[:, :3].reshape(-1, 3, 3).astype(np.float64)
        self._tri_centres = tri.mean(axis=1).astype(np.float32)
        # Homogeneous corners (3T, 4) for the CPU frustum test, a face's plane (normal n and
        # n . p) for the CPU back-face test.
        self._tri_hom = np.concatenate([tri.reshape(-1, 3), np.ones((len(tri) * 3, 1))], 1)
        self._tri_normal = verts[0::3, 3:6].astype(np.float64)
        self._tri_offset = np.einsum("ij,ij->i", self._tri_normal, tri[:, 0])
        self._tri_base = (np.arange(len(self._tri_centres), dtype=np.uint32) * 3)[:, None] + \
            np.arange(3, dtype=np.uint32)[None, :]
        self.ibo = self.ctx.buffer(reserve=max(len(verts), 1) * 4)
        names = ("in_pos", "in_normal", "in_color", "in_inst", "in_mat")
        # Attributes the shader compiler optimised away are skipped as padding bytes.
        fmt = " ".join(f if n in self.program else {"3f": "12x", "1f": "4x"}[f]
                       for f, n in zip(("3f", "3f", "3f", "1f", "1f"), names))
        self.vao = self.ctx.vertex_array(
            self.program, [(self.vbo, fmt, *[n for n in names if n in self.program])],
            index_buffer=self.ibo, index_element_size=4)
        self.n_vertices = len(verts)
        self.house_name = house.name

    def release_geometry(self) -> None:
        if self.vao is not None:
            self.vao.release()
            self.vbo.release()
            self.ibo.release()
        self.vao = self.vbo = self.ibo = None

    def release(self) -> None:
        """Free every GL resource of this renderer (the shared context stays)."""
        self.release_geometry()
        for res in (self.fbo, self._color, self._depth, self._inst, self._zbuf, self.program):
            res.release()

    def _visible_triangles(self, mvp: np.ndarray, eye: np.ndarray) -> np.ndarray:
        """(K,) int indices of the triangles that can show: not wholly outside one frustum
        plane (clip space, near plane included) and facing the camera.

        The same tests the rasteriser makes, done for all triangles at once in numpy: Mesa's
        llvmpipe pays ~1 us of vertex/setup work per triangle it is handed, and most of a
        house is behind, beside or facing away from the camera.
        """
        clip = (self._tri_hom @ mvp.T).reshape(-1, 3, 4)  # (T, 3, 4)
        w = clip[..., 3]
        out = (np.all(clip[..., 0] < -w, axis=1) | np.all(clip[..., 0] > w, axis=1)
               | np.all(clip[..., 1] < -w, axis=1) | np.all(clip[..., 1] > w, axis=1)
               | np.all(clip[..., 2] < -w, axis=1))  # z < -w: in front of the near plane
        facing = self._tri_normal @ eye.astype(np.float64) > self._tri_offset
        return np.flatnonzero(~out & facing)

    def render(self, T_world_cam: np.ndarray, intrinsics: CameraIntrinsics
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(rgb (H, W, 3) uint8, depth (H, W) float32 m, instances (H, W) int32, -1 = none)."""
        if self.vao is None:
            raise RenderError("Renderer.render called before set_house")
        if threading.get_ident() != self.thread:
            raise RenderError("a Renderer renders only in the thread that created it (its EGL "
                              "context is current there); create one per thread")
        if (intrinsics.width, intrinsics.height) != (self.width, self.height):
            raise RenderError(f"intrinsics are {intrinsics.width}x{intrinsics.height}, the "
                              f"renderer is {self.width}x{self.height}")
        view = np.linalg.inv(np.asarray(T_world_cam, dtype=np.float64))
        mvp = projection(intrinsics) @ view
        self.program["mvp"].write(mvp.T.astype("f4").tobytes())
        eye = np.asarray(T_world_cam, dtype=np.float32)[:3, 3]
        keep = self._visible_triangles(mvp, eye)
        d2 = np.square(self._tri_centres[keep] - eye).sum(axis=1)
        order = keep[np.argsort(d2, kind="stable")]
        if len(order):
            self.ibo.write(self._tri_base[order].tobytes())
        ctx = self.ctx
        self.fbo.use()
        # Boxes and quads are wound counter-clockwise seen from outside; the y-flipped
        # projection mirrors the window, so the visible (front) faces appear clockwise.
        ctx.enable_only(ctx.DEPTH_TEST | ctx.CULL_FACE)
        ctx.front_face = "cw"
        ctx.cull_face = "back"
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        if len(order):
            self.vao.render(vertices=3 * len(order))
        W, H = self.width, self.height
        # RGBA comes back as a plain copy (reading 3 components makes Mesa repack every pixel,
        # ~3x slower); cv2 drops alpha into the fresh RGB array.
        self.fbo.read_into(self._rgba, components=4, attachment=0, alignment=1)
        rgb = cv2.cvtColor(self._rgba, cv2.COLOR_RGBA2RGB)
        depth = np.empty((H, W), dtype=np.float32)
        instances = np.empty((H, W), dtype=np.int32)
        self.fbo.read_into(depth, components=1, attachment=1, dtype="f4", alignment=1)
        self.fbo.read_into(instances, components=1, attachment=2, dtype="i4", alignment=1)
        np.subtract(instances, 1, out=instances)  # stored as id + 1 so that clear (0) = none
        return rgb, depth, instances


def look_at_base(x: float, y: float, yaw: float, height: float, tilt: float = 0.0) -> np.ndarray:
    """T_world_cam of a camera at (x, y, height) looking along ``yaw`` (helper for tests)."""
    from hiconav.types import Pose2D, camera_pose_from_base

    return camera_pose_from_base(Pose2D(x, y, yaw), height, tilt)


__all__ = [
    "RenderError",
    "Renderer",
    "floor_triangles",
    "gl_context",
    "house_vertices",
    "look_at_base",
    "projection",
]
