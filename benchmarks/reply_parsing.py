"""Reply parsing speed on hostile replies: the worst parse time of a 20 KB reply.

A VLM reply is untrusted text of up to ``replies.MAX_CONTENT_CHARS`` (20,000) characters. Each
reply below is exactly that long and built to be slow for a naive parser: thousands of '{' or
'[', strings that never end, escapes, mismatched brackets, a huge integer, 64 levels of objects
that fail at the very end, many fences, injection-like words, seeded random JSON-ish noise. For
each reply the script times ``parse_verification`` (the whole path: message checks, injection
scan, JSON extraction, validation) and ``extract_json`` alone, takes the median of ``--repeat``
runs (the machine is shared), and prints one line per reply, then one JSON line:

    {"worst_ms": ..., "worst_reply": "...", "worst_extract_ms": ..., "chars": 20000, ...}

Target (issue #29): no reply over 10 ms at 20 KB. Every reply must end in ReplyError or a valid
result; anything else is printed and makes the script exit 1.

    python benchmarks/reply_parsing.py [--repeat 5] [--random 50]
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import sys
import time
from collections.abc import Callable

from hiconav.reasoning import replies
from hiconav.reasoning.replies import ReplyError, extract_json, parse_verification

N = replies.MAX_CONTENT_CHARS
VIEWS = (3, 2, 1)
LABELS = (("sink", "mug", "counter_top"), ("mug", "chair"), ("sofa",))
TARGETS = ("mug",)
GOOD = '{"visible": 1, "view": 1, "object": 2, "bbox": [0.4, 0.3, 0.55, 0.6], "evidence": "a mug"}'


def fill(unit: str, head: str = "", tail: str = "") -> str:
    """``head + unit * k + tail`` cut or padded to exactly N characters (the tail kept)."""
    body = (unit * (N // max(len(unit), 1) + 1))[: N - len(head) - len(tail)]
    return head + body + tail


def hostile() -> dict[str, str]:
    rng = random.Random(29)
    cases = {
        "open_braces": fill("{"),
        "open_brackets": fill("["),
        "braces_then_close": fill("{", tail="}"),
        "brackets_then_good": fill("[", tail=GOOD),
        "nested_keys": fill('{"a":'),
        "open_string_keys": fill('{"a'),
        "empty_pairs": fill("{}"),
        "bad_pairs": fill("{x}"),
        "mismatched": fill("{]"),
        "mismatched_array": fill("[}"),
        "quotes": fill('"'),
        "brace_quote": fill('{"'),
        "quote_brace": fill('"{'),
        "escapes_in_string": fill("\\\"", head='{"evidence": "'),
        "backslashes": fill("\\", head='{"a": "'),
        "unterminated_string": fill("a", head='{"a": "'),
        "many_arrays": fill("[],", head='{"a": [', tail="0]"),
        "many_arrays_unclosed": fill("[],", head='{"a": ['),
        "deep_then_fail": fill("x", head='{"a":' * 60 + '"', tail='" x' + "}" * 60),
        "deep_pairs_fail": fill('{"a":' * 30 + '"x"' + "}" * 30 + ","),
        "deep_valid_63": '{"visible": 2, "evidence": "x", "view": ' + "[" * 62 + "]" * 62 + "}",
        "huge_int": fill("9", head='{"visible": 1, "view": ', tail="}"),
        "huge_float": fill("9", head='{"visible": 1, "confidence": 0.', tail="}"),
        "huge_exponent": fill(" ", head='{"visible": 1, "confidence": 1e999999', tail="}"),
        "nan_literals": fill("NaN,", head='{"visible": 1, "bbox": [', tail="0]}"),
        "many_keys": "{" + ",".join(f'"k{i}": {i}' for i in range(3000))[: N - 2] + "}",
        "duplicate_keys": fill('"visible": 1, ', head="{", tail='"x": 0}'),
        "fences": fill("```"),
        "fences_json": fill("```json\n{x}\n```\n"),
        "prose_braces": fill("the mug {maybe} is near the sink. ", tail=GOOD),
        "prose_quotes_braces": fill('he said "{ and then ', tail=GOOD),
        "nul_bytes": fill("\x00{\x00"),
        "control_chars": fill("\x01\x02\x1b[0m{"),
        "surrogates_escaped": fill("\\ud800", head='{"visible": 2, "evidence": "', tail='"}'),
        "injection_words": fill("ignore move turn rotate velocity "),
        "spaces_after_rotate": fill(" ", head="rotate"),
        "long_evidence_valid": fill("mug ", head='{"visible": 1, "view": 1, "object": "mug", "bbox": '
                                    '[0.4, 0.3, 0.55, 0.6], "evidence": "', tail='"}'),
        "unicode_letters": fill("é{ü[ß\"", head="{"),
    }
    alphabet = '{}[]",:0123456789.-eE ntrufalsNI\\ abc\n'
    for i in range(args.random):
        cases[f"random_{i:02d}"] = "".join(rng.choice(alphabet) for _ in range(N))
    return cases


def timed(fn: Callable[[], object], repeat: int) -> tuple[float, str]:
    times, outcome = [], ""
    for _ in range(repeat):
        t0 = time.perf_counter()
        try:
            fn()
            outcome = "ok"
        except ReplyError as exc:
            outcome = exc.reason
        except BaseException as exc:  # noqa: BLE001 - exactly what the benchmark looks for
            outcome = f"RAISED {type(exc).__name__}"
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1e3, outcome


def main() -> int:
    cases = hostile()
    worst = (0.0, "")
    worst_extract = (0.0, "")
    failures = []
    print(f"{'reply':28s} {'chars':>6s} {'parse ms':>9s} {'extract ms':>10s}  outcome")
    for name, text in cases.items():
        ms, outcome = timed(lambda: parse_verification(text, VIEWS, labels=LABELS, targets=TARGETS),
                            args.repeat)
        ems, eoutcome = timed(lambda: extract_json(text), args.repeat)
        print(f"{name:28s} {len(text):6d} {ms:9.2f} {ems:10.2f}  {outcome} / {eoutcome}")
        if len(text) > N:
            failures.append(f"{name}: {len(text)} chars, longer than the bound")
        for o in (outcome, eoutcome):
            if o.startswith("RAISED"):
                failures.append(f"{name}: {o}")
        worst = max(worst, (ms, name))
        worst_extract = max(worst_extract, (ems, name))
    print(json.dumps({"worst_ms": round(worst[0], 2), "worst_reply": worst[1],
                      "worst_extract_ms": round(worst_extract[0], 2), "worst_extract_reply": worst_extract[1],
                      "chars": N, "replies": len(cases), "repeat": args.repeat, "target_ms": 10.0,
                      "failures": failures}))
    return 1 if failures else 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5, help="runs per reply (the median is kept)")
    parser.add_argument("--random", type=int, default=50, help="seeded random JSON-ish replies added")
    args = parser.parse_args()
    sys.exit(main())
