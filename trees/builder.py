"""Mission trees from YAML: parse, validate (with file:line:key in every error) and build py_trees.

File format (one node = a mapping with exactly one key, the node type)::

    name: objectnav                 # optional, defaults to the file stem
    description: ...                # optional
    blackboard:                     # optional defaults written to the mission blackboard
      instruction: find the bed
    root:
      Sequence:
        name: objectnav             # every node may carry a name
        memory: true
        children:
          - ParseInstruction: {instruction: "{instruction}"}   # {key}: read from the blackboard
          - Subtree: {tree: find_target}                       # include another YAML tree by name
          - Timeout:
              duration: 120
              child:
                Explore: {}

Composites take ``children:`` (a non-empty list), decorators ``child:`` (one node), leaves
neither. ``Subtree`` includes another tree file (looked up beside the including file, then in
``trees/`` and ``trees/missions/``); cycles are rejected with the chain of file:line. Parameters
are checked against the node type's declaration (``trees/registry.py``): unknown keys, missing
required keys, types, ranges and choices. The builder never ticks a tree and never touches actors.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml
from hiconav import yamlio
from hiconav.trees.errors import TreeError
from hiconav.trees.registry import BLACKBOARD_REF, NodeSpec, spec_for

TREES_DIR = Path(__file__).resolve().parent
_TOP_KEYS = {"name", "description", "blackboard", "root"}
_STRUCTURAL = {"name", "children", "child"}


@dataclass(frozen=True)
class BlackboardRef:
    """A parameter that reads blackboard ``key`` at tick time (written ``{key}`` in YAML)."""

    key: str


@dataclass
class NodeDef:
    """A validated node: its type, name, parameters (literal or ``BlackboardRef``) and children.

    ``origin`` maps each parameter to "file:line" so that tick-time errors can name the YAML.
    """

    type: str
    name: str
    spec: NodeSpec
    params: dict[str, Any]
    origin: dict[str, str]
    children: list[NodeDef]
    file: str
    line: int


@dataclass
class TreeDefinition:
    """A parsed mission file: name, description, blackboard defaults, root node, files included."""

    name: str
    description: str
    blackboard: dict[str, Any]
    root: NodeDef
    file: str
    includes: list[str] = field(default_factory=list)


def _line(node: yaml.Node) -> int:
    return node.start_mark.line + 1


def _err(message: str, file: str, node: yaml.Node | None, key: str | None = None) -> TreeError:
    return TreeError(message, file=file, line=_line(node) if node is not None else None, field=key)


def _scalar(node: yaml.Node, file: str, key: str) -> Any:
    return yamlio.construct(node, source=file, error=TreeError, field=key)


def _mapping_items(node: yaml.Node, file: str, what: str, key: str | None = None) -> list[tuple[str, yaml.Node, yaml.Node]]:
    """(key, key_node, value_node) of a mapping node; rejects non-mappings and duplicate keys."""
    if not isinstance(node, yaml.MappingNode):
        raise _err(f"{what} must be a mapping, got {_kind(node)}", file, node, key)
    seen: dict[str, int] = {}
    items = []
    for k_node, v_node in node.value:
        if not isinstance(k_node, yaml.ScalarNode):
            raise _err(f"keys of {what} must be strings", file, k_node, key)
        k = str(k_node.value)
        if k in seen:
            raise _err(f"duplicate key {k!r} in {what} (first on line {seen[k]})", file, k_node, k)
        seen[k] = _line(k_node)
        items.append((k, k_node, v_node))
    return items


def _kind(node: yaml.Node) -> str:
    if isinstance(node, yaml.MappingNode):
        return "a mapping"
    if isinstance(node, yaml.SequenceNode):
        return "a list"
    return f"the scalar {node.value!r}"


def find_tree_file(name: str, base_dir: Path | None = None) -> Path | None:
    """Resolve a tree by name or path: beside ``base_dir``, then ``trees/``, then ``trees/missions/``."""
    candidates: list[Path] = []
    raw = Path(name)
    names = [raw] if raw.suffix in (".yaml", ".yml") else [raw.with_name(raw.name + ".yaml"), raw]
    for n in names:
        if n.is_absolute():
            candidates.append(n)
            continue
        if base_dir is not None:
            candidates.append(base_dir / n)
        candidates += [Path.cwd() / n, TREES_DIR / n, TREES_DIR / "missions" / n]
    for c in candidates:
        if c.is_file():
            return c.resolve()
    return None


class _Parser:
    def __init__(self) -> None:
        self.includes: list[str] = []

    def parse_file(self, path: Path, stack: tuple[tuple[str, str], ...] = ()) -> TreeDefinition:
        file = str(path)
        doc = yamlio.compose_file(path, error=TreeError, what="mission tree")
        if doc is None:
            raise TreeError("empty mission file: expected a mapping with a 'root' node", file=file, line=1)
        items = _mapping_items(doc, file, "a mission file")
        top = {k: (kn, vn) for k, kn, vn in items}
        for k, kn, _ in items:
            if k not in _TOP_KEYS:
                raise _err(f"unknown top-level key {k!r}; expected one of {sorted(_TOP_KEYS)}", file, kn, k)
        if "root" not in top:
            raise _err("missing required top-level key 'root'", file, doc, "root")
        name = path.stem
        if "name" in top:
            name = _scalar(top["name"][1], file, "name")
            if not isinstance(name, str) or not name:
                raise _err("'name' must be a non-empty string", file, top["name"][1], "name")
        description = ""
        if "description" in top:
            description = str(_scalar(top["description"][1], file, "description"))
        blackboard: dict[str, Any] = {}
        if "blackboard" in top:
            for k, _, vn in _mapping_items(top["blackboard"][1], file, "'blackboard'", "blackboard"):
                blackboard[k] = _scalar(vn, file, f"blackboard.{k}")
        stack = stack + ((str(path), f"{file}:{_line(top['root'][0])}"),)
        root = self.parse_node(top["root"][1], file, path.parent, stack, "root")
        return TreeDefinition(name, description, blackboard, root, file, list(self.includes))

    def parse_node(self, node: yaml.Node, file: str, base: Path, stack: tuple, where: str) -> NodeDef:
        if not isinstance(node, yaml.MappingNode):
            raise _err(f"{where}: a node must be a mapping {{Type: {{params}}}}, got {_kind(node)}", file, node, where)
        items = _mapping_items(node, file, "a node", where)
        if len(items) != 1:
            keys = [k for k, _, _ in items]
            raise _err(f"{where}: a node must have exactly one key (its type), got {keys}", file, node, where)
        type_name, type_node, body = items[0]
        try:
            spec = spec_for(type_name, field=type_name)
        except TreeError:
            raise
        except Exception as exc:  # ConfigError from the registry: add the file and line
            reason = getattr(exc, "reason", str(exc))
            raise _err(reason, file, type_node, type_name) from exc
        if isinstance(body, yaml.ScalarNode) and body.value in ("", "~", "null") and body.tag.endswith("null"):
            params_items: list[tuple[str, yaml.Node, yaml.Node]] = []
        else:
            params_items = _mapping_items(body, file, f"the parameters of {type_name}", type_name)
        if type_name == "Subtree":
            return self.parse_subtree(type_node, params_items, file, base, stack)
        name = type_name
        params: dict[str, Any] = {}
        origin: dict[str, str] = {}
        children: list[NodeDef] = []
        child_nodes: list[tuple[yaml.Node, str]] = []
        for key, key_node, value_node in params_items:
            if key == "name":
                value = _scalar(value_node, file, key)
                if not isinstance(value, str) or not value:
                    raise _err(f"{type_name}.name must be a non-empty string", file, value_node, key)
                name = value
            elif key == "children":
                if spec.kind != "composite":
                    raise _err(f"{type_name} is a {spec.kind} and takes no 'children'"
                               + ("; use 'child'" if spec.kind == "decorator" else ""), file, key_node, key)
                if not isinstance(value_node, yaml.SequenceNode):
                    raise _err(f"{type_name}.children must be a list of nodes, got {_kind(value_node)}",
                               file, value_node, key)
                child_nodes += [(c, f"{type_name}.children[{i}]") for i, c in enumerate(value_node.value)]
            elif key == "child":
                if spec.kind != "decorator":
                    raise _err(f"{type_name} is a {spec.kind} and takes no 'child'"
                               + ("; use 'children'" if spec.kind == "composite" else ""), file, key_node, key)
                if isinstance(value_node, yaml.SequenceNode):
                    raise _err(f"{type_name}.child must be one node (a mapping), not a list", file, value_node, key)
                child_nodes.append((value_node, f"{type_name}.child"))
            else:
                if key not in spec.params:
                    known = sorted(spec.params) or ["(no parameters)"]
                    raise _err(f"unknown parameter {key!r} of {type_name}; known: {known}", file, key_node, key)
                decl = spec.params[key]
                value = _scalar(value_node, file, key)
                origin[key] = f"{file}:{_line(value_node)}"
                if isinstance(value, str) and value.startswith("{") and value.endswith("}"):
                    match = BLACKBOARD_REF.match(value)
                    if match is None:
                        raise _err(f"{type_name}.{key}: malformed blackboard reference {value!r}; "
                                   "write {key} with a key of letters, digits, '_', '.' or '/'",
                                   file, value_node, key)
                    if not decl.blackboard:
                        raise _err(f"{type_name}.{key} must be a literal, not a blackboard reference",
                                   file, value_node, key)
                    params[key] = BlackboardRef(match.group(1))
                    continue
                problem = decl.check(value)
                if problem is not None:
                    raise _err(f"{type_name}.{key}: {problem}", file, value_node, key)
                params[key] = value
        for key, decl in spec.params.items():
            if key not in params and not decl.from_settings:
                if decl.required:
                    raise _err(f"{type_name} requires parameter {key!r} ({decl.type.__name__})",
                               file, type_node, key)
                default = decl.default
                match = BLACKBOARD_REF.match(default) if isinstance(default, str) else None
                params[key] = BlackboardRef(match.group(1)) if match else default
                origin.setdefault(key, f"{file}:{_line(type_node)}")
        if spec.kind == "composite" and not child_nodes:
            raise _err(f"{type_name} needs a non-empty 'children' list", file, type_node, "children")
        if spec.kind == "decorator" and len(child_nodes) != 1:
            raise _err(f"{type_name} is a decorator and needs exactly one 'child'", file, type_node, "child")
        for child_node, child_where in child_nodes:
            children.append(self.parse_node(child_node, file, base, stack, child_where))
        return NodeDef(type_name, name, spec, params, origin, children, file, _line(type_node))

    def parse_subtree(self, type_node: yaml.Node, items: list, file: str, base: Path, stack: tuple) -> NodeDef:
        values = {k: (kn, vn) for k, kn, vn in items}
        for k, kn, _ in items:
            if k not in ("tree", "name"):
                raise _err(f"unknown parameter {k!r} of Subtree; known: ['name', 'tree']", file, kn, k)
        if "tree" not in values:
            raise _err("Subtree requires parameter 'tree' (a tree name or file)", file, type_node, "tree")
        ref = _scalar(values["tree"][1], file, "tree")
        if not isinstance(ref, str) or not ref:
            raise _err("Subtree.tree must be a tree name (string)", file, values["tree"][1], "tree")
        path = find_tree_file(ref, base)
        here = f"{file}:{_line(values['tree'][1])}"
        if path is None:
            raise _err(f"Subtree: no tree named {ref!r} (looked beside {file}, in {TREES_DIR} "
                       f"and {TREES_DIR / 'missions'})", file, values["tree"][1], "tree")
        chain = [s[0] for s in stack]
        if str(path) in chain:
            trail = " -> ".join(s[1] for s in stack[chain.index(str(path)):]) + f" -> {here}"
            raise _err(f"Subtree cycle: {ref!r} includes itself ({trail})", file, values["tree"][1], "tree")
        self.includes.append(str(path))
        sub = self.parse_file(path, stack + ((str(path), here),))
        root = sub.root
        if "name" in values:
            root.name = str(_scalar(values["name"][1], file, "name"))
        return root


def load_tree(source: str | Path) -> TreeDefinition:
    """Parse and validate a mission tree (a file path or a tree name such as ``objectnav``).

    Raises ``TreeError`` naming file:line [key] on any problem.
    """
    path = find_tree_file(str(source))
    if path is None:
        raise TreeError(f"no mission tree {str(source)!r} (a YAML file path or a name in {TREES_DIR})",
                        file=str(source))
    return _Parser().parse_file(path)


def build_node(node: NodeDef) -> Any:
    """Instantiate the py_trees behaviour (with its children) for a validated ``NodeDef``."""
    children = [build_node(c) for c in node.children]
    spec = node.spec
    if spec.kind == "leaf":
        return spec.factory(name=node.name, params=node.params, origin=node.origin)
    if spec.kind == "decorator":
        return spec.factory(node.name, children[0], node.params)
    return spec.factory(node.name, children, node.params)


def build_tree(source: str | Path | TreeDefinition) -> tuple[Any, TreeDefinition]:
    """Load (if needed), validate and build a mission tree; returns (root behaviour, definition)."""
    definition = source if isinstance(source, TreeDefinition) else load_tree(source)
    return build_node(definition.root), definition
