"""``hiconav tree FILE``: validate a mission tree and print it (ASCII; dot/SVG on request).

Registered by the lead in ``hiconav/cli.py`` as ("tree", "hiconav.trees.cli", "tree"). Validation
errors are ``TreeError`` (file:line [key]) and are printed by the CLI without a traceback.
"""

from __future__ import annotations

from pathlib import Path

import typer


def tree(
    source: str = typer.Argument(..., help="Mission YAML file, or a tree name such as 'objectnav'."),
    dot: Path | None = typer.Option(None, "--dot", help="Also write Graphviz dot to this file."),
    svg: Path | None = typer.Option(None, "--svg", help="Also render an SVG (needs the graphviz 'dot' program)."),
    params: bool = typer.Option(False, "--params", help="List each leaf's parameters."),
) -> None:
    """Validate a mission tree and print it."""
    import py_trees
    from hiconav.trees.builder import BlackboardRef, build_tree, load_tree

    definition = load_tree(source)
    root, _ = build_tree(definition)
    typer.echo(f"{definition.name}: {definition.file}")
    if definition.description:
        typer.echo(f"  {definition.description}")
    for inc in definition.includes:
        typer.echo(f"  includes {inc}")
    typer.echo(py_trees.display.ascii_tree(root))
    if params:
        def walk(node, depth=0):
            shown = {k: (f"{{{v.key}}}" if isinstance(v, BlackboardRef) else v) for k, v in node.params.items()}
            typer.echo(f"{'  ' * depth}{node.type} {node.name!r} {shown}  ({Path(node.file).name}:{node.line})")
            for c in node.children:
                walk(c, depth + 1)
        walk(definition.root)
    if dot is not None:
        graph = py_trees.display.dot_tree(root)
        dot.write_text(graph.to_string())
        typer.echo(f"wrote {dot}")
    if svg is not None:
        graph = py_trees.display.dot_tree(root)
        try:
            svg.write_bytes(graph.create_svg())
        except Exception as exc:  # pydot needs the graphviz binary
            raise typer.BadParameter(f"cannot render SVG ({exc}); use --dot and render it with graphviz") from exc
        typer.echo(f"wrote {svg}")
