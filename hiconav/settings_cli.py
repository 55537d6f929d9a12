"""``hiconav config``: validate a settings file and print the effective settings."""

from __future__ import annotations

from pathlib import Path

import typer
import yaml

from hiconav.settings import effective_settings, resolve


def config(
    file: Path | None = typer.Argument(None, help="Settings YAML to validate (sections sim, memory, ...)."),
    settings: list[str] = typer.Option([], "--set", help="Override a setting: area.key=value (repeatable)."),
) -> None:
    """Validate settings (file and --set) and print every section's effective values as YAML."""
    overrides = resolve(file, settings)
    typer.echo(yaml.safe_dump(effective_settings(overrides), sort_keys=False), nl=False)
