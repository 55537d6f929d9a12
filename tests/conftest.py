"""Shared fixtures: where the real data lives (../shared/data beside the checkout)."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest

# A suite started as a background job of a non-interactive shell (`cmd &`, nohup) inherits SIGINT
# ignored, and so would every subprocess it starts: the Ctrl-C tests (the SIGINT hook, the
# vehicle's clean exit, the zero setpoint before exit) need Python's default handler back.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)

ROOT = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("HICONAV_DATA", ROOT.parent / "shared" / "data"))


@pytest.fixture(scope="session")
def shared_data() -> Path:
    if not SHARED_DATA.is_dir():
        pytest.fail(f"shared data not found at {SHARED_DATA}; set HICONAV_DATA")
    return SHARED_DATA
