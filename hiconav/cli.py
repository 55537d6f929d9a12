"""The ``hiconav`` command line: one subcommand per user task.

Each subcommand lives in the module of the layer it exercises (``hiconav/<area>/cli.py``) and is
registered here; those modules import heavy dependencies (torch, moderngl) inside the command
body so that ``hiconav --help`` stays fast. Errors meant for the user (``HiconavError``) are
printed as one clear message, never as a bare traceback.
"""

from __future__ import annotations

import importlib
import sys

import click
import typer

from hiconav import __version__
from hiconav.errors import HiconavError

app = typer.Typer(
    name="hiconav",
    help="HiCo-Nav: hierarchical vision-language object navigation (simulator, missions, evaluation).",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

# (subcommand, module, function): the module owns the options and the implementation.
SUBCOMMANDS: list[tuple[str, str, str]] = [
    ("run", "hiconav.mission", "run_command"),
    ("sim", "hiconav.sim.cli", "sim"),
    ("vehicle", "hiconav.drivers.cli", "vehicle"),
    ("parse", "hiconav.reasoning.cli", "parse"),
    ("room-prior", "hiconav.reasoning.cli", "room_prior"),
    ("size-prior", "hiconav.reasoning.cli", "size_prior"),
    ("eval", "hiconav.eval.cli", "eval"),
    ("episodes", "hiconav.sim.episodes_cli", "episodes"),
    ("tree", "hiconav.trees.cli", "tree"),
    ("config", "hiconav.settings_cli", "config"),
]


def _version_callback(value: bool) -> None:
    if value:
        typer.echo(f"hiconav {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: bool = typer.Option(False, "--version", callback=_version_callback, is_eager=True,
                                 help="Print the version and exit."),
) -> None:
    """HiCo-Nav command line."""


def _register() -> None:
    for name, module_name, attr in SUBCOMMANDS:
        module = importlib.import_module(module_name)
        app.command(name)(getattr(module, attr))


_register()


def main(argv: list[str] | None = None) -> int:
    """Entry point; returns the process exit code."""
    try:
        app(args=argv, standalone_mode=False)
    except HiconavError as exc:
        typer.secho(f"error: {exc}", fg=typer.colors.RED, err=True)
        return 2
    except click.exceptions.Exit as exc:
        return exc.exit_code
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    except click.exceptions.Abort:
        typer.echo("aborted", err=True)
        return 130
    except KeyboardInterrupt:
        typer.echo("interrupted", err=True)
        return 130
    except (FileNotFoundError, PermissionError, IsADirectoryError) as exc:
        typer.secho(f"error: {exc}", fg=typer.colors.RED, err=True)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
