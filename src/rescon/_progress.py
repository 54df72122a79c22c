"""Progress bars on stderr: the one door every long computation goes through.

``enabled`` follows one rule everywhere: ``None`` shows a bar only when stderr is a
terminal (so pipes, CI logs and ``--json`` output stay clean), ``True`` forces it,
``False`` (the CLI's ``--quiet``) never shows one. Bars never write to stdout.
"""

from __future__ import annotations

import sys
from typing import Any

from ._validate import flag

__all__ = ["progress_bar", "wanted"]


def wanted(enabled: bool | None) -> bool:
    """Whether a bar should be shown: ``enabled``, or stderr is a terminal when None.
    Anything but True, False or None ("no", 0 …) is an InputError naming ``progress``,
    not read by its truth value."""
    if enabled is None:
        return sys.stderr.isatty()
    return flag("progress", enabled)


def progress_bar(enabled: bool | None, total: float | None, desc: str, *,
                 unit: str = "it", initial: float = 0, leave: bool = False,
                 position: int | None = None) -> Any:
    """A ``tqdm`` bar on stderr with ``total`` steps, or ``None`` when not :func:`wanted`.

    Callers treat ``None`` as "no bar" (``if bar is not None: bar.update()``).
    """
    if not wanted(enabled):
        return None
    from tqdm import tqdm

    return tqdm(total=total, desc=desc, unit=unit, initial=initial, leave=leave,
                position=position, file=sys.stderr, dynamic_ncols=True)
