"""Untrusted replies are bounded (issue #29): whatever the text, parsing ends in ReplyError or a
valid value, reads each reply in a bounded number of linear passes, and a verification reply
is about the target that was asked for (an object may be named by an unambiguous label).

Speed is measured, not asserted, by benchmarks/reply_parsing.py; here the decoder's work is
counted instead, which does not depend on how busy the machine is.
"""

from __future__ import annotations

import json
import random

import pytest

from hiconav.reasoning import replies
from hiconav.reasoning.replies import ReplyError, extract_json, parse_decomposition, parse_verification

VIEWS = (3, 2, 1)
LABELS = (("sink", "mug", "counter_top"), ("mug", "chair"), ("sofa",))
TARGETS = ("mug",)
GOOD = {"visible": 1, "view": 1, "object": 2, "bbox": [0.4, 0.3, 0.55, 0.6], "confidence": 0.9,
        "evidence": "A blue mug next to the sink."}


def verify(reply: dict | str | bytes, **kw) -> replies.VerificationReply:
    text = reply if isinstance(reply, (str, bytes)) else json.dumps(reply)
    kw.setdefault("labels", LABELS)
    kw.setdefault("targets", TARGETS)
    return parse_verification(text, kw.pop("views", VIEWS), **kw)


def reason_of(fn, *args, **kw) -> str:
    with pytest.raises(ReplyError) as info:
        fn(*args, **kw)
    return info.value.reason


# ---------------------------------------------------------------------------- deep nesting

@pytest.mark.parametrize("text", ["[" * 5000, "{" * 5000, '{"a":' * 3000, '{"a": [' * 2000,
                                  "Answer: " + '{"v": [' * 2000, "```json\n" + "[{" * 3000 + "\n```"])
def test_thousands_of_nested_brackets_are_a_reply_error_not_a_recursion_error(text: str) -> None:
    assert reason_of(extract_json, text) == replies.MALFORMED


def test_loads_refuses_deep_nesting_with_a_reply_error() -> None:
    with pytest.raises(ReplyError) as info:
        replies._loads("[" * 5000 + "]" * 5000)
    assert info.value.reason == replies.MALFORMED and "deeper than 64" in info.value.detail


def test_nesting_up_to_the_bound_is_read_and_one_more_level_is_refused() -> None:
    def nested(levels: int) -> str:  # the reply object itself is the first level
        return '{"visible": 2, "evidence": "none", "view": ' + "[" * (levels - 1) + "]" * (levels - 1) + "}"

    assert not verify(nested(replies.MAX_DEPTH)).visible
    assert reason_of(verify, nested(replies.MAX_DEPTH + 1)) == replies.MALFORMED


# ---------------------------------------------------------------------------- huge numbers

def test_an_integer_of_5000_digits_is_a_schema_error_not_a_value_error() -> None:
    text = '{"visible": 1, "view": ' + "9" * 5000 + ', "bbox": [0.1, 0.2, 0.3, 0.4]}'
    with pytest.raises(ReplyError) as info:
        extract_json(text)
    assert info.value.reason == replies.SCHEMA and "5000 digits" in info.value.detail


def test_an_integer_of_30_digits_is_read_and_judged_as_a_view_number() -> None:
    assert reason_of(verify, {**GOOD, "view": 10 ** 29}) == replies.VIEW_RANGE
    assert reason_of(verify, {**GOOD, "view": 10 ** 30}) == replies.SCHEMA


def test_a_view_given_as_a_5000_digit_string_is_a_schema_error() -> None:
    assert reason_of(verify, {**GOOD, "view": "9" * 5000}) == replies.SCHEMA


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity", "1e999", "-1e400", "0." + "1" * 100])
def test_non_finite_and_overlong_numbers_are_schema_errors(literal: str) -> None:
    text = '{"visible": 1, "view": 1, "confidence": ' + literal + ', "bbox": [0.1, 0.2, 0.3, 0.4]}'
    assert reason_of(verify, text) == replies.SCHEMA


# ---------------------------------------------------------------------------- linear time

def count_decoded(monkeypatch) -> list[int]:
    """Wrap the decoder; returns the list of lengths it is given."""
    sizes: list[int] = []
    decode = replies._decode

    def counting(text: str, start: int, end: int):
        sizes.append(end - start)
        return decode(text, start, end)

    monkeypatch.setattr(replies, "_decode", counting)
    return sizes


HOSTILE_20KB = {
    "braces": "{" * 19_999 + "}",
    "open_string_keys": ('{"a' * 7000)[:20_000],
    "bad_pairs": ("{x}" * 7000)[:20_000],
    "nested_then_fail": '{"a":' * 60 + '"' + "x" * 19_000 + '" x' + "}" * 60,
    "prose_braces": ("the mug {maybe} is near the sink. " * 600)[:19_900] + json.dumps(GOOD)[:90],
}


