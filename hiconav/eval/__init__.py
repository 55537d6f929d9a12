"""Evaluation harness: run benchmark episodes in parallel, metrics (SR, SPL, DTS), the failure
taxonomy, ablation presets, summary.json and report.md. See docs/evaluation.md.

This package must not implement navigation: episodes are run by an ``EpisodeRunner`` named by
import path (default ``hiconav.mission:run_episode``).
"""

from hiconav.eval.config import DEFAULT_RUNNER, EvalConfig
from hiconav.eval.records import EpisodeRecord, RecordWriter, read_records
from hiconav.eval.runner import EpisodeRunner, evaluate, run_task
from hiconav.eval.sources import EpisodeSpec, gibson_source, procthor_source
from hiconav.eval.taxonomy import Failure, classify, last_progress_step

__all__ = [
           "DEFAULT_RUNNER",
           "EpisodeRecord",
           "EpisodeRunner",
           "EpisodeSpec",
           "EvalConfig",
           "Failure",
           "RecordWriter",
           "classify",
           "evaluate",
           "gibson_source",
           "last_progress_step",
           "procthor_source",
           "read_records",
           "run_task",
]
