"""Exceptions of the cryoslosh package: one class per exit code of the ``cryoslosh`` CLI, carrying
the message the CLI prints after ``error:``."""

from __future__ import annotations

from typing import Any, Optional


class CryosloshError(Exception):
    """Base class of every error the engine raises."""

    #: The exit code of the CLI for the same failure.
    exit_code: int = 1


class BadInputError(CryosloshError, ValueError):
    """Bad input (CLI exit code 2): the campaign, an override, an option or an output directory.

    Nothing was written. When the campaign names them, ``file``, ``key`` (the dotted key path),
    ``value`` and ``allowed`` (the allowed range) say what was wrong; otherwise they are None.
    """

    exit_code = 2

    def __init__(
        self,
        message: str,
        file: Optional[str] = None,
        key: Optional[str] = None,
        value: Optional[str] = None,
        allowed: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        self.file = file
        self.key = key
        self.value = value
        self.allowed = allowed


class RunFailedError(CryosloshError, RuntimeError):
    """A runtime or I/O failure (CLI exit code 1): a full disk, an unreadable file, a GPU error."""

    exit_code = 1


class UntrustedError(CryosloshError):
    """The run finished (CLI exit code 3) but rejected or diverged more instances than
    ``[statistics]`` allows; ``result`` holds its tables all the same."""

    exit_code = 3

    def __init__(self, message: str, result: Any = None) -> None:
        super().__init__(message)
        self.result = result
