"""Reading the TOML files gripkit takes as input (model descriptions, sweep specifications)."""

from __future__ import annotations

import tomllib
from pathlib import Path

from ..errors import ConfigError


def read_toml(path, what: str) -> dict:
    """The table in the TOML file ``path``; ``what`` names the file's role in the error messages
    ("sweep file", "model description"). Raises :class:`ConfigError` for a missing file or bad TOML."""
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"{what} {str(path)!r} not found")
    try:
        return tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path.name}: not valid TOML: {exc}") from None
