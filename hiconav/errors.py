"""Project-wide error types.

Every user-facing error says what was wrong, where (file, line, field) and, where possible, what
would be right. The CLI catches ``HiconavError`` and prints its message without a traceback.
"""

from __future__ import annotations


class HiconavError(Exception):
    """Base class for errors meant for the user (printed without a traceback by the CLI)."""

    def __init__(self, message: str, *, file: str | None = None, line: int | None = None,
                 field: str | None = None) -> None:
        self.file = file
        self.line = line
        self.field = field
        where = ""
        if file is not None:
            where = str(file)
            if line is not None:
                where += f":{line}"
        if field is not None:
            where = f"{where} [{field}]" if where else f"[{field}]"
        self.reason = message
        super().__init__(f"{where}: {message}" if where else message)


class ConfigError(HiconavError):
    """Invalid configuration, robot profile or mission tree."""


class DataError(HiconavError):
    """Invalid input data: a house file, an episode file, a map."""


class FrameError(HiconavError):
    """A sensor frame that cannot be used (wrong shape, missing pose)."""
