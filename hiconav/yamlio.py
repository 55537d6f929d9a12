"""The one YAML loader of hiconav: mission trees, settings files, ``--set`` values, robot profiles.

Every YAML text that a user hands us goes through here, so that hostile or broken input gets one
clear ``ConfigError`` naming ``file:line`` and never a traceback or a hang:

- bytes are decoded as UTF-8 (the line and column of the first bad byte are named);
- NUL and other control characters (PyYAML's ``ReaderError``) are reported with their line;
- nesting deeper than ``Limits.max_depth`` is refused while composing, before Python's recursion
  limit is reached (also when aliases nest one deep structure inside another);
- a document larger than ``Limits.max_nodes`` once aliases are expanded is refused: every node
  carries its expanded size, an alias adds the size of the node it names, so an alias bomb
  ("billion laughs", aliases of aliases) is counted in linear time and never expanded;
- an alias that refers to the collection it sits in (a recursive structure) is refused;
- a key given twice in one mapping is refused with the line of the second key (and of the first).

The composed node tree keeps its marks, so callers map their own errors (pydantic, the tree
builder) back to lines. This module only reads text: it knows nothing of settings, trees or
profiles, and must not import them.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from yaml.events import AliasEvent, MappingEndEvent, MappingStartEvent, SequenceEndEvent, SequenceStartEvent
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

from hiconav.errors import ConfigError

__all__ = ["LIMITS", "Limits", "compose_file", "compose_text", "construct", "load_file", "load_text", "read_text"]


@dataclass(frozen=True)
class Limits:
    """Bounds on one YAML document (far above anything a mission, settings file or profile needs)."""

    max_depth: int = 100  # nested collections, aliases expanded
    max_nodes: int = 100_000  # scalars + collections, aliases expanded
    max_bytes: int = 8 * 1024 * 1024  # size of the file


LIMITS = Limits()


class _Refused(yaml.MarkedYAMLError):
    """A document that is well-formed YAML but one we refuse (too deep, too large, recursive, duplicate)."""


class _Loader(yaml.SafeLoader):
    """SafeLoader whose composer bounds depth and expanded size and rejects recursion and duplicates."""

    def __init__(self, stream: str, limits: Limits) -> None:
        super().__init__(stream)
        self.limits = limits
        self._depth = 0  # collections open around the node being composed
        self._size: dict[int, int] = {}  # id(collection node) -> nodes once aliases are expanded
        self._height: dict[int, int] = {}  # id(collection node) -> nesting depth once expanded
        self._open: set[int] = set()  # ids of collections being composed (their aliases recurse)

    # -- expanded size and height of a composed node --------------------------------------------
    def _node_size(self, node: Node) -> int:
        return self._size.get(id(node), 1)

    def _node_height(self, node: Node) -> int:
        return self._height.get(id(node), 0)

    def _add_child(self, total: int, height: int, child: Node, mark: Any) -> tuple[int, int]:
        """Account for ``child`` (composed at ``mark``) in its parent's size and height."""
        total += self._node_size(child)
        if total > self.limits.max_nodes:
            raise _Refused(None, None, f"the document holds more than {self.limits.max_nodes} nodes once "
                           "aliases are expanded (an alias bomb?); split it or use fewer aliases", mark)
        height = max(height, 1 + self._node_height(child))
        if self._depth + height - 1 > self.limits.max_depth:
            raise _Refused(None, None, f"nesting deeper than {self.limits.max_depth} levels once aliases "
                           "are expanded", mark)
        return total, height

    # -- composer ---------------------------------------------------------------------------------
    def compose_node(self, parent: Node | None, index: Any) -> Node:
        event = self.peek_event()
        if isinstance(event, AliasEvent):
            target = self.anchors.get(event.anchor)
            if target is not None and id(target) in self._open:
                raise _Refused(None, None, f"recursive alias *{event.anchor}: it sits inside the collection "
                               f"anchored &{event.anchor} on line {target.start_mark.line + 1} (a structure that "
                               "contains itself); an alias may only name a finished node", event.start_mark)
            return super().compose_node(parent, index)
        if isinstance(event, (SequenceStartEvent, MappingStartEvent)) and self._depth >= self.limits.max_depth:
            raise _Refused(None, None, f"nesting deeper than {self.limits.max_depth} levels", event.start_mark)
        return super().compose_node(parent, index)

    def _start_collection(self, cls: type[Node], anchor: str | None) -> Node:
        start_event = self.get_event()
        tag = start_event.tag
        if tag is None or tag == "!":
            tag = self.resolve(cls, None, start_event.implicit)
        node = cls(tag, [], start_event.start_mark, None, flow_style=start_event.flow_style)
        if anchor is not None:
            self.anchors[anchor] = node
        self._open.add(id(node))
        self._depth += 1
        return node

    def _end_collection(self, node: Node, total: int, height: int) -> Node:
        node.end_mark = self.get_event().end_mark
        self._open.discard(id(node))
        self._depth -= 1
        self._size[id(node)] = total
        self._height[id(node)] = height
        return node

    def compose_sequence_node(self, anchor: str | None) -> SequenceNode:
        node = self._start_collection(SequenceNode, anchor)
        total, height, index = 1, 1, 0
        while not self.check_event(SequenceEndEvent):
            mark = self.peek_event().start_mark
            child = self.compose_node(node, index)
            node.value.append(child)
            total, height = self._add_child(total, height, child, mark)
            index += 1
        return self._end_collection(node, total, height)

    def compose_mapping_node(self, anchor: str | None) -> MappingNode:
        node = self._start_collection(MappingNode, anchor)
        total, height = 1, 1
        seen: dict[Any, Node] = {}
        while not self.check_event(MappingEndEvent):
            mark = self.peek_event().start_mark
            key = self.compose_node(node, None)
            total, height = self._add_child(total, height, key, mark)
            identity = self._key_identity(key)
            if identity is not None:
                if identity in seen:
                    first = seen[identity]
                    raise _Refused(None, None, f"duplicate key {key.value!r} (first given on line "
                                   f"{first.start_mark.line + 1}); give each key once", mark)
                seen[identity] = key
            mark = self.peek_event().start_mark
            value = self.compose_node(node, key)
            total, height = self._add_child(total, height, value, mark)
            node.value.append((key, value))
        return self._end_collection(node, total, height)

    def _key_identity(self, key: Node) -> Any:
        """What makes two scalar keys the same key (their constructed value); None: not compared."""
        if not isinstance(key, ScalarNode):
            return None
        try:
            value = self.construct_object(key)
            hash(value)
        except Exception:  # noqa: BLE001 - a key that cannot be constructed is compared by its text
            return (key.tag, key.value)
        return (type(value).__name__, value)

    # -- constructor --------------------------------------------------------------------------------
    def construct_object(self, node: Node, deep: bool = False) -> Any:
        try:
            return super().construct_object(node, deep=deep)
        except yaml.YAMLError:
            raise
        except (ValueError, OverflowError, TypeError) as exc:  # a timestamp "2001-13-45", a 5000-digit int
            raise yaml.constructor.ConstructorError(None, None, f"cannot read the value {_short(node)} ({exc})",
                                                    node.start_mark) from None


