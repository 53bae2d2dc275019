"""Reading the TOML files gripkit takes as input (model descriptions, sweep specifications)."""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

from ..arguments import check_path
from ..errors import ConfigError


def read_toml(path, what: str) -> dict:
    """The table in the TOML file ``path``; ``what`` names the file's role in the error messages
    ("sweep file", "model description"). Raises :class:`ConfigError` for a missing or unreadable
    file (a folder, no permission, not UTF-8 text) or bad TOML."""
    check_path(path, what, "read_toml()")
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"{what} {str(path)!r} not found")
    if path.is_dir():
        raise ConfigError(f"{what} {str(path)!r} is a folder, expected a .toml file")
    try:
        text = path.read_bytes().decode("utf-8-sig")  # a leading BOM (Windows editors) is fine
    except UnicodeDecodeError as exc:
        raise ConfigError(f"{what} {str(path)!r} is not UTF-8 text (byte "
                          f"0x{exc.object[exc.start]:02x} at offset "
                          f"{exc.start} cannot be decoded)", hint="a TOML file is UTF-8 text: "
                                                                  "check that the "
                          "path names the .toml file, and save it as UTF-8") from None
    except PermissionError:
        raise ConfigError(f"{what} {str(path)!r} cannot be read: permission denied",
                          hint="make it readable (chmod u+r) or copy it "
                               "somewhere you can read") from None
    except OSError as exc:
        raise ConfigError(f"{what} {str(path)!r} cannot be read: {exc.strerror or exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path.name}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ConfigError(f"{what} {str(path)!r} cannot be read: its TOML nests arrays or tables "
                          f"deeper than Python's recursion limit ({sys.getrecursionlimit()})",
                          hint="a gripkit TOML file nests a few levels: check the file") from None
    except ValueError as exc:  # an integer beyond Python's limit on digits read from text
        raise ConfigError(f"{what} {str(path)!r} cannot be read: {str(exc).split(';')[0]} (a "
                          f"number in the file has more digits than any value gripkit takes)",
                          hint="check the file") from None
