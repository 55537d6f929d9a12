"""``hiconav parse``: decompose an instruction into targets and related objects, print JSON.

Uses the offline parser unless a VLM endpoint is configured (``--base-url``, the environment
variable ``HICONAV_VLM_BASE_URL``, or ``reasoning.vlm.base_url`` in the settings); the printed
JSON names the backend that answered in ``source``. Heavy imports stay inside the function.
"""

from __future__ import annotations

import json
import os

import typer


def parse(
    instruction: str = typer.Argument(..., help='The instruction, e.g. "find the blue mug beside the sink".'),
    base_url: str = typer.Option(None, "--base-url", help="OpenAI-compatible endpoint, e.g. "
                                 "http://127.0.0.1:8080/v1 (default: $HICONAV_VLM_BASE_URL or settings)."),
    model: str = typer.Option(None, "--model", help="Model name sent to the endpoint."),
    offline: bool = typer.Option(False, "--offline",
                                 help="Use the offline parser even if an endpoint is set."),
    no_json_mode: bool = typer.Option(False, "--no-json-mode",
                                      help="Do not send response_format json_object."),
    timeout: float = typer.Option(None, "--timeout", help="Request timeout in seconds."),
    embeddings: bool = typer.Option(True, "--embeddings/--no-embeddings",
                                    help="Map unknown nouns to the vocabulary with MiniLM similarity."),
) -> None:
    """Decompose an instruction into target and related objects (printed as JSON)."""
    from hiconav.reasoning.config import ReasoningConfig
    from hiconav.reasoning.decompose import decompose_instruction, default_similarity

    config = _load_config()
    vlm = config.vlm.model_dump()
    url = base_url or os.environ.get("HICONAV_VLM_BASE_URL") or vlm.get("base_url")
    vlm["base_url"] = None if offline else url
    if model:
        vlm["model"] = model
    if no_json_mode:
        vlm["json_mode"] = False
    if timeout:
        vlm["timeout_s"] = timeout
    data = config.model_dump()
    data["vlm"] = vlm
    if offline:
        data["backend"] = "offline"
    config = ReasoningConfig.model_validate(data)
    similarity = default_similarity() if embeddings else (lambda a, b: 0.0)
    task = decompose_instruction(instruction, config, similarity=similarity)
    out = task.to_json()
    if task.source == "offline":
        out["note"] = ("offline rule-based parser (no VLM endpoint configured)" if not config.use_vlm()
                       else "FALLBACK: the VLM failed; offline rule-based parser (see log)")
    typer.echo(json.dumps(out))


def _load_config():
    """ReasoningConfig from hiconav.settings when the lead's settings module provides one."""
    from hiconav.reasoning.config import ReasoningConfig

    try:
        from hiconav import settings  # type: ignore[attr-defined]

        loaded = settings.load_settings()
        reasoning = getattr(loaded, "reasoning", None)
        if isinstance(reasoning, ReasoningConfig):
            return reasoning
    except (ImportError, AttributeError):
        pass
    return ReasoningConfig()


def room_prior(
    houses: str = typer.Option(..., "--houses", help="A ProcTHOR houses file (.jsonl or .jsonl.gz), anywhere on "
                               "disk: training houses only, never those you report on."),
    out: str = typer.Option(None, "--out", help="Where to write the counts (default: the shipped "
                            "hiconav/reasoning/room_prior.json)."),
) -> None:
    """Count object categories per room type in houses: the room prior the offline reasoner infers
    rooms from (``reasoning.offline.room_prior`` points it at a file of your own)."""
    from pathlib import Path

    from hiconav.reasoning import room_prior as rp

    target = out or str(rp.DEFAULT_FILE)
    prior = rp.learn(rp.houses_of(houses), source=Path(houses).name)
    if not prior.counts:
        raise typer.BadParameter(f"{houses}: no object stands in a bedroom, bathroom, kitchen or living room",
                                 param_hint="--houses")
    rp.save(prior, target)
    n = sum(sum(c.values()) for c in prior.counts.values())
    typer.echo(json.dumps({"houses": houses, "categories": len(prior.counts), "objects": n, "out": target}))


def size_prior(
    houses: str = typer.Option(..., "--houses", help="A ProcTHOR houses file (.jsonl or .jsonl.gz), anywhere on "
                               "disk: training houses only, never those you report on."),
    out: str = typer.Option(None, "--out", help="Where to write the sizes (default: the shipped "
                            "hiconav/reasoning/size_prior.json)."),
    min_count: int = typer.Option(5, "--min-count", min=1, help="Categories with fewer instances get no size."),
) -> None:
    """Median footprint sides of each object category in houses: the size prior the offline
    reasoner tells a box seen in part by (``reasoning.offline.size_prior`` points it at a file of
    your own)."""
    from pathlib import Path

    from hiconav.reasoning import room_prior as rp
    from hiconav.reasoning import size_prior as sp

    target = out or str(sp.DEFAULT_FILE)
    prior = sp.learn(rp.houses_of(houses), source=Path(houses).name, min_count=min_count)
    if not prior.sizes:
        raise typer.BadParameter(f"{houses}: no category has {min_count} instances or more", param_hint="--houses")
    sp.save(prior, target)
    typer.echo(json.dumps({"houses": houses, "categories": len(prior.sizes),
                           "objects": sum(prior.counts.values()), "out": target}))
