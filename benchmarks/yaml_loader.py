"""YAML loader benchmark: what the checks of ``hiconav.yamlio`` cost, and how fast hostile text is refused.

Times (best of ``--repeat``) for: composing and constructing ``config/default.yaml`` and
``trees/objectnav.yaml`` with plain ``yaml.safe_load`` and with ``hiconav.yamlio.load_text``; refusing
an alias bomb of 9 ** 9 scalars; refusing 100,000 nested ``[``; refusing a flat list just above the
node limit. Ends with one JSON line of milliseconds. Figures move with the machine's load.

    python benchmarks/yaml_loader.py [--repeat 5]
"""

from __future__ import annotations

import argparse
import json
import time
from collections.abc import Callable

import yaml

from hiconav import yamlio
from hiconav.errors import ConfigError
from hiconav.settings import DEFAULT_FILE
from hiconav.trees.builder import TREES_DIR


def best_ms(fn: Callable[[], object], repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        try:
            fn()
        except ConfigError:
            pass
        times.append(time.perf_counter() - t0)
    return round(min(times) * 1000.0, 2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    repeat = parser.parse_args().repeat
    default = DEFAULT_FILE.read_text()
    tree = (TREES_DIR / "objectnav.yaml").read_text()
    bomb = "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + "".join(
        f"{b}: &{b} [" + ", ".join([f"*{a}"] * 9) + "]\n" for a, b in zip("abcdefgh", "bcdefghi"))
    flat = "[" + ", ".join(["1"] * (yamlio.LIMITS.max_nodes + 1)) + "]"
    figures = {
        "default_yaml_safe_load_ms": best_ms(lambda: yaml.safe_load(default), repeat),
        "default_yaml_yamlio_ms": best_ms(lambda: yamlio.load_text(default), repeat),
        "objectnav_safe_load_ms": best_ms(lambda: yaml.safe_load(tree), repeat),
        "objectnav_yamlio_ms": best_ms(lambda: yamlio.load_text(tree), repeat),
        "alias_bomb_refused_ms": best_ms(lambda: yamlio.load_text(bomb), repeat),
        "nested_100k_refused_ms": best_ms(lambda: yamlio.load_text("[" * 100_000), repeat),
        "flat_100001_refused_ms": best_ms(lambda: yamlio.load_text(flat), repeat),
    }
    for key, value in figures.items():
        print(f"{key:28s} {value:10.2f}")
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