@pytest.mark.parametrize("name", sorted(HOSTILE_20KB))
def test_a_20kb_hostile_reply_is_decoded_a_bounded_number_of_times(monkeypatch, name: str) -> None:
    """One decode per '{' made 20 KB of braces quadratic; now the decoder sees at most
    MAX_CANDIDATES spans and at most a few times the reply's length in all."""
    text = HOSTILE_20KB[name]
    assert len(text) <= replies.MAX_CONTENT_CHARS
    sizes = count_decoded(monkeypatch)
    with pytest.raises(ReplyError):
        parse_verification(text, VIEWS)
    assert len(sizes) <= replies.MAX_CANDIDATES + 1
    assert sum(sizes) <= 2 * len(text)


def test_candidates_inside_a_failed_one_are_not_decoded_again(monkeypatch) -> None:
    text = '{"a": ' * 30 + '"x" oops' + "}" * 30  # every object fails at the same place
    sizes = count_decoded(monkeypatch)
    with pytest.raises(ReplyError):
        extract_json(text)
    assert len(sizes) == 2  # the whole text once, then the outermost candidate; the 29 inside skipped


def test_an_object_after_a_failed_one_in_the_same_braces_is_still_found() -> None:
    assert extract_json('{"answer" {"visible": 2}}') == {"visible": 2}
    assert extract_json('note {x} then {"visible": 2} and {"visible": 1}') == {"visible": 2}


def test_an_object_after_a_stray_brace_and_quote_in_prose_is_found() -> None:
    assert extract_json('I think { it"s this: {"visible": 2, "evidence": "none"}') == \
        {"visible": 2, "evidence": "none"}


def test_a_reply_longer_than_the_bound_is_oversized() -> None:
    text = json.dumps({**GOOD, "evidence": "m" * replies.MAX_CONTENT_CHARS})
    assert reason_of(extract_json, text) == replies.OVERSIZED


# ---------------------------------------------------------------------------- odd text

def test_a_reply_may_be_utf8_bytes() -> None:
    assert verify(json.dumps(GOOD).encode()).visible
    assert reason_of(verify, b'{"visible": 1, "evidence": "\xff\xfe"}') == replies.MALFORMED


def test_a_non_text_reply_is_a_schema_error() -> None:
    assert reason_of(extract_json, 42) == replies.SCHEMA


def test_an_unpaired_surrogate_in_the_text_is_malformed() -> None:
    assert reason_of(verify, '{"visible": 2, "evidence": "\ud800"}') == replies.MALFORMED


def test_escaped_surrogates_and_control_characters_are_dropped_from_the_evidence() -> None:
    r = verify('{"visible": 2, "evidence": "no \\ud800mug\\u0000 \\u001b[31mhere"}')
    assert r.evidence == "no mug [31mhere"
    r.evidence.encode("utf-8")  # safe to write to any log


def test_a_raw_nul_inside_a_json_string_is_malformed() -> None:
    assert reason_of(extract_json, '{"visible": 2, "evidence": "a\x00b"}') == replies.MALFORMED


# ---------------------------------------------------------------------------- the target asked for

def test_a_reply_whose_target_is_something_else_is_refused() -> None:
    with pytest.raises(ReplyError) as info:
        verify({**GOOD, "target": "sofa"})
    assert info.value.reason == replies.WRONG_TARGET and "'sofa'" in info.value.detail
    assert "mug" in info.value.detail


@pytest.mark.parametrize("target", ["mug", "Blue Mug", "blue mug (next to sink)", "blue mug next to the sink",
                                    "mugs", "coffee_mug"])
def test_a_target_that_names_the_target_is_accepted(target: str) -> None:
    r = verify({**GOOD, "target": target})
    assert r.visible and r.target == "mug"


@pytest.mark.parametrize("target", ["sink next to the mug", "mug rack", "counter with a mug", "bed"])
def test_a_target_whose_head_is_another_thing_is_refused(target: str) -> None:
    assert reason_of(verify, {**GOOD, "target": target}) == replies.WRONG_TARGET


def test_a_not_visible_reply_is_not_judged_by_its_target() -> None:
    assert not verify({"visible": 2, "target": "none", "evidence": "no mug"}).visible


def test_without_targets_the_target_field_is_not_checked() -> None:
    assert parse_verification(json.dumps({**GOOD, "target": "sofa"}), VIEWS).visible


def test_the_reply_names_which_of_several_targets_it_found() -> None:
    r = verify({**GOOD, "view": 3, "object": 1, "bbox": [0.1, 0.1, 0.9, 0.9], "target": "couch"},
               targets=("sofa", "couch"))
    assert r.target == "couch"


# ---------------------------------------------------------------------------- objects named by label

def test_an_object_named_by_its_label_is_the_one_object_with_that_label() -> None:
    r = verify({**GOOD, "object": "mug"})
    assert r.view == 0 and r.object == 1 and r.target == "mug"


def test_a_described_label_names_the_object_it_ends_with() -> None:
    assert verify({**GOOD, "view": 2, "object": "Blue Mug", "bbox": [0.1, 0.2, 0.2, 0.3]}).object == 0


