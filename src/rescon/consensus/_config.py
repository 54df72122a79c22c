"""Key checks for the dict (TOML) forms of adversaries, DoS schedules and attacks."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from typing import Any

from ..errors import InputError


def check_keys(what: str, d: Mapping[str, Any], required: Iterable[str],
               optional: Iterable[str] = (), tag: str | None = "kind") -> None:
    """One-line errors for unknown and missing keys of ``d`` (``tag``, the key that
    chose the kind, is always allowed)."""
    required, optional = tuple(required), tuple(optional)
    unknown = sorted(set(d) - set(required) - set(optional) - {tag})
    if unknown:
        raise InputError(
            f"{what} has unknown key(s) {unknown}; allowed: {sorted(required + optional)}"
        )
    missing = [k for k in required if k not in d]
    if missing:
        raise InputError(f"{what} is missing key(s) {missing}")
