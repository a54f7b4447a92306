"""The TOML reader on every supported Python: `from protocol.toml import tomllib`.

Python 3.11 has it in the standard library; on 3.10 it is tomli, the same parser under its PyPI
name (a dependency there only, pyproject.toml).
"""

from __future__ import annotations

import sys

if sys.version_info >= (3, 11):
    import tomllib
else:
    import tomli as tomllib

__all__ = ["tomllib"]
