"""Baseline and ablation presets of ``hiconav eval``, as config overrides.

A preset is a flat dict of dotted settings paths -> values (``"exploration.utility.use_vis": False``)
that the episode runner applies on top of its defaults (``hiconav.settings``). The full method
is the empty override; every ablation switches one part of the method off, so that its effect
is measured on the same episodes with the same seeds. ``--preset ablations`` runs them all.

This module must not import the method's modules: it only names settings.
"""

from __future__ import annotations

from typing import Any

from hiconav.errors import ConfigError
from hiconav.settings import nest  # noqa: F401  (re-exported: runners with nested settings use it)

# Settings paths (owned by the exploration, memory and mission areas; hiconav/<area>/config.py):
#   exploration.ordering.ordering   "wtrp" (the method) | "greedy_utility" | "nearest"
#   exploration.utility.use_struct  S_struct on/off  (S(f) = l1 S_struct + l2 S_vis, frontier utility)
#   exploration.utility.use_vis     S_vis on/off (out-of-boundary visual evidence)
#   memory.prune                    ILP anchor pruning (weighted set multicover) on/off
#   mission.verify                  VerifyTarget with fresh views before stopping on/off
#   mission.reasoning               subgraph verification by the reasoning layer on/off
#   mission.sync_reasoning          the robot holds still while a reasoning call is in flight
PRESETS: dict[str, dict[str, Any]] = {
    "full": {},
    "greedy_nearest": {"exploration.ordering.ordering": "nearest", "exploration.utility.use_struct": False,
                       "exploration.utility.use_vis": False},
    "utility_greedy": {"exploration.ordering.ordering": "greedy_utility"},
    "no_struct": {"exploration.utility.use_struct": False},
    "no_vis": {"exploration.utility.use_vis": False},
    "no_ilp": {"memory.prune": False},
    "no_verify": {"mission.verify": False},
    "no_reasoning": {"mission.reasoning": False},
    "sync_reasoning": {"mission.sync_reasoning": True},
}

#: What each preset removes, as the report's ablation table labels it.
DESCRIPTIONS: dict[str, str] = {
    "full": "Ours (full system)",
    "greedy_nearest": "greedy nearest frontier (no utility, no WTRP)",
    "utility_greedy": "w/o WTRP formulation (utility, greedy order)",
    "no_struct": "w/o structural-semantic score S_struct",
    "no_vis": "w/o out-of-boundary score S_vis",
    "no_ilp": "w/o ILP anchor pruning",
    "no_verify": "w/o target verification",
    "no_reasoning": "w/o reasoning (memory label matches only)",
    "sync_reasoning": "synchronous reasoning (robot holds during each call)",
}

GROUPS: dict[str, tuple[str, ...]] = {"ablations": tuple(PRESETS)}


def resolve_presets(names: str | list[str] | tuple[str, ...]) -> list[str]:
    """Expand a comma-separated list of preset or group names, keeping order, no duplicates."""
    if isinstance(names, str):
        names = [names]
    out: list[str] = []
    for item in names:
        for name in (n.strip() for n in item.split(",")):
            if not name:
                continue
            expanded = GROUPS.get(name, (name,))
            for preset in expanded:
                if preset not in PRESETS:
                    known = ", ".join([*PRESETS, *GROUPS])
                    raise ConfigError(f"unknown preset {preset!r}; known: {known}", field="preset")
                if preset not in out:
                    out.append(preset)
    if not out:
        raise ConfigError("no preset given", field="preset")
    return out


def overrides_for(preset: str, extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """The preset's overrides with ``extra`` (from ``--set``) applied on top."""
    if preset not in PRESETS:
        raise ConfigError(f"unknown preset {preset!r}; known: {', '.join(PRESETS)}", field="preset")
    return {**PRESETS[preset], **(extra or {})}


