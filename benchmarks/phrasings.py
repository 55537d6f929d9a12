"""People's phrasings of described instances: does the offline parser read them as the template?

The episode generator (``hiconav episodes --task textnav``) writes instructions from a few
templates ("take me to the chair next to the fridge"). People say the same thing in other ways:
a room word before the noun ("the kitchen table"), the room first ("In the kitchen, find the
chair ..."), a follow-up sentence ("Find the chair. The one
next to the fridge."), a relative clause ("the chair that is next to the fridge"), a polite
lead ("I'd like to go to ..."), the relation first ("Next to the fridge, there's a chair. Take me
to it."), a room in the possessive ("the kitchen's chair"), a dashed afterthought ("the chair
next to the fridge - go there"), the target called by another name, what to do on arrival
("... and stop there"), the speaker's reason ("... so I can have a look, thanks"), steps of the
way first ("Go down the hall, turn left and stop by ..."), who wants it ("The chair I want is the
one next to the fridge."), the goal said as a predicate ("Explore and find it: the ... is my
destination."), a typing slip ("the armhcair ..."), something told before the request ("My
keys are somewhere around here. Take me to ..."), a look asked for politely ("Could you possibly
take a look at ...? :)"), a hedge and a condition ("... that's kinda next to ..., if you look
around"). A parser that reads only the templates
loses the description and stops at the first instance of the category it sees.

For each textnav instruction the script writes every form below that applies, decomposes the
template and each form offline (``decompose_instruction``, MiniLM similarity) and counts a form as
read when its targets and the relations on them (what singles the instance out) equal the
template's; a form the parser fails on counts as not read. It prints one line per form, the
instructions read differently (up to ``--show``), then one JSON line:

    {"instructions": N, "phrasings": P, "agree": A, "rate": A / P, "by_form": {form: rate, ...}}

    python benchmarks/phrasings.py [--episodes FILE.jsonl] [--houses FILE] [--limit 30] [--show 10]
                                   [--write PEOPLE.jsonl]

``--write`` also writes the episodes (``--episodes`` required) with one form each, for
``hiconav eval``: even lines the room word where it applies, else the follow-up; odd lines the
relative clause.

Without ``--episodes`` it generates one textnav episode per house for the first ``--limit``
houses of ``--houses`` (default: the shared ProcTHOR val houses), about 3 s a house.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import zlib
from pathlib import Path

from hiconav.reasoning.config import ReasoningConfig
from hiconav.reasoning.decompose import _singular, decompose_instruction
from hiconav.reasoning.grounding import target_relations
from hiconav.sim.task_episodes import TEXTNAV_PHRASINGS, _article, spoken

sys.path.insert(0, str(Path(__file__).resolve().parent))
from ovon_names import NAMES  # noqa: E402  (benchmarks/ is no package)

# the generator's leading words ("take me to the "), read off its templates
LEAD = re.compile("^(?:" + "|".join(re.escape(p.split("{np}")[0]) for p in TEXTNAV_PHRASINGS) + ")",
                  re.IGNORECASE)
ROOM = re.compile(r"in the (kitchen|living room|bedroom|bathroom)")
# descriptions that may be said relation first ("Next to the fridge, there's a chair."): one
# relation phrase, then its object
FRONTABLE = re.compile(r"(?:in|on|on top of|next to|beside|by|near|under|below|beneath|above|close to) the [a-z ]+")


def other_names(target: str) -> list[str]:
    """Names people give ``target`` beyond the generator's (``ovon_names.NAMES``), singular and
    without a preposition of their own ("the lamp on the desk" is a description, not a name)."""
    return [n for n in NAMES.get(target, ()) if _singular(n.split()[-1]) == n.split()[-1]
            and not {"on", "for", "of"} & set(n.split())]


def slip(name: str) -> str:
    """``name`` with a typing slip: the two letters after the third of its longest word of
    five letters or more swapped ("armchiar"); unchanged without such a word."""
    words = name.split()
    k = max(range(len(words)), key=lambda i: len(words[i]))
    w = words[k]
    if len(w) < 5 or w[3] == w[4]:
        return name
    words[k] = w[:3] + w[4] + w[3] + w[5:]
    return " ".join(words)


def forms(instruction: str, target: str) -> dict[str, str]:
    """The people's forms of one template instruction (form name -> text); {} when the template's
    noun phrase cannot be found (the instruction is not a generator template)."""
    text = instruction.strip().rstrip("?.")
    m = LEAD.match(text)
    np_ = text[m.end():] if m else text
    name = spoken(target)
    if not np_.lower().startswith(name.lower()):
        return {}
    rest = np_[len(name):].strip()
    out = {
        "follow-up": f"Find the {name}. The one {rest}.",
        "relative clause": f"I'd like to go to the {name} that is {rest}",
        "question": f"Could you head over to the {name} {rest}?",
        "bare": f"the {name} {rest}, please",
    }
    out["dash"] = f"the {name} {rest} - go there"
    out["arrival"] = f"Could you find the {name} {rest} and stop there"
    out["reason"] = f"bring me to the {name} {rest} so I can have a look, thanks"
    out["route"] = f"Go down the hall, turn left and stop by the {name} {rest}"
    out["wanted"] = f"The {name} I want is the one {rest}."
    out["destination"] = f"Explore and find it: the {name} {rest} is my destination."
    out["context"] = f"My keys are somewhere around here. Take me to the {name} {rest}."
    out["look"] = f"Could you possibly take a look at the {name} {rest}? :)"
    out["hedge"] = f"Find the {name} that's kinda {rest}, if you look around."
    slipped = slip(name)
    if slipped != name:
        out["slip"] = f"find the {slipped} {rest}"
    others = other_names(target)
    if others:
        other = others[zlib.crc32(instruction.encode()) % len(others)]
        out["other name"] = f"take me to the {other} {rest}"
    if FRONTABLE.match(rest):
        first = rest[0].upper() + rest[1:]
        out["relation first"] = f"{first}, there's {_article(name)} {name}. Take me to it."
    room = ROOM.fullmatch(rest)
    if room:
        out["room word"] = f"take me to the {room.group(1)} {name}"
        out["room possessive"] = f"can you find the {room.group(1)}'s {name}?"
    tail = re.search(r"\s*\b" + ROOM.pattern + "$", rest)
    if tail:
        before = rest[:tail.start()].strip()
        out["leading room"] = f"In the {tail.group(1)}, find the {name}" + (f" {before}" if before else "")
    return out


def generated(houses: str, limit: int) -> list[dict]:
    from hiconav.sim.houses import load_house
    from hiconav.sim.task_episodes import generate_task_episodes

    eps = []
    for i in range(limit):
        try:
            house = load_house(f"{houses}#{i}")
        except Exception as exc:  # fewer houses than the limit, or a bad line: report and go on
            print(f"house {houses}#{i}: {exc}", file=sys.stderr)
            break
        eps += [{"instruction": e.instruction, "target": e.target}
                for e in generate_task_episodes(house, i, "textnav", 1, 0)]
    return eps


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", help="a textnav episode file (JSON Lines); default: generate")
    ap.add_argument("--houses", default=str(Path(__file__).resolve().parents[1].parent / "shared" / "data"
                                            / "procthor" / "val.jsonl.gz"))
    ap.add_argument("--limit", type=int, default=30, help="houses to generate episodes in")
    ap.add_argument("--show", type=int, default=10, help="phrasings read differently to print")
    ap.add_argument("--write", help="write the episodes with one people's form each (needs --episodes)")
    ap.add_argument("--form", help="with --write: this form for every episode where it applies "
                    "(e.g. 'other name'); default: the room word or follow-up, and the relative clause")
    args = ap.parse_args(argv)
    if args.write and not args.episodes:
        ap.error("--write needs --episodes")
    if args.episodes:
        eps = [json.loads(line) for line in open(args.episodes) if line.strip()]
    else:
        eps = generated(args.houses, args.limit)
    from hiconav.perception.embedder import get_embedder

    similarity = get_embedder("minilm").similarity
    cfg = ReasoningConfig()

    def key(text: str):
        try:
            t = decompose_instruction(text, cfg, similarity=similarity)
        except Exception as exc:  # a parser that fails on a phrasing reads it as nothing
            return ("error", type(exc).__name__)
        return t.targets, frozenset(target_relations(t.relations, t.targets))

    total = agree = 0
    by_form: dict[str, list[int]] = {}
    wrong: list[tuple[str, str]] = []
    n = 0
    for ep in eps:
        fs = forms(ep["instruction"], ep["target"])
        if not fs:
            continue
        n += 1
        want = key(ep["instruction"])
        for form, text in fs.items():
            ok = key(text) == want
            total += 1
            agree += ok
            by_form.setdefault(form, [0, 0])
            by_form[form][0] += ok
            by_form[form][1] += 1
            if not ok:
                wrong.append((ep["instruction"], text))
    if args.write:
        with open(args.write, "w") as out:
            for i, ep in enumerate(eps):
                fs = forms(ep["instruction"], ep["target"])
                if fs and args.form:
                    ep = dict(ep, instruction=fs.get(args.form, ep["instruction"]))
                elif fs:
                    even = fs.get("room word", fs["follow-up"])
                    ep = dict(ep, instruction=even if i % 2 == 0 else fs["relative clause"])
                out.write(json.dumps(ep) + "\n")
        print(f"wrote {len(eps)} episodes to {args.write}")
    for form, (a, t) in sorted(by_form.items()):
        print(f"{form:16s} {a:4d}/{t:<4d} read as the template")
    for template, text in wrong[:args.show]:
        print(f"  differs: {text!r} (template {template!r})")
    print(json.dumps({"instructions": n, "phrasings": total, "agree": agree,
                      "rate": round(agree / total, 4) if total else None,
                      "by_form": {f: round(a / t, 4) for f, (a, t) in sorted(by_form.items())}}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
