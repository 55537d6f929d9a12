"""Tolerant parsing and strict validation of model replies (subgraph verification, decomposition).

A reply is untrusted text. This module turns it into a small validated value or raises
``ReplyError(reason, detail)``; callers turn that into "not found" with the reason logged. It
accepts JSON in JSON mode, inside code fences, or embedded in prose, and rejects anything
malformed, out of range, truncated, or that tries to instruct the robot (motion words,
"ignore previous instructions", tool calls, unexpected command fields). It never produces a
command and must not raise anything but ``ReplyError`` for any input string.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

# Rejection reason codes (stable; counted in Reasoner stats and tested).
EMPTY = "empty"
TRUNCATED = "truncated"
OVERSIZED = "oversized"
MALFORMED = "malformed_json"
SCHEMA = "schema"
UNEXPECTED_FIELD = "unexpected_field"
VIEW_RANGE = "view_out_of_range"
OBJECT_RANGE = "object_out_of_range"
BBOX = "bbox_invalid"
INJECTION = "instruction_injection"
TOOL_CALL = "tool_call"
NOT_VISIBLE = "not_visible"  # a valid reply that says "not visible"; not a rejection

MAX_CONTENT_CHARS = 20_000
MAX_EVIDENCE_CHARS = 600
MAX_LABEL_CHARS = 60

# Text that addresses the robot instead of describing images. Matched case-insensitively on the
# whole reply, so an order hidden in prose around valid JSON is caught as well.
_INJECTION = re.compile(
    r"\b(?:"
    r"ignore\s+(?:all\s+|any\s+|the\s+|your\s+)?(?:previous|prior|above|earlier|system)\b"
    r"|disregard\s+(?:all\s+|the\s+|your\s+)?(?:previous|prior|above|instructions)"
    r"|(?:new|updated)\s+instructions?\s*:"
    r"|system\s+prompt"
    r"|(?:move|drive|walk|go|head|proceed)\s+"
    r"(?:forward|forwards|backward|backwards|back|ahead|straight|left|right)"
    r"|turn\s+(?:left|right|around)"
    r"|rotate\s+(?:left|right|\d)"
    r"|(?:navigate|drive|walk|proceed|go|head)\s+to\b"
    r"|stop\s+(?:the\s+)?(?:robot|mission|navigation|moving)"
    r"|(?:run|execute)\s+(?:the\s+|this\s+)?(?:command|code|script|shell)"
    r"|you\s+(?:must|should)\s+(?:now\s+)?(?:move|go|turn|stop|drive|navigate)"
    r"|set\s+(?:the\s+)?(?:velocity|speed|goal)"
    r"|cmd_vel|velocity\s*=|move_forward|turn_left|turn_right"
    r")",
    re.IGNORECASE,
)

_FENCE = re.compile(r"```(?:json|JSON)?\s*(.*?)```", re.DOTALL)


class ReplyError(Exception):
    """A reply that cannot be used; ``reason`` is one of the codes above."""

    def __init__(self, reason: str, detail: str) -> None:
        super().__init__(f"{reason}: {detail}")
        self.reason = reason
        self.detail = detail


def _no_duplicates(pairs: list[tuple[str, Any]]) -> dict:
    out: dict[str, Any] = {}
    for key, value in pairs:
        if key in out:
            raise ReplyError(SCHEMA, f"duplicate key {key!r}")
        out[key] = value
    return out


def _reject_constant(name: str) -> Any:
    raise ReplyError(SCHEMA, f"{name} in JSON (not a finite number)")


def _loads(text: str) -> Any:
    return json.loads(text, object_pairs_hook=_no_duplicates, parse_constant=_reject_constant)


def check_injection(text: str) -> None:
    """Raise ReplyError(INJECTION) if ``text`` contains instructions aimed at the robot."""
    match = _INJECTION.search(text)
    if match:
        raise ReplyError(INJECTION, f"reply gives an instruction: {match.group(0)!r}")


def check_message(content: str | None, *, finish_reason: str | None = None,
                  message: dict | None = None) -> str:
    """Common checks on an assistant message; returns the stripped content."""
    if message and (message.get("tool_calls") or message.get("function_call")):
        raise ReplyError(TOOL_CALL, "reply asks to call a tool/function")
    if finish_reason == "length":
        raise ReplyError(TRUNCATED, "reply cut off at max_tokens (finish_reason=length)")
    if finish_reason in ("tool_calls", "function_call"):
        raise ReplyError(TOOL_CALL, f"finish_reason={finish_reason}")
    if content is None or not content.strip():
        raise ReplyError(EMPTY, "reply has no content")
    if len(content) > MAX_CONTENT_CHARS:
        raise ReplyError(OVERSIZED, f"reply content too long ({len(content)} chars > {MAX_CONTENT_CHARS})")
    check_injection(content)
    return content.strip()


def extract_json(text: str) -> dict:
    """The first JSON object in ``text``: bare, in a ``` fence, or embedded in prose.

    Raises ReplyError(EMPTY | MALFORMED | TRUNCATED | SCHEMA).
    """
    text = text.strip()
    if not text:
        raise ReplyError(EMPTY, "reply has no content")
    candidates: list[str] = []
    if text.startswith(("{", "[")):
        candidates.append(text)
    candidates += [m.group(1).strip() for m in _FENCE.finditer(text)]
    last_error = "no JSON object in reply"
    for cand in candidates:
        try:
            value = _loads(cand)
        except json.JSONDecodeError as exc:
            last_error = f"{exc.msg} at line {exc.lineno} column {exc.colno}"
            continue
        if not isinstance(value, dict):
            raise ReplyError(SCHEMA, f"top-level JSON is {type(value).__name__}, not an object")
        return value
    # Embedded in prose: try every '{' with a raw decoder.
    decoder = json.JSONDecoder(object_pairs_hook=_no_duplicates, parse_constant=_reject_constant)
    for match in re.finditer(r"\{", text):
        try:
            value, _ = decoder.raw_decode(text, match.start())
        except json.JSONDecodeError as exc:
            last_error = f"{exc.msg} at column {exc.colno}"
            continue
        if isinstance(value, dict):
            return value
    if text.count("{") > text.count("}"):
        raise ReplyError(TRUNCATED, f"unbalanced braces: JSON cut off ({last_error})")
    raise ReplyError(MALFORMED, last_error)


# ---------------------------------------------------------------------------- verification

_VERIFY_FIELDS = {
    "visible": ("visible", "visibility", "target_visible"),
    "view": ("view", "anchor", "image", "view_index"),
    "object": ("object", "object_index", "object_id"),
    "bbox": ("bbox", "box", "bounding_box"),
    "evidence": ("evidence", "reason", "reasoning", "explanation"),
    "confidence": ("confidence", "score"),
    "target": ("target", "label"),
}
_ALIAS = {alias: name for name, aliases in _VERIFY_FIELDS.items() for alias in aliases}


@dataclass(frozen=True)
class VerificationReply:
    """A validated verification reply. Indices are 0-based (the prompt shows them 1-based).

    view: index into the subgraph's views; object: index into that view's object list, or None;
    bbox: (x1, y1, x2, y2) normalised to [0, 1] in that view's image.
    """

    visible: bool
    view: int | None
    object: int | None
    bbox: tuple[float, float, float, float] | None
    evidence: str
    confidence: float | None


def _as_int(value: Any, name: str) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool):
        raise ReplyError(SCHEMA, f"{name} is a boolean, expected an integer")
    if isinstance(value, int):
        return value
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, str) and re.fullmatch(r"\s*\d+\s*", value):
        return int(value)
    raise ReplyError(SCHEMA, f"{name} is {value!r}, expected an integer")


def _visible(value: Any) -> bool:
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)) and value in (1, 2):
        return value == 1
    if isinstance(value, str):
        v = value.strip().lower()
        if v in ("1", "yes", "true", "visible"):
            return True
        if v in ("2", "no", "false", "not visible", "invisible"):
            return False
    raise ReplyError(SCHEMA, f"visible is {value!r}, expected 1 (visible) or 2 (not visible)")


def _bbox(value: Any) -> tuple[float, float, float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 4:
        raise ReplyError(BBOX, f"bbox is {value!r}, expected [x1, y1, x2, y2]")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ReplyError(BBOX, f"bbox has a non-number {v!r}")
        out.append(float(v))
    x1, y1, x2, y2 = out
    if min(out) < 0.0 or max(out) > 1.0:
        raise ReplyError(BBOX, f"bbox {out} outside [0, 1] (expected normalised coordinates)")
    if not (x2 > x1 and y2 > y1):
        raise ReplyError(BBOX, f"bbox {out} is empty (need x1 < x2 and y1 < y2)")
    return x1, y1, x2, y2


def parse_verification(content: str | None, objects_per_view: Sequence[int], *,
                       finish_reason: str | None = None, message: dict | None = None) -> VerificationReply:
    """Validate a reply to the three-step verification prompt.

    objects_per_view: number of objects listed under each view (the views are numbered 1..n in
    the prompt, their objects 1..m). Raises ReplyError; a reply saying "not visible" is valid
    and returned with ``visible=False``.
    """
    text = check_message(content, finish_reason=finish_reason, message=message)
    raw = extract_json(text)
    fields: dict[str, Any] = {}
    for key, value in raw.items():
        name = _ALIAS.get(str(key).strip().lower())
        if name is None:
            raise ReplyError(UNEXPECTED_FIELD,
                             f"unexpected field {key!r} (allowed: {sorted(_VERIFY_FIELDS)})")
        if name in fields:
            raise ReplyError(SCHEMA, f"field {name!r} given twice (as {key!r})")
        fields[name] = value
    if "visible" not in fields:
        raise ReplyError(SCHEMA, "missing field 'visible'")
    evidence = fields.get("evidence") or ""
    if not isinstance(evidence, str):
        raise ReplyError(SCHEMA, f"evidence is {type(evidence).__name__}, expected a string")
    evidence = " ".join(evidence.split())[:MAX_EVIDENCE_CHARS]
    confidence = fields.get("confidence")
    if confidence is not None:
        if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) \
                or not math.isfinite(confidence) or not 0.0 <= confidence <= 1.0:
            raise ReplyError(SCHEMA, f"confidence is {confidence!r}, expected a number in [0, 1]")
        confidence = float(confidence)
    target = fields.get("target")
    if target is not None and not isinstance(target, str):
        raise ReplyError(SCHEMA, f"target is {type(target).__name__}, expected a string")
    if not _visible(fields["visible"]):
        return VerificationReply(False, None, None, None, evidence, confidence)
    view = _as_int(fields.get("view"), "view")
    n_views = len(objects_per_view)
    if view is None:
        raise ReplyError(VIEW_RANGE, "visible=1 but no view given")
    if not 1 <= view <= n_views:
        raise ReplyError(VIEW_RANGE, f"view {view} not in 1..{n_views}")
    obj = _as_int(fields.get("object"), "object")
    if obj is not None:
        n_obj = objects_per_view[view - 1]
        if not 1 <= obj <= n_obj:
            raise ReplyError(OBJECT_RANGE, f"object {obj} not in view {view}'s list 1..{n_obj}")
    if fields.get("bbox") is None:
        raise ReplyError(BBOX, "visible=1 but no bbox given")
    bbox = _bbox(fields["bbox"])
    return VerificationReply(True, view - 1, None if obj is None else obj - 1, bbox, evidence, confidence)


# ---------------------------------------------------------------------------- decomposition

_LABEL = re.compile(r"^[a-z0-9][a-z0-9 _\-']*$")
_DECOMP_FIELDS = {"targets", "related", "attributes", "relations", "reasoning", "target"}


def _label_list(value: Any, name: str, max_n: int) -> list[str]:
    if isinstance(value, str):
        value = [value]
    if not isinstance(value, list):
        raise ReplyError(SCHEMA, f"{name} is {type(value).__name__}, expected a list of strings")
    out: list[str] = []
    for item in value[:max_n]:
        if not isinstance(item, str):
            raise ReplyError(SCHEMA, f"{name} has a {type(item).__name__}, expected strings")
        label = " ".join(item.strip().lower().split())
        if not label:
            continue
        if len(label) > MAX_LABEL_CHARS or len(label.split()) > 4 or not _LABEL.match(label):
            raise ReplyError(SCHEMA, f"{name} entry {item[:80]!r} is not an object name")
        if label not in out:
            out.append(label)
    return out


@dataclass(frozen=True)
class DecompositionReply:
    """A validated decomposition: target and related object names, attributes, relations."""

    targets: tuple[str, ...]
    related: tuple[str, ...]
    attributes: dict[str, tuple[str, ...]]
    relations: tuple[tuple[str, str, str], ...]


def parse_decomposition(content: str | None, *, finish_reason: str | None = None,
                        message: dict | None = None) -> DecompositionReply:
    """Validate a reply ``{"targets": [...], "related": [...], "attributes"?, "relations"?}``."""
    text = check_message(content, finish_reason=finish_reason, message=message)
    raw = extract_json(text)
    for key in raw:
        if key not in _DECOMP_FIELDS:
            raise ReplyError(UNEXPECTED_FIELD,
                             f"unexpected field {key!r} (allowed: {sorted(_DECOMP_FIELDS)})")
    targets = _label_list(raw.get("targets", raw.get("target", [])), "targets", 5)
    if not targets:
        raise ReplyError(EMPTY, "no target object in the reply")
    related = [r for r in _label_list(raw.get("related", []), "related", 12) if r not in targets]
    attributes: dict[str, tuple[str, ...]] = {}
    attrs = raw.get("attributes", {})
    if attrs is None:
        attrs = {}
    if not isinstance(attrs, dict):
        raise ReplyError(SCHEMA, "attributes must be an object {label: [attribute, ...]}")
    for key, values in attrs.items():
        label = _label_list([key], "attributes key", 1)
        vals = _label_list(values, f"attributes[{key!r}]", 8)
        if label and vals:
            attributes[label[0]] = tuple(vals)
    relations: list[tuple[str, str, str]] = []
    rels = raw.get("relations", [])
    if rels is None:
        rels = []
    if not isinstance(rels, list):
        raise ReplyError(SCHEMA, "relations must be a list of [subject, relation, object]")
    for rel in rels[:12]:
        if not isinstance(rel, (list, tuple)) or len(rel) != 3:
            raise ReplyError(SCHEMA, f"relation {rel!r} is not [subject, relation, object]")
        if not all(isinstance(x, str) and x.strip() for x in rel):
            raise ReplyError(SCHEMA, f"relation {rel!r} has empty or non-string parts")
        s, r, o = (_label_list([x], "relation", 1)[0] for x in rel)
        relations.append((s, r, o))
    return DecompositionReply(tuple(targets), tuple(related), attributes, tuple(relations))
