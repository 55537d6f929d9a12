"""Prompts for the VLM: instruction decomposition and the three-step subgraph verification.

Paper, section "Deep Reasoning", paragraph "VLM Reasoning": given the instruction T and one
subgraph (<= k visual anchors with their objects), the VLM (1) assesses the visibility of the
target across all anchors (1 = visible, 2 = not visible), (2) selects the most relevant anchor
and localises the target with a bounding box, and (3) gives concise evidence.

This module builds OpenAI chat ``messages`` only; it does not send them and does not parse
replies. Views are numbered from 1 and objects within a view from 1 in the text; ``ViewIndex``
maps those numbers back to anchor and object-node ids.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from hiconav.types import TaskSpec

SYSTEM_VERIFY = (
    "You are the visual reasoning module of a home robot that searches for objects. You look at "
    "images from the robot's memory and answer one question about them. You never give movement "
    "or control instructions and never call tools. Reply with one JSON object and nothing else."
)

SYSTEM_DECOMPOSE = (
    "You turn a navigation instruction for a home robot into object names. Reply with one JSON "
    "object and nothing else."
)


@dataclass(frozen=True)
class ViewIndex:
    """Maps the prompt's numbering back to memory ids.

    anchor_ids[i]: the anchor shown as view i + 1; object_ids[i][j]: the object node listed as
    object j + 1 under that view; labels[i][j]: its label.
    """

    anchor_ids: tuple[int, ...]
    object_ids: tuple[tuple[int, ...], ...]
    labels: tuple[tuple[str, ...], ...]

    @property
    def objects_per_view(self) -> tuple[int, ...]:
        return tuple(len(o) for o in self.object_ids)


def describe_target(task: TaskSpec) -> str:
    """'blue mug (next to sink)'-style description of the target set O_t."""
    parts = []
    for t in task.targets:
        attrs = " ".join(task.attributes.get(t, ()))
        name = f"{attrs} {t.replace('_', ' ')}".strip()
        rels = [f"{r} {o.replace('_', ' ')}" for s, r, o in task.relations if s == t]
        parts.append(f"{name} ({'; '.join(rels)})" if rels else name)
    return " or ".join(parts)


def _fmt_box(box: Any) -> str:
    b = np.asarray(box, dtype=float).reshape(4)
    return "[" + ", ".join(f"{v:.2f}" for v in b) + "]"


def verification_messages(task: TaskSpec, subgraph: Any, *, k: int = 5, max_objects: int = 40,
                          images: bool = True, image_format: str = "jpeg", image_max_side: int = 512,
                          jpeg_quality: int = 85) -> tuple[list[dict], ViewIndex]:
    """Messages for one subgraph (<= k anchors, highest-priority order as given) and the index.

    subgraph: a ``hiconav.memory.Subgraph`` (``anchors``: AnchorView with ``id``, ``image`` (h, w, 3)
    uint8 RGB, ``object_ids``, ``boxes`` (n, 4) normalised xyxy, ``labels_seen``; ``objects``:
    ObjectView with ``id``, ``label``). ``images=False`` sends only the object lists (text-only
    models).
    """
    from hiconav.reasoning.vlm_client import image_data_url

    objects = {o.id: o for o in subgraph.objects}
    anchor_ids, object_ids, labels = [], [], []
    content: list[dict] = []
    anchors = list(subgraph.anchors)[:k]
    target = describe_target(task)
    related = ", ".join(r.replace("_", " ") for r in task.related) or "none"
    header = (
        f"Task instruction: {task.instruction}\n"
        f"Target: {target}\n"
        f"Related objects (context only): {related}\n"
        f"You are given {len(anchors)} view(s) of the house, numbered 1 to {len(anchors)}. Under "
        "each view are the objects detected in it, numbered from 1, each with its box as "
        "normalised [x1, y1, x2, y2] (0 to 1, origin at the top-left of the image).\n"
    )
    content.append({"type": "text", "text": header})
    for vi, anchor in enumerate(anchors, start=1):
        ids, labs, lines = [], [], []
        boxes = np.asarray(getattr(anchor, "boxes", np.zeros((0, 4))), dtype=float).reshape(-1, 4)
        for j, oid in enumerate(anchor.object_ids):
            if oid not in objects or len(ids) >= max_objects:
                continue
            ids.append(int(oid))
            labs.append(objects[oid].label)
            box = f" {_fmt_box(boxes[j])}" if j < len(boxes) else ""
            lines.append(f"  {len(ids)}. {objects[oid].label.replace('_', ' ')}{box}")
        anchor_ids.append(int(anchor.id))
        object_ids.append(tuple(ids))
        labels.append(tuple(labs))
        seen = [s for s in dict.fromkeys(getattr(anchor, "labels_seen", ())) if s not in labs]
        text = f"View {vi}: objects:\n" + ("\n".join(lines) if lines else "  (none listed)")
        if seen:
            text += "\n  also seen farther away: " + ", ".join(s.replace("_", " ") for s in seen[:20])
        content.append({"type": "text", "text": text})
        image = getattr(anchor, "image", None)
        if images and image is not None and np.asarray(image).size > 0:
            url = image_data_url(np.asarray(image), image_format, image_max_side, jpeg_quality)
            content.append({"type": "image_url", "image_url": {"url": url}})
    content.append({"type": "text", "text": (
        "Answer in three steps.\n"
        "Step 1: is the target visible in any view? visible = 1 if yes, 2 if no.\n"
        "Step 2: if visible = 1, choose the one view where the target is seen best (view, its "
        "number), the number of the target in that view's object list (object, or null if it is "
        "not listed), and the target's bounding box in that view as normalised "
        "[x1, y1, x2, y2] (bbox).\n"
        "Step 3: give one sentence of evidence for your answer.\n"
        'Reply with JSON only: {"visible": 1 or 2, "view": number or null, "object": number or '
        'null, "bbox": [x1, y1, x2, y2] or null, "confidence": 0 to 1, "evidence": "..."}'
    )})
    messages = [{"role": "system", "content": SYSTEM_VERIFY}, {"role": "user", "content": content}]
    return messages, ViewIndex(tuple(anchor_ids), tuple(object_ids), tuple(labels))


def decomposition_messages(instruction: str, vocabulary: Sequence[str] = ()) -> list[dict]:
    """Messages asking for {"targets": [...], "related": [...], "attributes": {...}, "relations": [...]}."""
    vocab = ", ".join(v.replace("_", " ") for v in vocabulary[:150])
    user = (
        f"Instruction: {instruction}\n"
        "List the target objects (whose sighting completes the instruction) and up to 6 related "
        "objects that are usually found near the target (cues for where to look).\n"
        + (f"Prefer these object names where they fit: {vocab}.\n" if vocab else "")
        + 'Reply with JSON only: {"targets": ["..."], "related": ["..."], '
        '"attributes": {"target name": ["colour, material or size words"]}, '
        '"relations": [["target name", "relation", "object name"]]}'
    )
    return [{"role": "system", "content": SYSTEM_DECOMPOSE}, {"role": "user", "content": user}]