def _short(node: Node, width: int = 40) -> str:
    """The text of a scalar node for a message, cut to ``width`` characters."""
    text = str(node.value) if isinstance(node, ScalarNode) else f"<{node.id}>"
    return repr(text if len(text) <= width else text[:width] + "...")


def _position(text: str, index: int) -> tuple[int, int]:
    """1-based (line, column) of character ``index`` of ``text``."""
    line = text.count("\n", 0, index) + 1
    return line, index - (text.rfind("\n", 0, index) + 1) + 1


def _convert(exc: yaml.YAMLError, text: str, source: str, error: type[ConfigError], field: str | None) -> ConfigError:
    """A PyYAML error as ``error`` naming ``source:line`` and what is wrong, in one line."""
    if isinstance(exc, yaml.reader.ReaderError):
        line, column = _position(text, exc.position) if isinstance(exc.position, int) else (None, None)
        char = exc.character if isinstance(exc.character, str) else chr(exc.character)
        kind = "control" if ord(char) < 0x20 or 0x7F <= ord(char) <= 0x9F else "non-printable"
        what = "a NUL byte" if char == "\0" else f"the {kind} character {char!r} (#x{ord(char):04x})"
        return error(f"{what} at column {column}: YAML text may hold only printable characters "
                     "(is this a binary file?)", file=source, line=line, field=field)
    if isinstance(exc, yaml.MarkedYAMLError):
        mark = exc.problem_mark or exc.context_mark
        problem = exc.problem or exc.context or "invalid YAML"
        if isinstance(exc, _Refused):
            message = problem
        else:
            context = exc.context if exc.problem else None
            if context and exc.context_mark is not None and exc.context_mark is not mark:
                context += f" (line {exc.context_mark.line + 1})"
            if context and problem.startswith("but "):  # "expected X (line 1), but found Y"
                problem = f"{context}, {problem}"
            elif context:  # "expected ',' or ']', but got ... (while parsing a flow sequence, line 3)"
                problem = f"{problem} ({context})"
            message = f"not valid YAML: {problem}"
        return error(message, file=source, line=mark.line + 1 if mark is not None else None, field=field)
    return error(f"not valid YAML: {exc}", file=source, field=field)


