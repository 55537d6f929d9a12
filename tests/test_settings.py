"""Settings files: defaults documented in config/default.yaml, strict validation with file:line."""

from __future__ import annotations

from pathlib import Path

import pytest
import yaml

from hiconav.errors import ConfigError
from hiconav.settings import DEFAULT_FILE, effective_settings, load_settings_file, resolve


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "settings.yaml"
    path.write_text(text)
    return path


def test_default_file_equals_the_code_defaults() -> None:
    assert DEFAULT_FILE.is_file()
    assert effective_settings(load_settings_file(DEFAULT_FILE)) == effective_settings({})
    assert yaml.safe_load(DEFAULT_FILE.read_text()) == effective_settings({})


def test_a_settings_file_overrides_only_what_it_names(tmp_path: Path) -> None:
    path = write(tmp_path, "memory:\n  tau: 0.55\nexploration:\n  utility:\n    beta: 5.0\n")
    overrides = load_settings_file(path)
    assert overrides == {"memory.tau": 0.55, "exploration.utility.beta": 5.0}
    eff = effective_settings(overrides)
    assert eff["memory"]["tau"] == 0.55 and eff["exploration"]["utility"]["beta"] == 5.0
    assert eff["sim"]["max_steps"] == 500


def test_set_options_win_over_the_file(tmp_path: Path) -> None:
    path = write(tmp_path, "memory:\n  tau: 0.55\n")
    assert resolve(path, ["memory.tau=0.7"])["memory.tau"] == 0.7


@pytest.mark.parametrize(
    ("text", "line", "field"),
    [
        ("memory:\n  tua: 0.5\n", 2, "memory.tua"),  # typo: unknown key
        ("sim:\n  width: 640\nmemroy:\n  tau: 1\n", 3, "memroy"),  # unknown section
        ("memory:\n  tau: 7.0\n", 2, "memory.tau"),  # out of range
        ("exploration:\n  utility:\n    beta: lots\n", 3, "exploration.utility.beta"),  # wrong type
        ("sim: [1, 2]\n", 1, "sim"),  # a section that is not a mapping
    ],
)
def test_bad_settings_name_file_line_and_field(tmp_path: Path, text: str, line: int, field: str) -> None:
    path = write(tmp_path, text)
    with pytest.raises(ConfigError) as info:
        load_settings_file(path)
    assert f"{path}:{line}" in str(info.value)
    assert field in str(info.value)


def test_malformed_yaml_names_the_line(tmp_path: Path) -> None:
    path = write(tmp_path, "memory:\n  tau: 0.5\n  r: [1,\n")
    with pytest.raises(ConfigError, match=r"settings.yaml:\d+"):
        load_settings_file(path)


def test_bad_set_option_is_a_clear_error() -> None:
    with pytest.raises(ConfigError, match="memory.nosuch"):
        resolve(None, ["memory.nosuch=1"])
    with pytest.raises(ConfigError, match="area.key=value"):
        resolve(None, ["tau=1"])
