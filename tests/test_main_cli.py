"""The command line: help lists the subcommands, --version works, user errors have no traceback."""

from __future__ import annotations

import subprocess
import sys

from hiconav import __version__
from hiconav.cli import SUBCOMMANDS, main


def run_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "hiconav.cli", *args], capture_output=True, text=True,
                          timeout=120)


def test_help_lists_every_subcommand() -> None:
    result = run_cli("--help")
    assert result.returncode == 0, result.stderr
    for name, _module, _function in SUBCOMMANDS:
        assert name in result.stdout


def test_version_prints_package_version(capsys) -> None:
    assert main(["--version"]) == 0
    assert __version__ in capsys.readouterr().out


def test_unknown_house_is_one_clear_line_not_a_traceback() -> None:
    result = run_cli("sim", "--house", "procthor:nosuchsplit/3", "--steps", "1")
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    assert "nosuchsplit" in result.stderr