def read_text(path: str | Path, *, error: type[ConfigError] = ConfigError, limits: Limits = LIMITS,
              what: str = "file") -> str:
    """The text of a UTF-8 file; ``error`` (file:line) when it is unreadable, too large or not UTF-8."""
    path = Path(path)
    source = str(path)
    try:
        with path.open("rb") as handle:
            data = handle.read(limits.max_bytes + 1)
    except OSError as exc:
        raise error(f"cannot read {what}: {exc.strerror or exc}", file=source) from None
    if len(data) > limits.max_bytes:
        raise error(f"the {what} is larger than {limits.max_bytes} bytes", file=source)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise error(f"not UTF-8 text: byte 0x{data[exc.start]:02x} at column {column} cannot be decoded "
                    "(save the file as UTF-8; is this a binary file?)", file=source, line=line) from None


def compose_text(text: str, *, source: str = "<yaml>", error: type[ConfigError] = ConfigError,
                 field: str | None = None, limits: Limits = LIMITS) -> Node | None:
    """The checked node tree of one YAML document (None when the text holds no document)."""
    try:
        loader = _Loader(text, limits)
    except yaml.YAMLError as exc:  # the reader checks the whole text for unprintable characters first
        raise _convert(exc, text, source, error, field) from None
    try:
        return loader.get_single_node()
    except yaml.YAMLError as exc:
        raise _convert(exc, text, source, error, field) from None
    except RecursionError:  # only when called from an already deep stack: the limits keep us far below
        raise error(f"nesting too deep to read (limit {limits.max_depth})", file=source, field=field) from None
    finally:
        loader.dispose()


def construct(node: Node | None, *, source: str = "<yaml>", error: type[ConfigError] = ConfigError,
              field: str | None = None) -> Any:
    """Python data (dicts, lists, scalars) of a node from ``compose_text``; errors name the line."""
    if node is None:
        return None
    loader = _Loader("", LIMITS)
    try:
        return loader.construct_document(node)
    except yaml.YAMLError as exc:
        raise _convert(exc, "", source, error, field) from None
    finally:
        loader.dispose()


def compose_file(path: str | Path, *, error: type[ConfigError] = ConfigError, limits: Limits = LIMITS,
                 what: str = "file") -> Node | None:
    """The checked node tree of a YAML file (None when it is empty)."""
    return compose_text(read_text(path, error=error, limits=limits, what=what), source=str(path), error=error,
                        limits=limits)


def load_text(text: str, *, source: str = "<yaml>", error: type[ConfigError] = ConfigError,
              field: str | None = None, limits: Limits = LIMITS) -> tuple[Any, Node | None]:
    """(data, root node) of one YAML document in ``text``; data is None for an empty text."""
    node = compose_text(text, source=source, error=error, field=field, limits=limits)
    return construct(node, source=source, error=error, field=field), node


def load_file(path: str | Path, *, error: type[ConfigError] = ConfigError, limits: Limits = LIMITS,
              what: str = "file") -> tuple[Any, Node | None]:
    """(data, root node) of a YAML file; data is None for an empty file."""
    node = compose_file(path, error=error, limits=limits, what=what)
    return construct(node, source=str(path), error=error), node
