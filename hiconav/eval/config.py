"""Settings of the evaluation harness (``hiconav eval``), validated on construction.

This module must not run anything; ``hiconav.eval.runner.evaluate`` consumes it.
"""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

#: Import path of the per-episode runner: ``module:function`` with the ``EpisodeRunner`` signature.
DEFAULT_RUNNER = "hiconav.mission:run_episode"


class EvalConfig(BaseModel):
    """How to run a benchmark: which runner, presets, backend and seeds."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    runner: str = Field(DEFAULT_RUNNER, description="import path module:function of the episode runner")
    presets: tuple[str, ...] = Field(("full",), description="preset names (see hiconav.eval.presets)")
    overrides: dict[str, Any] = Field(default_factory=dict, description="dotted settings applied on top of every preset")
    seed: int = Field(0, description="base seed; each episode's seed is derived from it and the episode id")
    workers: int | None = Field(None, ge=0, description="worker processes (None = core count, 0 = in this process)")
    backend: Literal["local", "ray"] = "local"
    address: str | None = Field(None, description="Ray cluster address (ray backend); None starts a local instance")
    start_method: Literal["forkserver", "spawn"] = Field("forkserver", description="multiprocessing context of local workers")
    stuck_window: int = Field(50, ge=1, description="steps without progress that make a failure 'stuck'")
    progress: bool = Field(True, description="show a progress bar (ETA, running SR and SPL)")
    report: bool = Field(True, description="write summary.json, report.md and plots at the end")
