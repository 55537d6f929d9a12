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

Speed: one static vertex buffer per house; every frame the triangles are re-ordered nearest
first (an index buffer, argsort of ~5k centroids) so the early depth test skips hidden
fragments, back faces are culled, shading is per vertex and the texture is trig-free; the three
images are read straight into fresh numpy arrays (one copy each, plus the int32 conversion of
the instance channel, stored as float id + 1 so that clearing to 0 means "none").

Pixel (row v, col u) shows the ray through the OpenCV pixel centre (u, v), so
``backproject(depth, K)`` recovers the surface exactly. Rows come out top-first (the projection
flips y), so the read-back needs no flip. This module renders only: it must not move the robot
or decide anything about episodes.

Requires libEGL and Mesa's drivers (Debian: libegl1, libgl1-mesa-dri); on a machine with an
NVIDIA driver EGL uses the GPU.
"""

from __future__ import annotations

import threading

import numpy as np

from hiconav.errors import HiconavError
from hiconav.sim.house import Box, House, QuadSet
from hiconav.types import CameraIntrinsics

NEAR, FAR = 0.02, 200.0  # clip planes (m); depth validity is [min_depth, max_depth]
MATERIALS = {"object": 0.0, "wall": 1.0, "floor": 2.0, "ceiling": 3.0}


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
flat out float v_inst;
flat out float v_mat;
void main() {
    gl_Position = mvp * vec4(in_pos, 1.0);
    v_z = gl_Position.w;  // = camera-frame z (optical axis distance)
    v_world = in_pos;
    // Faces are flat, so Lambert shading (sun + ambient + a side tint) is per vertex.
    float shade = 0.5 + 0.5 * max(dot(in_normal, sun), 0.0) + 0.12 * abs(in_normal.x);
    v_color = in_color * shade;
    v_inst = in_inst;
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
flat in float v_inst;
flat in float v_mat;
layout(location = 0) out vec4 f_color;
layout(location = 1) out float f_depth;
layout(location = 2) out float f_inst;

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
        tex = 0.5 * grain + 0.5 * tri(dot(p, vec3(1.13, 0.84, 1.54)) + v_inst * 0.37);
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


def house_vertices(house: House) -> np.ndarray:
    """All render geometry of a house: its boxes plus a floor and a ceiling slab."""
    h, w = house.nav.shape
    res = house.nav.resolution
    ox, oy = house.nav.origin
    cx, cy = ox + w * res / 2, oy + h * res / 2
    sx, sy = w * res + 2.0, h * res + 2.0
    extra = [
        Box((cx, cy, -0.05), (sx, sy, 0.1), 0.0, house.floor_color, -1, "floor"),
        Box((cx, cy, house.wall_height + 0.05), (sx, sy, 0.1), 0.0, house.ceiling_color, -1,
            "ceiling"),
    ]
    verts = boxes_to_vertices(list(house.boxes) + extra)
    if house.quads is not None and len(house.quads):
        verts = np.concatenate([verts, quads_to_vertices(house.quads)])
    return verts


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
        self._inst = ctx.texture(size, 1, dtype="f4")
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
        self._tri_centres = verts[:, :3].reshape(-1, 3, 3).mean(axis=1).astype(np.float32)
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
        d2 = np.square(self._tri_centres - eye).sum(axis=1)
        self.ibo.write(self._tri_base[np.argsort(d2, kind="stable")].tobytes())
        ctx = self.ctx
        self.fbo.use()
        # Boxes and quads are wound counter-clockwise seen from outside; the y-flipped
        # projection mirrors the window, so the visible (front) faces appear clockwise.
        ctx.enable_only(ctx.DEPTH_TEST | ctx.CULL_FACE)
        ctx.front_face = "cw"
        ctx.cull_face = "back"
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self.vao.render()
        W, H = self.width, self.height
        rgb = np.empty((H, W, 3), dtype=np.uint8)
        depth = np.empty((H, W), dtype=np.float32)
        inst = np.empty((H, W), dtype=np.float32)
        self.fbo.read_into(rgb, components=3, attachment=0, alignment=1)
        self.fbo.read_into(depth, components=1, attachment=1, dtype="f4", alignment=1)
        self.fbo.read_into(inst, components=1, attachment=2, dtype="f4", alignment=1)
        instances = inst.astype(np.int32)
        instances -= 1
        return rgb, depth, instances


def look_at_base(x: float, y: float, yaw: float, height: float, tilt: float = 0.0) -> np.ndarray:
    """T_world_cam of a camera at (x, y, height) looking along ``yaw`` (helper for tests)."""
    from hiconav.types import Pose2D, camera_pose_from_base

    return camera_pose_from_base(Pose2D(x, y, yaw), height, tilt)


__all__ = [
    "RenderError",
    "Renderer",
    "gl_context",
    "house_vertices",
    "look_at_base",
    "projection",
]
