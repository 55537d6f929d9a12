"""The one YAML loader (hiconav.yamlio): hostile or broken text is one ConfigError naming file:line."""

from __future__ import annotations

from pathlib import Path

import pytest

from hiconav.errors import ConfigError
from hiconav.trees.errors import TreeError
from hiconav.yamlio import LIMITS, Limits, compose_text, load_file, load_text


def write(tmp_path: Path, content: str | bytes, name: str = "hostile.yaml") -> Path:
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content, encoding="utf-8")
    return path


def alias_bomb(levels: int = 9, width: int = 9) -> str:
    """Aliases of aliases: ``width ** levels`` scalars once expanded, a few hundred bytes of text."""
    lines = ["l0: &l0 [" + ", ".join(["lol"] * width) + "]"]
    lines += [f"l{i}: &l{i} [" + ", ".join([f"*l{i - 1}"] * width) + "]" for i in range(1, levels + 1)]
    return "\n".join(lines) + "\n"


# -- encoding and characters ---------------------------------------------------------------------
def test_invalid_utf8_names_the_line_and_column_of_the_bad_byte(tmp_path: Path) -> None:
    path = write(tmp_path, "a: 1\nb: caf\xe9\n".encode("latin-1"))
    with pytest.raises(ConfigError, match="not UTF-8") as info:
        load_file(path)
    assert f"{path}:2" in str(info.value)
    assert "0xe9 at column 7" in str(info.value)


def test_a_binary_file_is_refused_as_not_utf8(tmp_path: Path) -> None:
    path = write(tmp_path, b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR")
    with pytest.raises(ConfigError, match="not UTF-8") as info:
        load_file(path)
    assert info.value.line == 1


def test_a_nul_byte_is_refused_with_its_line(tmp_path: Path) -> None:
    path = write(tmp_path, "a: 1\nb: x\x00y\n")
    with pytest.raises(ConfigError, match="NUL byte at column 5") as info:
        load_file(path)
    assert f"{path}:2" in str(info.value)


def test_a_control_character_is_refused_with_its_line(tmp_path: Path) -> None:
    path = write(tmp_path, "a: 1\n\nb: \x1b[31mred\n")
    with pytest.raises(ConfigError, match=r"control character '\\x1b'") as info:
        load_file(path)
    assert f"{path}:3" in str(info.value)


def test_a_non_character_is_refused_as_non_printable() -> None:
    with pytest.raises(ConfigError, match=r"non-printable character '\\ufffe'") as info:
        load_text("a: \ufffe\n", source="odd.yaml")
    assert info.value.line == 1


def test_a_byte_order_mark_is_accepted(tmp_path: Path) -> None:
    path = write(tmp_path, "\ufeffa: 1\n")
    assert load_file(path)[0] == {"a": 1}


def test_a_file_larger_than_the_limit_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "a: " + "x" * 200 + "\n")
    with pytest.raises(ConfigError, match="larger than 100 bytes"):
        load_file(path, limits=Limits(max_bytes=100))


def test_an_unreadable_path_is_a_config_error(tmp_path: Path) -> None:
    with pytest.raises(ConfigError, match="cannot read") as info:
        load_file(tmp_path)  # a directory
    assert info.value.file == str(tmp_path)


# -- structure: depth, size, recursion, duplicates -------------------------------------------------
def test_thousands_of_nested_brackets_are_refused_not_a_recursion_error() -> None:
    with pytest.raises(ConfigError, match=f"nesting deeper than {LIMITS.max_depth} levels") as info:
        load_text("a: " + "[" * 5000 + "]" * 5000 + "\n", source="deep.yaml")
    assert str(info.value).startswith("deep.yaml:1:")


def test_nested_mappings_are_bounded_as_well() -> None:
    text = "a:\n" + "".join("  " * i + f"k{i}:\n" for i in range(1, 150)) + "  " * 150 + "v: 1\n"
    with pytest.raises(ConfigError, match="nesting deeper than 100") as info:
        load_text(text, source="deep.yaml")
    assert info.value.line == 101  # the mapping that opens level 101


def test_exactly_the_depth_limit_is_accepted() -> None:
    data, _ = load_text("[" * 100 + "]" * 100)
    for _ in range(99):
        data = data[0]
    assert data == []


