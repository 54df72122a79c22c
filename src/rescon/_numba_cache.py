"""A cache directory for numba's compiled kernels wherever rescon is installed.

numba caches a ``cache=True`` kernel next to its module (the package's ``__pycache__``)
or, for a read-only package, in the user's cache directory. When neither can be written
(a system or container install run by another user with HOME=/, say) numba refuses
every such kernel at import with a RuntimeError ("no locator available"). The packages
holding rescon's kernels (``rescon.graphs``, ``rescon.geometry``) call
:func:`ensure_numba_cache` before any of their modules import numba.
"""

from __future__ import annotations

import os
from pathlib import Path

#: set once the check has run in this process (it is the same answer every time)
_checked = False


def ensure_numba_cache() -> None:
    """Give numba a cache directory when it would find none.

    Tries numba's first choice as numba does (a temporary file in the package's
    ``__pycache__``), without importing numba; only when that fails asks numba's own
    cache locators, in its order, about a file of the package. When none can cache
    there, sets ``NUMBA_CACHE_DIR`` (numba's config and the environment, for worker
    processes) to ``rescon-numba-<uid>`` in the temporary directory — used only when it
    is a directory of this user that no one else may write (numba's cache holds
    pickles), else a fresh private one. A user's own ``NUMBA_CACHE_DIR`` is kept; a
    numba without these internals is left to its own behaviour."""
    global _checked
    if _checked or os.environ.get("NUMBA_CACHE_DIR"):
        return
    _checked = True
    import tempfile

    probe = str(Path(__file__).parent / "graphs" / "_kernels.py")
    pycache = os.path.join(os.path.dirname(probe), "__pycache__")
    try:
        os.makedirs(pycache, exist_ok=True)
        tempfile.TemporaryFile(dir=pycache).close()
        return
    except OSError:
        pass
    try:
        from numba.core import caching, config

        if any(cls.from_function(ensure_numba_cache, probe) is not None
               for cls in caching.CacheImpl._locator_classes):
            return
        config.CACHE_DIR = os.environ["NUMBA_CACHE_DIR"] = _private_directory()
    except Exception:  # noqa: BLE001 (a numba without these internals: its own behaviour)
        return


def _private_directory() -> str:
    """``<tmp>/rescon-numba-<uid>`` when it is this user's and no one else may write it,
    else a fresh private directory."""
    import stat
    import tempfile

    if hasattr(os, "getuid"):
        path = os.path.join(tempfile.gettempdir(), f"rescon-numba-{os.getuid()}")
        try:
            os.mkdir(path, 0o700)
        except FileExistsError:
            pass
        st = os.lstat(path)
        if stat.S_ISDIR(st.st_mode) and st.st_uid == os.getuid() and not st.st_mode & 0o022:
            return path
    return tempfile.mkdtemp(prefix="rescon-numba-")
