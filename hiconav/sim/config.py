"""Simulator configuration (typed, validated at load).

Defaults follow Habitat ObjectNav (640x480, HFOV 79 deg, camera 0.88 m, depth 0.5-5.0 m,
forward 0.25 m, turn 30 deg, success 1.0 m geodesic within 500 steps). This module only holds
settings; it must not import the renderer or touch data files.
"""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field


class SimConfig(BaseModel):
    """Settings of one simulator instance. Lengths in metres, angles in degrees."""

    model_config = ConfigDict(frozen=True, extra="forbid", allow_inf_nan=False)

    width: int = Field(640, gt=0, description="image width (pixels)")
    height: int = Field(480, gt=0, description="image height (pixels)")
    hfov_deg: float = Field(79.0, gt=0.0, lt=180.0, description="horizontal field of view")
    camera_height: float = Field(0.88, gt=0.0, description="camera above the floor (m)")
    min_depth: float = Field(0.5, ge=0.0, description="depth below this reads 0 (m)")
    max_depth: float = Field(5.0, gt=0.0, description="depth beyond this reads 0 (m)")
    forward_step: float = Field(0.25, gt=0.0, description="move_forward distance (m)")
    turn_deg: float = Field(30.0, gt=0.0, description="turn_left/turn_right angle")
    tilt_deg: float = Field(30.0, gt=0.0, description="look_up/look_down angle")
    max_tilt_deg: float = Field(60.0, ge=0.0, description="limit of the camera pitch")
    robot_radius: float = Field(0.18, gt=0.0, description="robot disc radius (m)")
    allow_sliding: bool = Field(True, description="a blocked move slides along the obstacle (Habitat-Sim's "
                                "default) instead of stopping dead")
    success_distance: float = Field(1.0, ge=0.0, description="geodesic success radius (m)")
    max_steps: int = Field(500, gt=0, description="episode step limit")
    texture_noise: float = Field(0.12, ge=0.0, le=1.0,
                                 description="amplitude of the procedural colour noise")
