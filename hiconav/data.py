"""Where the real data sets live (ProcTHOR, Gibson, TRP and set-cover instances).

Looked up in order: the HICONAV_DATA environment variable; ``shared/data`` beside the
current folder or any parent of it; ``shared/data`` beside the source checkout. The data is
never downloaded.
"""

from __future__ import annotations

import os
from pathlib import Path

from hiconav.errors import DataError


def data_root() -> Path:
    """The folder that holds procthor/, gibson/, trp/ and setcover/."""
    env = os.environ.get("HICONAV_DATA")
    if env:
        path = Path(env)
        if not path.is_dir():
            raise DataError(f"HICONAV_DATA={env} is not a folder")
        return path
    candidates = []
    cwd = Path.cwd().resolve()
    for base in (cwd, *cwd.parents):
        candidates += [base / "shared" / "data", base.parent / "shared" / "data"]
    source = Path(__file__).resolve().parents[1]
    candidates += [source.parent / "shared" / "data", source / "shared" / "data"]
    for path in candidates:
        if (path / "procthor").is_dir() or (path / "gibson").is_dir():
            return path
    raise DataError("cannot find the data folder (shared/data); set HICONAV_DATA to its path")
