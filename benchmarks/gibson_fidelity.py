"""Gibson fidelity: Habitat's official reference paths measured in our simulator.

For each path of ``reference_paths.jsonl`` (one official Habitat ObjectNav path per train scene,
with Habitat's own geodesic distance), prints whether both ends are traversable on our map of
that floor and the ratio of our fast-marching distance to Habitat's; ends with one JSON line:

    {"paths": N, "valid": V, "ratio_median": r, "ratio_min": a, "ratio_max": b}

Target (issue #26): every path valid, every ratio within 0.97-1.03.

    python benchmarks/gibson_fidelity.py [--maps FILE] [--reference FILE]
"""

from __future__ import annotations

import argparse
import json

from hiconav.data import data_root
from hiconav.sim.fidelity import check_path, read_reference_paths, summarise


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default=None, help="Gibson maps *.pbz2 (default: the shared train maps)")
    parser.add_argument("--reference", default=None, help="reference paths *.jsonl (default: the shared file)")
    args = parser.parse_args()
    root = data_root() / "gibson"
    maps = args.maps or str(root / "train_info.pbz2")
    reference = args.reference or str(root / "reference_paths.jsonl")
    checks = [check_path(maps, ref) for ref in read_reference_paths(reference)]
    for c in checks:
        status = f"ratio {c.ratio:.3f}  ours {c.ours:6.2f} m  habitat {c.habitat:6.2f} m" if c.valid else c.reason
        print(f"{c.scene:14s} floor {c.floor}  {status}")
    print(json.dumps(summarise(checks)))


if __name__ == "__main__":
    main()
