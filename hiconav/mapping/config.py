"""Settings of the mapping area (occupancy grid, frontiers), validated by pydantic. Data only."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict, Field, ValidationInfo, field_validator


class OccupancyConfig(BaseModel):
    """mapping.occupancy.*: the 2D occupancy grid built from depth."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    resolution: float = Field(0.05, gt=0.0, description="cell side (m)")
    initial_size_m: float = Field(12.0, gt=0.0, description="side of the first grid, centred on the robot")
    grow_padding_m: float = Field(4.0, ge=0.0, description="extra margin added when the grid grows")
    max_extent_m: float = Field(
        200.0,
        gt=0.0,
        le=2000.0,
        description="the grid never grows wider or taller than this (m): a frame that would need more "
        "(a pose far off, a localisation glitch) is refused (FrameError) instead of allocating "
        "(200 m at 0.05 m is 4000 x 4000 cells, about 150 MB of layers)",
    )
    depth_stride: int = Field(4, ge=1, description="use every n-th depth pixel in both directions")
    min_depth: float = Field(0.1, ge=0.0, description="closer depth is ignored (m)")
    max_depth: float = Field(5.0, gt=0.0, description="mapping range along the optical axis (m)")
    sensor_max_depth: float = Field(
        5.0,
        gt=0.0,
        description="the camera's clip depth (m): returns at or "
        "beyond min(this, max_depth) are 'far' and hold no obstacle",
    )
    sensor_min_depth: float = Field(
        0.5,
        ge=0.0,
        description="the camera reads 0 closer than this (m); such "
        "pixels stop free-space clearing in their direction",
    )
    clear_at_max_range: bool = Field(
        True,
        description="pixels at the sensor's max depth clear free space "
        "up to the mapping range (no obstacle marked)",
    )
    floor_z: float = Field(0.0, description="world height of the floor (m)")
    obstacle_min_height: float = Field(0.1, ge=0.0, description="points below floor_z + this are floor")
    obstacle_max_height: float = Field(
        1.5,
        gt=0.0,
        description="points above floor_z + this are ignored as obstacles (the robot passes under)",
    )
    robot_radius: float = Field(0.18, gt=0.0, description="inflation radius (m)")
    inflation_margin: float = Field(
        0.05,
        ge=0.0,
        description="extra inflation beyond the robot radius (m): covers the discretisation of obstacles "
        "and the heading tolerance of discrete motion",
    )
    obstacle_pad: float = Field(
        0.5,
        ge=0.0,
        le=1.0,
        description="an obstacle point also marks the cells within this many cells of it (per axis), so "
        "a surface on a cell boundary marks both sides (the map does not depend on the grid's phase)",
    )
    free_margin: float = Field(0.05, ge=0.0, description="free space stops this far before an obstacle (m)")
    angle_bin_deg: float = Field(1.0, gt=0.0, description="angular bins of the free-space fan (deg)")
    hit_weight: int = Field(3, ge=1, description="log-odds added to a cell with obstacle points")
    miss_weight: int = Field(1, ge=0, description="log-odds removed from a cell seen free")
    logodds_clamp: int = Field(12, ge=1, le=100)
    mark_footprint_free: bool = Field(True, description="the cells under the robot are free")

    @field_validator("max_extent_m")
    @classmethod
    def _extent_holds_the_first_grid(cls, v: float, info: ValidationInfo) -> float:
        initial = info.data.get("initial_size_m")
        if initial is not None and v < initial:
            raise ValueError(f"max_extent_m must be at least initial_size_m ({initial:g} m)")
        return v


class FrontierConfig(BaseModel):
    """mapping.frontiers.*: frontier extraction and tracking."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    min_size_cells: int = Field(8, ge=1, description="smaller frontier clusters are dropped")
    max_size_cells: int = Field(400, ge=1, description="larger clusters are split along their length")
    viewpoint_search_m: float = Field(2.5, gt=0.0, description="max distance of a viewpoint to the centroid")
    match_distance_m: float = Field(1.0, ge=0.0, description="centroid distance to keep an id (no overlap)")
    drop_unreachable: bool = Field(
        True, description="drop frontiers with no viewpoint reachable from the robot"
    )
    robot_search_m: float = Field(0.5, ge=0.0, description="search radius for a free cell near the robot")
    squeeze_fallback: bool = Field(
        True, description="when no frontier has a reachable viewpoint, keep those reachable on the lethal "
        "layer one cell thinner (a passage the map's noise closed by a cell)"
    )


class PoseGateConfig(BaseModel):
    """mapping.pose_gate.*: a base pose may not move faster than the robot can between frames."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    max_speed_mps: float = Field(
        2.0,
        gt=0.0,
        le=100.0,
        description="fastest the base pose may move between frames (m/s); a frame whose pose moved farther "
        "than this times the elapsed time plus margin_m is a localisation glitch and is dropped "
        "(4x the simulator's and the rovers' 0.5 m/s)",
    )
    margin_m: float = Field(
        1.0,
        ge=0.0,
        le=100.0,
        description="jump allowed on top of the speed bound (m): odometry noise, stamps that lag the pose",
    )


class MappingConfig(BaseModel):
    """mapping.* settings."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)

    occupancy: OccupancyConfig = Field(default_factory=OccupancyConfig)
    frontiers: FrontierConfig = Field(default_factory=FrontierConfig)
    pose_gate: PoseGateConfig = Field(default_factory=PoseGateConfig)
