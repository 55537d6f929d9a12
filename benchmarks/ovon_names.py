"""Names people give the target categories: does the offline parser map each to its category?

The open-vocabulary generator (``hiconav episodes --task ovon``) names each target with one of
``task_episodes.OVON_NAMES``. People use many more ("the writing table", "the media cabinet",
"the wastepaper basket", "the t.v."); a name the parser maps to another category sends the robot
to the wrong object, and one it maps to no category (kept as said) is a label the simulator's
detector never gives: the robot searches until its steps run out.

``NAMES`` below holds, per category, names that are not the generator's (the category's own
words and ``OVON_NAMES`` are left out). They were collected at stop 45 while the synonyms were
written, so the rate is a regression figure, not a held-out one. The script decomposes
"find the <name>" offline (MiniLM similarity, as a mission does) and counts a name as read when
the first target is the category. It prints the names read otherwise, then one JSON line:

    {"names": N, "agree": A, "rate": A / N, "by_category": {category: rate, ...}}

    python benchmarks/ovon_names.py [--episodes val_ovon.jsonl --write NAMES.jsonl] [--seed 0]

``--write`` also writes the episodes of ``--episodes`` with each instruction's name replaced by
one of ``NAMES`` for its target (a generator phrasing, both drawn with ``--seed``), for
``hiconav eval``.
"""

from __future__ import annotations

import argparse
import json
import random
import sys

from hiconav.reasoning.config import ReasoningConfig
from hiconav.reasoning.decompose import decompose_instruction
from hiconav.sim.task_episodes import OVON_NAMES, OVON_PHRASINGS, _article

NAMES: dict[str, tuple[str, ...]] = {
    "chair": ("dining chair", "kitchen chair", "office chair", "desk chair", "wooden chair", "side chair",
              "folding chair", "chairs"),
    "sofa": ("sectional", "sofa bed", "two-seater", "three-seater", "divan", "futon", "chesterfield",
             "love seat", "sofas"),
    "bed": ("double bed", "queen bed", "king bed", "king-size bed", "single bed", "twin bed", "bunk bed",
            "daybed", "day bed", "guest bed", "beds"),
    "toilet": ("toilet bowl", "w.c.", "water closet", "restroom toilet", "john", "potty"),
    "tv": ("tv set", "flatscreen", "flat-screen", "smart tv", "tv screen", "t.v.", "led tv", "plasma tv",
           "plasma screen", "the tele", "idiot box"),
    "plant": ("house plant", "potted plant", "pot plant", "flowerpot", "indoor plant", "fern", "succulent",
              "cactus", "ficus", "palm", "bonsai", "greenery", "plants"),
    "dining_table": ("dining room table", "eating table", "breakfast table", "table for dinner",
                     "dining-table"),
    "fridge": ("fridge freezer", "fridge-freezer", "freezer", "cooler", "frig", "refridgerator",
               "mini fridge"),
    "sink": ("kitchen sink", "bathroom sink", "hand basin", "wash-hand basin", "lavatory sink", "vanity sink"),
    "laptop": ("notebook", "laptop computer", "macbook", "chromebook", "portable computer", "computer",
               "pc laptop"),
    "armchair": ("wingback", "wingback chair", "club chair", "arm chair", "reading chair", "lounger",
                 "upholstered chair"),
    "desk": ("writing desk", "work desk", "computer desk", "study desk", "office desk", "workstation",
             "bureau desk", "writing table", "study table"),
    "dresser": ("bureau", "drawers", "chest", "highboy", "tallboy", "lowboy", "chest-of-drawers",
                "dressing table"),
    "microwave": ("microwave oven", "micro"),
    "toaster": ("bread toaster", "pop-up toaster"),
    "coffee_machine": ("coffee brewer", "coffeemaker", "espresso maker", "nespresso", "coffee pot",
                       "percolator", "keurig", "drip coffee maker"),
    "washing_machine": ("clothes washer", "washing-machine", "front loader"),
    "clothes_dryer": ("tumble drier", "drier", "clothes drier", "laundry dryer"),
    "floor_lamp": ("standard lamp", "floor light", "torchiere", "uplighter", "tall lamp", "arc lamp"),
    "desk_lamp": ("desk light", "task lamp", "study lamp", "lamp on the desk", "small lamp"),
    "side_table": ("night table", "bedside cabinet", "side-table", "occasional table", "accent table",
                   "lamp table"),
    "tv_stand": ("entertainment centre", "television stand", "tv bench", "media cabinet", "tv console",
                 "media unit", "television cabinet"),
    "shelving_unit": ("book shelf", "shelves", "shelf unit", "shelving", "etagere", "display shelf", "book case",
                      "storage shelves"),
    "garbage_can": ("garbage bin", "bin", "trashcan", "waste basket", "litter bin", "recycling bin",
                    "wastepaper basket", "garbage"),
    "oven": ("range", "kitchen range", "oven range", "cooking range"),
    "bathtub": ("bath tub", "soaking tub", "jacuzzi"),
    "stool": ("bar stool", "barstool", "step stool", "kitchen stool", "counter stool", "stools"),
    "safe": ("strongbox", "lockbox", "safe box", "strong box", "safety deposit box", "vault", "security safe",
             "wall safe"),
    "teddy_bear": ("plushie", "stuffed bear", "toy bear", "cuddly toy", "stuffed toy", "plush"),
    "statue": ("bust", "statuette", "carving", "figure", "ornament"),
    "vase": ("flower vase", "urn", "flower jar", "vases"),
    "painting": ("photo", "photograph", "canvas", "art print", "poster", "wall art", "portrait",
                 "landscape painting", "picture frame", "art"),
    "laundry_hamper": ("clothes hamper", "dirty clothes basket", "linen basket", "washing basket"),
    "dog_bed": ("dog basket", "dog cushion", "pet cushion", "dog mattress", "cat bed", "doggy bed"),
}


def read(name: str, config: ReasoningConfig) -> str | None:
    """The first target the offline parser reads in "find the <name>" (None: no object found)."""
    try:
        return decompose_instruction(f"find the {name}", config).targets[0]
    except Exception:  # noqa: BLE001 - a name the parser fails on counts as not read
        return None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--episodes", help="an ovon episode file (for --write)")
    ap.add_argument("--write", help="write the episodes with people's names here")
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    if args.write and not args.episodes:
        ap.error("--write needs --episodes")
    config = ReasoningConfig()
    agree, by_category = 0, {}
    total = 0
    for category, names in NAMES.items():
        ok = 0
        for name in names:
            got = read(name, config)
            total += 1
            ok += got == category
            if got != category:
                print(f"{category:16} {name!r:24} read as {got}")
        agree += ok
        by_category[category] = round(ok / len(names), 3)
    if args.write:
        rng = random.Random(args.seed)
        lines = []
        with open(args.episodes, encoding="utf-8") as fh:
            for line in fh:
                if not line.strip():
                    continue
                ep = json.loads(line)
                names = [n for n in NAMES.get(ep.get("target", ""), ()) if n not in OVON_NAMES.get(ep["target"], ())]
                if names:
                    name = rng.choice(names)
                    ep["instruction"] = rng.choice(OVON_PHRASINGS).format(a=_article(name), name=name)
                lines.append(json.dumps(ep) + "\n")
        with open(args.write, "w", encoding="utf-8") as fh:
            fh.writelines(lines)
        print(f"wrote {len(lines)} episodes to {args.write}", file=sys.stderr)
    print(json.dumps({"names": total, "agree": agree, "rate": round(agree / max(total, 1), 3),
                      "by_category": by_category}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