def test_a_label_with_underscores_is_named_with_spaces() -> None:
    r = verify({**GOOD, "object": "counter top", "bbox": [0.5, 0.5, 0.9, 0.9]}, targets=("counter_top",))
    assert r.object == 2 and r.target == "counter_top"


def test_a_label_that_several_objects_of_the_view_have_is_ambiguous() -> None:
    labels = (("mug", "sink", "mug"), ("chair",), ("sofa",))
    with pytest.raises(ReplyError) as info:
        verify({**GOOD, "object": "mug"}, labels=labels)
    assert info.value.reason == replies.AMBIGUOUS_OBJECT
    assert "numbers 1, 3" in info.value.detail and "expected the object's number" in info.value.detail


def test_the_exact_label_wins_over_a_shorter_one_it_contains() -> None:
    labels = (("mug", "coffee_mug", "sink"), ("chair",), ("sofa",))
    assert verify({**GOOD, "object": "coffee mug"}, labels=labels, targets=("coffee_mug",)).object == 1


def test_a_label_not_in_the_view_is_out_of_range_with_the_view_listed() -> None:
    with pytest.raises(ReplyError) as info:
        verify({**GOOD, "view": 3, "object": "mug"})
    assert info.value.reason == replies.OBJECT_RANGE and "1 sofa" in info.value.detail


def test_an_object_named_by_the_label_of_another_thing_is_refused() -> None:
    with pytest.raises(ReplyError) as info:
        verify({**GOOD, "object": "sink"})
    assert info.value.reason == replies.WRONG_TARGET and "'sink'" in info.value.detail


def test_without_labels_an_object_name_is_a_schema_error_as_before() -> None:
    assert reason_of(parse_verification, json.dumps({**GOOD, "object": "mug"}), VIEWS) == replies.SCHEMA


def test_numbers_as_strings_are_still_numbers() -> None:
    assert verify({**GOOD, "object": " 3 ", "bbox": [0.5, 0.5, 0.9, 0.9]}, targets=()).object == 2


# ---------------------------------------------------------------------------- property: anything in

def hostile_texts(n: int, seed: int) -> list[str | bytes]:
    rng = random.Random(seed)
    good = json.dumps(GOOD)
    pieces = ['{', '}', '[', ']', '"', '\\', ':', ',', ' ', '\n', 'NaN', 'Infinity', '-', 'e', '1', '0.5', 'true',
              'null', '"visible"', '"view"', '"object"', '"bbox"', '"mug"', '"target"', '```', '```json',
              '\x00', '\ud800', '\\ud800', '\\u0000', 'é', '😀', '9' * 40, '9' * 5000, '[' * 100, '{' * 100,
              '{"a":' * 80, good, good[:40]]
    out: list[str | bytes] = []
    for i in range(n):
        kind = i % 5
        if kind == 0:  # random bytes
            out.append(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400))))
        elif kind == 1:  # random bytes read leniently into a str (lone surrogates included)
            raw = bytes(rng.randrange(256) for _ in range(rng.randrange(1, 400)))
            out.append(raw.decode("utf-8", "surrogateescape"))
        elif kind == 2:  # JSON-ish pieces glued at random
            out.append("".join(rng.choice(pieces) for _ in range(rng.randrange(1, 60))))
        elif kind == 3:  # a good reply with pieces spliced in
            t = good
            for _ in range(rng.randrange(1, 5)):
                j = rng.randrange(len(t) + 1)
                t = t[:j] + rng.choice(pieces) + t[j + rng.randrange(3):]
            out.append(t)
        else:  # random nesting of brackets around values
            depth = rng.randrange(0, 150)
            opens = [rng.choice("{[") for _ in range(depth)]
            body = "".join(o + ('"k": ' if o == "{" else "") for o in opens) + rng.choice(["1", '"x"', good])
            closes = "".join("}" if o == "{" else "]" for o in reversed(opens))
            if rng.random() < 0.5:
                closes = closes[: rng.randrange(len(closes) + 1)]
            out.append(body + closes)
    return out


def check_valid(r: replies.VerificationReply) -> None:
    assert len(r.evidence) <= replies.MAX_EVIDENCE_CHARS
    r.evidence.encode("utf-8")
    if r.visible:
        assert r.view is not None and 0 <= r.view < len(VIEWS)
        assert r.object is None or 0 <= r.object < VIEWS[r.view]
        assert r.bbox is not None and all(0.0 <= v <= 1.0 for v in r.bbox)
        assert r.target in (None, "mug")


def test_hundreds_of_hostile_texts_give_a_reply_error_or_a_valid_reply() -> None:
    texts = hostile_texts(400, seed=29)
    outcomes = {"valid": 0, "error": 0}
    for text in texts:
        for call in (lambda t: check_valid(verify(t)), lambda t: parse_decomposition(t),
                     lambda t: isinstance(extract_json(t), dict) or pytest.fail("not a dict")):
            try:
                call(text)
                outcomes["valid"] += 1
            except ReplyError as exc:
                assert exc.reason and isinstance(exc.detail, str)
                outcomes["error"] += 1
    assert outcomes["error"] > 0 and outcomes["valid"] > 0  # the generator reaches both ends
