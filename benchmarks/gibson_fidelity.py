"""Gibson fidelity: Habitat's official reference paths measured in our simulator.

For each path of ``reference_paths.jsonl`` (one official Habitat ObjectNav path per train scene,
with Habitat's own geodesic distance), prints whether both ends are traversable on our map of
that floor and the ratio of our fast-marching distance to Habitat's; ends with one JSON line:

    {"paths": N, "valid": V, "ratio_median": r, "ratio_min": a, "ratio_max": b}

Target (issue #26): every path valid, every ratio within 0.97-1.03.

The JSON line measures through ``--mask`` (default ``navmesh``: channel 0 as it is, the navmesh
Habitat measured on; ``semexp``: channel 0 dilated by SemExp's 2-cell disk, the mask of our Gibson
SPL and success, whose wider passages give distances 1-4% short of Habitat's). Each path's line
shows both ratios.

    python benchmarks/gibson_fidelity.py [--maps FILE] [--reference FILE] [--mask navmesh|semexp]
"""

from __future__ import annotations

import argparse
import json

from hiconav.data import data_root
from hiconav.sim.fidelity import MASKS, check_path, read_reference_paths, summarise


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--maps", default=None, help="Gibson maps *.pbz2 (default: the shared train maps)")
    parser.add_argument("--reference", default=None, help="reference paths *.jsonl (default: the shared file)")
    parser.add_argument("--mask", default="navmesh", choices=MASKS,
                        help="the mask distances are measured through (default: navmesh, as Habitat)")
    args = parser.parse_args()
    root = data_root() / "gibson"
    maps = args.maps or str(root / "train_info.pbz2")
    reference = args.reference or str(root / "reference_paths.jsonl")
    refs = read_reference_paths(reference)
    by_mask = {m: [check_path(maps, ref, mask=m) for ref in refs] for m in MASKS}
    for i, c in enumerate(by_mask[args.mask]):
        if c.valid:
            other = {m: by_mask[m][i].ratio for m in MASKS}
            status = (f"ratio {c.ratio:.4f}  ours {c.ours:6.2f} m  habitat {c.habitat:6.2f} m  ("
                      + ", ".join(f"{m} {r:.4f}" for m, r in other.items()) + ")")
        else:
            status = c.reason
        print(f"{c.scene:14s} floor {c.floor}  {status}")
    for m in MASKS:
        if m != args.mask:
            print(f"{m} mask: {json.dumps(summarise(by_mask[m]))}")
    print(json.dumps(summarise(by_mask[args.mask])))


if __name__ == "__main__":
    main()
