"""Node labels in the order rescon prints them (messages, JSON witnesses)."""

from __future__ import annotations

from collections.abc import Hashable, Iterable

__all__ = ["sorted_labels"]


def sorted_labels(labels: Iterable[Hashable]) -> list[Hashable]:
    """Node labels in natural order: numbers first by value, then the rest by text — a
    total order for graphs whose labels mix ints and strings (``sorted`` alone raises
    TypeError there)."""
    return sorted(labels, key=lambda v: (0, v, "") if isinstance(v, (int, float)) and
                  not isinstance(v, bool) else (1, 0, str(v)))
