"""rescon.sweep: experiment grids on Dask (DESIGN.md, ``rescon sweep``).

:func:`sweep` runs every cell of a grid (:mod:`rescon.sweep.grid`) as one Dask task —
the pure function :func:`rescon.sweep.cell.run_cell`, spec dict → row dict — on an
embedded ``distributed.LocalCluster`` or any running scheduler, and streams the rows to
a resumable Parquet table (:mod:`rescon.sweep.run`). Dask, pandas and pyarrow are
imported when a sweep runs (``pip install rescon[dask]``).

The package itself is callable — ``rescon.sweep(grid, ...)`` is :func:`sweep` — so the
API name of DESIGN.md and the subpackage (``import rescon.sweep.grid``) coexist."""

import sys
import types
from typing import Any

from .run import sweep

__all__ = ["sweep"]


class _CallableModule(types.ModuleType):
    """This package, callable as :func:`sweep`."""

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return sweep(*args, **kwargs)

    @property
    def __signature__(self) -> Any:
        """:func:`sweep`'s, for ``inspect.signature(rescon.sweep)`` and ``help``."""
        import inspect

        return inspect.signature(sweep)


sys.modules[__name__].__class__ = _CallableModule
