"""``hiconav config``: validate a settings file and print the effective settings."""

from __future__ import annotations

from pathlib import Path

import typer
import yaml

from hiconav.settings import describe_settings, effective_settings, resolve


def config(
    file: Path | None = typer.Argument(None, help="Settings YAML to validate (sections sim, memory, ...)."),
    settings: list[str] = typer.Option([], "--set", help="Override a setting: area.key=value (repeatable)."),
    describe: bool = typer.Option(False, "--describe",
                                  help="List every documented setting: its effective value, range and reason."),
) -> None:
    """Validate settings (file and --set) and print every section's effective values as YAML."""
    overrides = resolve(file, settings)
    if describe:
        for line in describe_settings(overrides):
            typer.echo(line)
        return
    typer.echo(yaml.safe_dump(effective_settings(overrides), sort_keys=False), nl=False)
