"""``load_house(spec)``: address a house by name ("procthor:val/3", "gibson:Allensville",
"gibson:Allensville/0"), by a file path (a ProcTHOR house ``.json``/``.json.gz``), or by a house
of a data file anywhere on disk: ``FILE.jsonl.gz#N`` (line N, 0-based, of a ProcTHOR houses file)
or ``FILE.pbz2#Scene/floor`` (a floor of a SemExp / L3MVN Gibson maps file such as
``val_info.pbz2``).

Loaded houses are cached per spec (they are treated as immutable). This module resolves names
and dispatches to the loaders; it must not contain data-set parsing itself.
"""

from __future__ import annotations

from pathlib import Path

from hiconav.data import data_root
from hiconav.errors import DataError
from hiconav.sim.house import House

_CACHE: dict[tuple[str, str], House] = {}


def house_names(data_dir: Path | None = None) -> list[str]:
    """Every house name available in the data folder (ProcTHOR splits and Gibson floors)."""
    from hiconav.sim import gibson, procthor

    root = data_dir or data_root()
    names: list[str] = []
    for split in ("train", "val"):
        path = root / "procthor" / f"{split}.jsonl.gz"
        if path.is_file():
            names += [f"procthor:{split}/{i}" for i in range(len(procthor.split_lines(str(path))))]
    if (root / "gibson" / "train_info.pbz2").is_file():
        info = gibson.load_info(gibson.info_path(root))
        for scene in sorted(info):
            for floor in sorted(info[scene]):
                names.append(f"gibson:{scene}" if floor == 0 else f"gibson:{scene}/{floor}")
    return names


def load_house(spec: str, data_dir: Path | None = None, *, cache: bool = True) -> House:
    """Load a house by name or path; raises ``DataError`` naming valid names on failure."""
    from hiconav.sim import gibson, procthor

    root = data_dir or data_root()
    key = (str(root), spec)
    if cache and key in _CACHE:
        return _CACHE[key]
    kind, sep, rest = spec.partition(":")
    if sep and kind == "procthor":
        split, slash, idx = rest.partition("/")
        if split not in ("train", "val") or not slash or not idx.isdigit():
            raise DataError(f"bad ProcTHOR house name '{spec}': expected procthor:train/N or "
                            "procthor:val/N with N in 0..99", field="house")
        house = procthor.load_procthor(split, int(idx), root)
    elif sep and kind == "gibson":
        scene, slash, floor = rest.partition("/")
        if slash and not floor.isdigit():
            raise DataError(f"bad Gibson house name '{spec}': expected gibson:Scene or "
                            "gibson:Scene/floor", field="house")
        house = gibson.load_gibson(scene, int(floor) if slash else 0, root)
    elif "#" in spec and Path(spec.rpartition("#")[0]).expanduser().is_file():
        house = _load_file_entry(spec, root)
    else:
        path = Path(spec)
        if path.is_file():
            house = procthor.load_procthor_file(path, root)
        else:
            scenes = ", ".join(gibson.scene_names(root)) if (root / "gibson").is_dir() else ""
            raise DataError(
                f"unknown house '{spec}': not a file, and not one of procthor:train/0..99, "
                f"procthor:val/0..99, gibson:<scene> with scene in: {scenes}, FILE.jsonl.gz#N or "
                "FILE.pbz2#Scene/floor", field="house")
    if cache:
        _CACHE[key] = house
    return house


def _load_file_entry(spec: str, root: Path) -> House:
    """``FILE#N`` (ProcTHOR houses file) or ``FILE#Scene/floor`` (Gibson maps file)."""
    from hiconav.sim import gibson, procthor

    file, _, entry = spec.rpartition("#")
    path = Path(file).expanduser().resolve()
    if path.name.endswith(".pbz2"):
        scene, slash, floor = entry.partition("/")
        if not scene or (slash and not floor.isdigit()):
            raise DataError(f"bad Gibson house '{spec}': expected FILE.pbz2#Scene/floor", field="house")
        return gibson.load_gibson_file(path, scene, int(floor) if slash else 0)
    if not entry.isdigit():
        raise DataError(f"bad house '{spec}': expected FILE.jsonl.gz#N (N the 0-based line)", field="house")
    return procthor.load_procthor_line(path, int(entry), root)