def test_nesting_through_aliases_counts_towards_the_depth() -> None:
    text = "a: &a " + "[" * 60 + "]" * 60 + "\nb: " + "[" * 50 + "*a" + "]" * 50 + "\n"
    with pytest.raises(ConfigError, match="nesting deeper than 100 levels once aliases are expanded") as info:
        load_text(text, source="alias_deep.yaml")
    assert info.value.line == 2


def test_an_alias_bomb_is_refused_at_the_alias_that_crosses_the_limit() -> None:
    text = alias_bomb()  # 9 ** 9 = 387 million scalars once expanded
    with pytest.raises(ConfigError, match="more than 100000 nodes once aliases are expanded") as info:
        load_text(text, source="bomb.yaml")
    assert info.value.line == 6  # l5 holds 9 copies of l4 (9 ** 5 = 59049 scalars each)


def test_nodes_are_counted_with_aliases_expanded() -> None:
    # root mapping, key a, [1, 2, 3] (4), key b, [*a, *a] (1 + 4 + 4): 16 nodes in all
    text = "a: &a [1, 2, 3]\nb: [*a, *a]\n"
    assert load_text(text, limits=Limits(max_nodes=16))[0] == {"a": [1, 2, 3], "b": [[1, 2, 3], [1, 2, 3]]}
    with pytest.raises(ConfigError, match="more than 15 nodes"):
        load_text(text, limits=Limits(max_nodes=15))


def test_a_recursive_alias_in_a_sequence_is_refused() -> None:
    with pytest.raises(ConfigError, match=r"recursive alias \*x") as info:
        load_text("a: 1\nb: &x [1, *x]\n", source="rec.yaml")
    assert info.value.line == 2


def test_a_recursive_alias_in_a_mapping_is_refused_with_the_anchor_line() -> None:
    with pytest.raises(ConfigError, match=r"anchored &x on line 1") as info:
        load_text("a: &x\n  b:\n    c: *x\n", source="rec.yaml")
    assert info.value.line == 3


def test_an_alias_to_a_finished_node_is_shared_not_refused() -> None:
    assert load_text("a: &x {k: 1}\nb: [*x, *x]\n")[0] == {"a": {"k": 1}, "b": [{"k": 1}, {"k": 1}]}


def test_a_duplicate_key_names_the_line_of_the_second_and_the_first() -> None:
    with pytest.raises(ConfigError, match=r"duplicate key 'tau' \(first given on line 2\)") as info:
        load_text("memory:\n  tau: 0.5\n  r: 2\n  tau: 0.6\n", source="dup.yaml")
    assert str(info.value).startswith("dup.yaml:4:")


def test_keys_that_differ_only_in_quoting_are_duplicates() -> None:
    with pytest.raises(ConfigError, match="duplicate key"):
        load_text("a: 1\n'a': 2\n")


def test_a_merge_key_may_be_overridden_without_a_duplicate() -> None:
    assert load_text("base: &b {x: 1, y: 2}\nc:\n  <<: *b\n  x: 3\n")[0]["c"] == {"x": 3, "y": 2}


def test_the_same_key_in_different_mappings_is_fine() -> None:
    assert load_text("a: {k: 1}\nb: {k: 2}\n")[0] == {"a": {"k": 1}, "b": {"k": 2}}


# -- syntax and values ---------------------------------------------------------------------------
def test_a_syntax_error_names_the_line() -> None:
    with pytest.raises(ConfigError, match="not valid YAML") as info:
        load_text("a:\n  b: [1,\n  c: 2\n", source="syntax.yaml")
    assert info.value.file == "syntax.yaml" and info.value.line is not None


def test_a_second_document_is_refused() -> None:
    with pytest.raises(ConfigError, match="single document") as info:
        load_text("a: 1\n---\nb: 2\n")
    assert info.value.line == 2


def test_a_value_that_cannot_be_constructed_is_an_error_not_a_value_error() -> None:
    with pytest.raises(ConfigError, match="cannot read the value '2001-13-45'") as info:
        load_text("a: 1\nwhen: 2001-13-45\n", source="date.yaml")
    assert info.value.line == 2


def test_python_tags_are_not_constructed() -> None:
    with pytest.raises(ConfigError, match="could not determine a constructor"):
        load_text("a: !!python/object/apply:os.system [echo hi]\n")


def test_an_empty_text_is_no_document() -> None:
    assert load_text("") == (None, None)
    assert compose_text("# only a comment\n") is None


def test_errors_take_the_callers_error_class() -> None:
    with pytest.raises(TreeError):
        load_text("a: [1,\n", error=TreeError)
