"""Tolerant parsing and strict validation of model replies (subgraph verification, decomposition).

A reply is untrusted text. This module turns it into a small validated value or raises
``ReplyError(reason, detail)``; callers turn that into "not found" with the reason logged. It
accepts JSON in JSON mode, inside code fences, or embedded in prose, and rejects anything
malformed, out of range, truncated, or that tries to instruct the robot (motion words,
"ignore previous instructions", tool calls, unexpected command fields), and a verification
reply that found something other than the target asked for. It never produces a command and
must not raise anything but ``ReplyError`` for any input (str or bytes: NUL, unpaired
surrogates, huge numbers, NaN, brackets nested thousands deep), in time linear in its length:
one scan finds the candidate objects (see "the JSON scanner"), nesting is bounded by
MAX_DEPTH, integers by MAX_INT_DIGITS, the reply by MAX_CONTENT_CHARS.
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
AMBIGUOUS_OBJECT = "ambiguous_object"  # the object named by a label that several objects of the view have
WRONG_TARGET = "wrong_target"  # the reply found something other than the target asked for
BBOX = "bbox_invalid"
INJECTION = "instruction_injection"
TOOL_CALL = "tool_call"
NOT_VISIBLE = "not_visible"  # a valid reply that says "not visible"; not a rejection

MAX_CONTENT_CHARS = 20_000
MAX_EVIDENCE_CHARS = 600
MAX_LABEL_CHARS = 60
# Bounds on what the JSON scanner and decoder accept (they keep parsing linear and exception-free).
MAX_DEPTH = 64  # brackets nested in a reply
MAX_INT_DIGITS = 30  # digits of an integer literal (Python refuses to read > 4300)
MAX_NUMBER_CHARS = 64  # characters of a number literal with a fraction or an exponent
MAX_TOKENS = 1024  # brackets and strings the scanner looks at, all candidates together
MAX_CANDIDATES = 32  # '{...}' spans decoded before giving up
MAX_FENCES = 8  # ``` fences looked into
RESCAN_FACTOR = 4  # characters scanned, rescans included, per character of the reply

# Text that addresses the robot instead of describing images. Matched on the whole reply in
# lower case (lowering once is 3-4x faster than re.IGNORECASE on 20 KB), so an order hidden in
# prose around valid JSON is caught as well. Every literal below is lower case.
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
            raise ReplyError(SCHEMA, f"duplicate key {key[:80]!r}")
        out[key] = value
    return out


def _reject_constant(name: str) -> Any:
    raise ReplyError(SCHEMA, f"{name} in JSON (not a finite number)")


def _parse_int(literal: str) -> int:
    digits = len(literal) - literal.startswith("-")
    if digits > MAX_INT_DIGITS:
        raise ReplyError(SCHEMA, f"integer of {digits} digits in JSON (at most {MAX_INT_DIGITS})")
    return int(literal)


def _parse_float(literal: str) -> float:
    if len(literal) > MAX_NUMBER_CHARS:
        raise ReplyError(SCHEMA, f"number of {len(literal)} characters in JSON (at most {MAX_NUMBER_CHARS})")
    value = float(literal)
    if not math.isfinite(value):
        raise ReplyError(SCHEMA, f"number {literal!r} in JSON is not finite")
    return value


_DECODER = json.JSONDecoder(object_pairs_hook=_no_duplicates, parse_constant=_reject_constant,
                            parse_int=_parse_int, parse_float=_parse_float)


def _as_text(content: Any) -> str:
    """A reply as text: str as is, bytes as UTF-8; anything else is refused."""
    if isinstance(content, (bytes, bytearray, memoryview)):
        try:
            content = bytes(content).decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ReplyError(MALFORMED, f"reply is not UTF-8 text (byte {exc.start})") from None
    if not isinstance(content, str):
        raise ReplyError(SCHEMA, f"reply content is {type(content).__name__}, expected text")
    bad = _SURROGATE.search(content)
    if bad:
        raise ReplyError(MALFORMED, f"reply has an unpaired surrogate at character {bad.start()}")
    return content


def _decode(text: str, start: int, end: int) -> Any:
    """``text[start:end]`` as JSON; the caller has checked that it nests at most MAX_DEPTH deep.

    Raises json.JSONDecodeError (its ``pos`` absolute in ``text``) or ReplyError.
    """
    try:
        return _DECODER.decode(text[start:end])
    except json.JSONDecodeError as exc:
        raise json.JSONDecodeError(exc.msg, text, start + exc.pos) from None
    except (RecursionError, ValueError, OverflowError, MemoryError) as exc:  # bounded above; belt and braces
        raise ReplyError(MALFORMED, f"JSON at character {start} cannot be read ({type(exc).__name__})") from None


# ---------------------------------------------------------------------------- the JSON scanner
#
# One left-to-right pass finds a reply's candidate objects. Outside any bracket the text is prose
# (quotes mean nothing there, only '{' opens a candidate); inside, each JSON string is skipped
# whole by one C-level regex match and brackets are counted on a stack of at most MAX_DEPTH.
# Every '{...}' that closes is a candidate, decoded only where an enclosing candidate's decode
# did not already fail inside it. A candidate that never closes is rescanned from just after its
# '{' (that brace may have been prose) within a budget of RESCAN_FACTOR x the text's length, and
# the brackets and strings looked at are counted (MAX_TOKENS): a 20 KB reply of any shape costs a
# few linear passes, never one decode per '{' (which was quadratic).

_TOKEN = re.compile(r'[{}\[\]"]')
_STRING = re.compile(r'"[^"\\]*(?:\\.[^"\\]*)*"', re.DOTALL)
_CLOSER = {"{": "}", "[": "]"}
_SURROGATE = re.compile("[\ud800-\udfff]")


@dataclass
class _Group:
    """What scanning one bracket group found."""

    spans: list[tuple[int, int]]  # the '{...}' that closed inside it, (start, end), any order
    end: int | None  # one past the group's closing bracket; None if it did not close
    stop: int  # where the scan stopped: end, a mismatched closer, or the end of the text


@dataclass
class _Search:
    """The budgets and the last decode error of one ``extract_json`` call."""

    tokens_left: int = MAX_TOKENS
    decodes_left: int = MAX_CANDIDATES
    last_error: str = "no JSON object in reply"


def _scan_group(text: str, begin: int, limit: int, search: _Search) -> _Group:
    """Scan the bracket group that ``text[begin]`` ('{' or '[') opens, up to ``limit``.

    Raises ReplyError(MALFORMED) past MAX_DEPTH levels or when the token budget is spent.
    """
    stack = [begin]
    closers = [_CLOSER[text[begin]]]
    spans: list[tuple[int, int]] = []
    pos = begin + 1
    token, string = _TOKEN.search, _STRING.match
    while True:
        search.tokens_left -= 1
        if search.tokens_left < 0:
            raise ReplyError(MALFORMED, f"more than {MAX_TOKENS} brackets and strings: not a reply")
        m = token(text, pos, limit)
        if m is None:
            return _Group(spans, None, limit)
        c, p = m.group(), m.start()
        if c == '"':
            s = string(text, p, limit)
            if s is None:  # a string that never ends: the group cannot close
                return _Group(spans, None, limit)
            pos = s.end()
            continue
        pos = p + 1
        if c in "{[":
            if len(stack) >= MAX_DEPTH:
                raise ReplyError(MALFORMED, f"JSON nested deeper than {MAX_DEPTH} levels at character {p}")
            stack.append(p)
            closers.append(_CLOSER[c])
            continue
        if c != closers[-1]:  # '}' closing a '[' or the reverse: no JSON from here on
            return _Group(spans, None, p)
        start = stack.pop()
        closers.pop()
        if c == "}":
            spans.append((start, pos))
        if not stack:
            return _Group(spans, pos, pos)


def _first_object(text: str, begin: int, limit: int, search: _Search) -> dict | None:
    """The first ``{...}`` of ``text[begin:limit]`` that decodes as a JSON object, by its '{'."""
    chars_left = RESCAN_FACTOR * (limit - begin) + 64
    pos = begin
    while True:
        start = text.find("{", pos, limit)
        if start < 0:
            return None
        group = _scan_group(text, start, limit, search)
        failed_at = -1  # a candidate failed there: the ones around that point fail as well
        for s, e in sorted(group.spans):
            if s < failed_at < e:
                continue
            search.decodes_left -= 1
            if search.decodes_left < 0:
                raise ReplyError(MALFORMED, f"no JSON object in the first {MAX_CANDIDATES} candidates "
                                            f"({search.last_error})")
            try:
                value = _decode(text, s, e)
            except json.JSONDecodeError as exc:
                failed_at = exc.pos
                search.last_error = f"{exc.msg} at character {exc.pos}"
                continue
            if isinstance(value, dict):
                return value
        chars_left -= group.stop - start
        if group.end is not None:
            pos = group.end
        elif chars_left > 0:
            pos = start + 1  # that '{' may have been prose: read on just after it
        else:
            pos = group.stop


def _whole(text: str, search: _Search) -> Any:
    """``text`` as one JSON value. Raises json.JSONDecodeError or ReplyError (depth, numbers)."""
    begin = len(text) - len(text.lstrip(" \t\n\r"))
    if begin < len(text) and text[begin] in "{[":
        # bounds the nesting the decoder can meet: it stops at its first error, which is no later
        # than where this scan stops (a mismatched closer, an unterminated string, the end)
        _scan_group(text, begin, len(text), search)
    return _decode(text, 0, len(text))


def _loads(text: str | bytes) -> Any:
    """``text`` as one JSON value, bounded as every reply is (size, depth, numbers).

    Raises ReplyError (OVERSIZED, MALFORMED with the position, SCHEMA) and nothing else.
    """
    text = _as_text(text)
    if len(text) > MAX_CONTENT_CHARS:
        raise ReplyError(OVERSIZED, f"JSON text too long ({len(text)} chars > {MAX_CONTENT_CHARS})")
    try:
        return _whole(text, _Search())
    except json.JSONDecodeError as exc:
        raise ReplyError(MALFORMED, f"{exc.msg} at character {exc.pos}") from None


def check_injection(text: str) -> None:
    """Raise ReplyError(INJECTION) if ``text`` contains instructions aimed at the robot."""
    lower = text.lower()
    match = _INJECTION.search(lower)
    if match:
        # lower() keeps the length of almost every text; quote the reply's own words when it does
        words = text[match.start():match.end()] if len(lower) == len(text) else match.group(0)
        raise ReplyError(INJECTION, f"reply gives an instruction: {words!r}")


def check_message(content: str | bytes | None, *, finish_reason: str | None = None,
                  message: dict | None = None) -> str:
    """Common checks on an assistant message; returns the stripped content."""
    if message and (message.get("tool_calls") or message.get("function_call")):
        raise ReplyError(TOOL_CALL, "reply asks to call a tool/function")
    if finish_reason == "length":
        raise ReplyError(TRUNCATED, "reply cut off at max_tokens (finish_reason=length)")
    if finish_reason in ("tool_calls", "function_call"):
        raise ReplyError(TOOL_CALL, f"finish_reason={finish_reason}")
    if content is None:
        raise ReplyError(EMPTY, "reply has no content")
    content = _as_text(content)
    if not content.strip():
        raise ReplyError(EMPTY, "reply has no content")
    if len(content) > MAX_CONTENT_CHARS:
        raise ReplyError(OVERSIZED, f"reply content too long ({len(content)} chars > {MAX_CONTENT_CHARS})")
    check_injection(content)
    return content.strip()


def extract_json(text: str | bytes) -> dict:
    """The first JSON object in ``text``: bare, in a ``` fence, or embedded in prose.

    Linear in the length of ``text`` (at most MAX_CONTENT_CHARS), nesting at most MAX_DEPTH,
    integers of at most MAX_INT_DIGITS digits. Raises ReplyError(EMPTY | OVERSIZED | MALFORMED |
    TRUNCATED | SCHEMA) and nothing else, whatever the text.
    """
    text = _as_text(text)
    if len(text) > MAX_CONTENT_CHARS:
        raise ReplyError(OVERSIZED, f"reply content too long ({len(text)} chars > {MAX_CONTENT_CHARS})")
    text = text.strip()
    if not text:
        raise ReplyError(EMPTY, "reply has no content")
    search = _Search()
    if text[0] in "{[":
        try:
            value = _whole(text, search)
        except json.JSONDecodeError as exc:
            search.last_error = f"{exc.msg} at character {exc.pos}"
        else:
            if not isinstance(value, dict):
                raise ReplyError(SCHEMA, f"top-level JSON is {type(value).__name__}, not an object")
            return value
    for n, fence in enumerate(_FENCE.finditer(text)):
        if n >= MAX_FENCES:
            break
        value = _first_object(text, fence.start(1), fence.end(1), search)
        if value is not None:
            return value
    value = _first_object(text, 0, len(text), search)
    if value is not None:
        return value
    if text.count("{") > text.count("}"):
        raise ReplyError(TRUNCATED, f"unbalanced braces: JSON cut off ({search.last_error})")
    raise ReplyError(MALFORMED, search.last_error)


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
    bbox: (x1, y1, x2, y2) normalised to [0, 1] in that view's image; target: the target label
    asked for that the reply names (its "target" field or the object it names by label), None
    when it names none.
    """

    visible: bool
    view: int | None
    object: int | None
    bbox: tuple[float, float, float, float] | None
    evidence: str
    confidence: float | None
    target: str | None = None


def _short(value: Any) -> str:
    """``repr(value)`` cut to 80 characters, for error details."""
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


def _as_int(value: Any, name: str) -> int | None:
    if value is None:
        return None
    if isinstance(value, bool):
        raise ReplyError(SCHEMA, f"{name} is a boolean, expected an integer")
    if isinstance(value, int):
        return value
    if isinstance(value, float) and value.is_integer():
        return int(value)
    if isinstance(value, str) and re.fullmatch(rf"\s*\d{{1,{MAX_INT_DIGITS}}}\s*", value):
        return int(value)
    raise ReplyError(SCHEMA, f"{name} is {_short(value)}, expected an integer")


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
    raise ReplyError(SCHEMA, f"visible is {_short(value)}, expected 1 (visible) or 2 (not visible)")


def _bbox(value: Any) -> tuple[float, float, float, float]:
    if not isinstance(value, (list, tuple)) or len(value) != 4:
        raise ReplyError(BBOX, f"bbox is {_short(value)}, expected [x1, y1, x2, y2]")
    out = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise ReplyError(BBOX, f"bbox has a non-number {_short(v)}")
        out.append(float(v))
    x1, y1, x2, y2 = out
    if min(out) < 0.0 or max(out) > 1.0:
        raise ReplyError(BBOX, f"bbox {out} outside [0, 1] (expected normalised coordinates)")
    if not (x2 > x1 and y2 > y1):
        raise ReplyError(BBOX, f"bbox {out} is empty (need x1 < x2 and y1 < y2)")
    return x1, y1, x2, y2


def _clean(text: str) -> str:
    """Whitespace collapsed, control characters and unpaired surrogates (from \\u escapes) dropped."""
    return _CONTROL.sub("", " ".join(text.split()))


# Words after which a name goes on to say where the thing is ("mug next to the sink", "sink with
# a mug"): the thing a phrase names is the one before the first of them.
_RELATION_WORDS = frozenset(
    "next beside besides near nearby on onto in inside into under underneath beneath below above over "
    "by behind at with between against of from to left right front top and or that which is".split())
_CONTROL = re.compile("[\x00-\x1f\x7f-\x9f\ud800-\udfff]")


def _words(name: str) -> list[str]:
    """'Blue Counter_Top (next to sink)' -> ['blue', 'counter', 'top']: lower case, '_' and '-'
    as spaces, cut at a bracket or punctuation that starts a clause."""
    head = re.split(r"[(\[{,;:.!?]", name.lower(), maxsplit=1)[0]
    return re.sub(r"[^a-z0-9' ]+", " ", head.replace("_", " ").replace("-", " ")).split()


def _plural_of(word: str, singular: str) -> bool:
    return word == singular or word in (singular + "s", singular + "es") or (
        singular.endswith("y") and word == singular[:-1] + "ies")


def _names(phrase: list[str], label: list[str]) -> bool:
    """Whether the phrase's words name a ``label`` thing: the label's words occur in it (the last
    one maybe plural), with no relation word before them and only a relation word (or nothing)
    after them. "blue mug next to the sink" names a mug, not a sink; "mug rack" names no mug."""
    n = len(label)
    if not n:
        return False
    for i in range(len(phrase) - n + 1):
        if phrase[i:i + n - 1] == label[:-1] and _plural_of(phrase[i + n - 1], label[-1]) \
                and (i + n == len(phrase) or phrase[i + n] in _RELATION_WORDS):
            return True
        if phrase[i] in _RELATION_WORDS:
            return False
    return False


def _named_target(name: str, targets: Sequence[str]) -> str | None:
    """The first of ``targets`` that ``name`` names, or None."""
    phrase = _words(name)
    for target in targets:
        if _names(phrase, _words(target)):
            return target
    return None


def _object_by_label(name: str, view: int, view_labels: Sequence[str]) -> int:
    """The 1-based number of the one object of ``view`` that ``name`` names (exactly its label,
    else the longest label it names); ReplyError when none or several do."""
    phrase = _words(name)
    listed = ", ".join(f"{j} {lab.replace('_', ' ')}" for j, lab in enumerate(view_labels, start=1))
    matches = [j for j, lab in enumerate(view_labels, start=1) if _words(lab) == phrase and phrase]
    if not matches:
        named = [(len(_words(lab)), j) for j, lab in enumerate(view_labels, start=1)
                 if _names(phrase, _words(lab))]
        longest = max((n for n, _ in named), default=0)
        matches = [j for n, j in named if n == longest]
    if not matches:
        raise ReplyError(OBJECT_RANGE, f"object {_short(name)} is not in view {view}'s list ({listed or 'empty'})")
    if len(matches) > 1:
        raise ReplyError(AMBIGUOUS_OBJECT, f"object {_short(name)} names {len(matches)} objects of view {view} "
                                           f"(numbers {', '.join(map(str, matches))} of: {listed}); "
                                           "expected the object's number")
    return matches[0]


def parse_verification(content: str | bytes | None, objects_per_view: Sequence[int], *,
                       finish_reason: str | None = None, message: dict | None = None,
                       labels: Sequence[Sequence[str]] | None = None,
                       targets: Sequence[str] = ()) -> VerificationReply:
    """Validate a reply to the three-step verification prompt.

    objects_per_view: number of objects listed under each view (the views are numbered 1..n in
    the prompt, their objects 1..m). labels: the labels of those objects (``ViewIndex.labels``);
    with them a reply may name its object by label ("object": "bed") when that names exactly
    one object of the view (several: AMBIGUOUS_OBJECT). targets: the target labels asked for
    (``TaskSpec.targets``); a reply that finds something else, by its "target" field or by the
    object it names, is refused (WRONG_TARGET). Raises ReplyError; a reply saying "not visible"
    is valid and returned with ``visible=False``.
    """
    text = check_message(content, finish_reason=finish_reason, message=message)
    raw = extract_json(text)
    fields: dict[str, Any] = {}
    for key, value in raw.items():
        name = _ALIAS.get(key.strip().lower())
        if name is None:
            raise ReplyError(UNEXPECTED_FIELD,
                             f"unexpected field {_short(key)} (allowed: {sorted(_VERIFY_FIELDS)})")
        if name in fields:
            raise ReplyError(SCHEMA, f"field {name!r} given twice (as {_short(key)})")
        fields[name] = value
    if "visible" not in fields:
        raise ReplyError(SCHEMA, "missing field 'visible'")
    evidence = fields.get("evidence") or ""
    if not isinstance(evidence, str):
        raise ReplyError(SCHEMA, f"evidence is {type(evidence).__name__}, expected a string")
    evidence = _clean(evidence)[:MAX_EVIDENCE_CHARS]
    confidence = fields.get("confidence")
    if confidence is not None:
        if isinstance(confidence, bool) or not isinstance(confidence, (int, float)) \
                or not math.isfinite(confidence) or not 0.0 <= confidence <= 1.0:
            raise ReplyError(SCHEMA, f"confidence is {_short(confidence)}, expected a number in [0, 1]")
        confidence = float(confidence)
    target = fields.get("target")
    if target is not None and not isinstance(target, str):
        raise ReplyError(SCHEMA, f"target is {type(target).__name__}, expected a string")
    if not _visible(fields["visible"]):
        return VerificationReply(False, None, None, None, evidence, confidence)
    asked = " or ".join(t.replace("_", " ") for t in targets)
    found = None
    if targets and target is not None and target.strip():
        found = _named_target(target, targets)
        if found is None:
            raise ReplyError(WRONG_TARGET, f"the reply found {_short(target)}, not the target asked for ({asked})")
    view = _as_int(fields.get("view"), "view")
    n_views = len(objects_per_view)
    if view is None:
        raise ReplyError(VIEW_RANGE, "visible=1 but no view given")
    if not 1 <= view <= n_views:
        raise ReplyError(VIEW_RANGE, f"view {view} not in 1..{n_views}")
    value = fields.get("object")
    if isinstance(value, str) and labels is not None and re.search(r"[^\W\d_]", value):
        # named by its label, as many models do ("object": "bed")
        obj = _object_by_label(value, view, labels[view - 1] if view <= len(labels) else ())
        if targets:
            named = _named_target(value, targets)
            if named is None:
                raise ReplyError(WRONG_TARGET, f"the reply names object {obj} of view {view}, "
                                               f"{_short(value)}, not the target asked for ({asked})")
            found = found or named
    else:
        obj = _as_int(value, "object")
    if obj is not None:
        n_obj = objects_per_view[view - 1]
        if not 1 <= obj <= n_obj:
            raise ReplyError(OBJECT_RANGE, f"object {obj} not in view {view}'s list 1..{n_obj}")
    if fields.get("bbox") is None:
        raise ReplyError(BBOX, "visible=1 but no bbox given")
    bbox = _bbox(fields["bbox"])
    return VerificationReply(True, view - 1, None if obj is None else obj - 1, bbox, evidence, confidence,
                             found)


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
