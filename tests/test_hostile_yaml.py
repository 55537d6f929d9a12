"""Hostile YAML through every reader (trees, settings, profiles) and the CLI: file:line, never a traceback."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from hiconav.cli import main
from hiconav.drivers.profiles import load_profile
from hiconav.errors import ConfigError
from hiconav.settings import load_settings_file
from hiconav.trees import load_tree

BOMB = "a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + "".join(
    f"{b}: &{b} [" + ", ".join([f"*{a}"] * 9) + "]\n" for a, b in zip("abcdefgh", "bcdefghi"))

#: name -> (file content, line of the error, words in the message)
HOSTILE: dict[str, tuple[str | bytes, int, str]] = {
    "alias_bomb": (BOMB, 6, "nodes once aliases are expanded"),
    "invalid_utf8": ("name: x\ndescription: caf\xe9\n".encode("latin-1"), 2, "not UTF-8"),
    "binary": (b"\x7fELF\x02\x01\x01\x00\x00\x00\xff\xfe", 1, "not UTF-8"),
    "nul_byte": ("name: x\n\nroot: \x00\n", 3, "NUL byte"),
    "control_character": ("name: x\nroot: \x07\n", 2, "control character"),
    "deep_nesting": ("name: x\nroot: " + "[" * 5000 + "\n", 2, "nesting deeper than 100"),
    "recursive_alias": ("name: x\nroot: &r\n  Sequence:\n    children: [*r]\n", 4, "recursive alias *r"),
    "duplicate_key": ("name: x\nroot: {}\nname: y\n", 3, "duplicate key 'name' (first given on line 1)"),
}

READERS: dict[str, Callable[[Path], Any]] = {
    "tree": load_tree, "settings": load_settings_file, "profile": load_profile,
}


def write(tmp_path: Path, content: str | bytes) -> Path:
    path = tmp_path / "hostile.yaml"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path


@pytest.mark.parametrize("reader", READERS)
@pytest.mark.parametrize("case", HOSTILE)
def test_every_reader_refuses_hostile_yaml_with_file_and_line(tmp_path: Path, reader: str, case: str) -> None:
    content, line, words = HOSTILE[case]
    path = write(tmp_path, content)
    with pytest.raises(ConfigError) as info:
        READERS[reader](path)
    assert str(info.value).startswith(f"{path}:{line}: "), str(info.value)
    assert words in str(info.value)


@pytest.mark.parametrize("command", ["tree", "config"])
@pytest.mark.parametrize("case", HOSTILE)
def test_the_cli_prints_one_line_with_file_and_line_and_exits_non_zero(tmp_path: Path, capsys, command: str,
                                                                       case: str) -> None:
    content, line, words = HOSTILE[case]
    path = write(tmp_path, content)
    assert main([command, str(path)]) != 0
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and "Traceback" not in captured.err
    assert captured.err.startswith(f"error: {path}:{line}: ") and words in captured.err


@pytest.mark.parametrize("command", ["tree", "config"])
def test_an_alias_bomb_does_not_hang_the_cli(tmp_path: Path, command: str) -> None:
    path = write(tmp_path, BOMB)
    result = subprocess.run([sys.executable, "-m", "hiconav.cli", command, str(path)], capture_output=True,
                            text=True, timeout=120)
    assert result.returncode != 0
    assert "Traceback" not in result.stderr
    assert f"{path}:6" in result.stderr


def test_a_recursive_alias_in_set_is_one_line(capsys) -> None:
    assert main(["config", "--set", "memory.tau=&x [*x]"]) != 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "recursive alias *x" in err and "[memory.tau]" in err


def test_an_infinite_rate_is_refused_by_config_with_its_line(tmp_path: Path, capsys) -> None:
    path = write(tmp_path, "mission:\n  rates:\n    control: .inf\n")
    assert main(["config", str(path)]) != 0
    err = capsys.readouterr().err
    assert err.startswith(f"error: {path}:3 [mission.rates.control]: Input should be a finite number")
