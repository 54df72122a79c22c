"""rescon.sweep: experiment grids on Dask (DESIGN.md, ``rescon sweep``).

:func:`sweep` runs every cell of a grid (:mod:`rescon.sweep.grid`) as one Dask task —
the pure function :func:`rescon.sweep.cell.run_cell`, spec dict → row dict — on an
embedded ``distributed.LocalCluster`` or any running scheduler, and streams the rows to
a resumable Parquet table (:mod:`rescon.sweep.run`). Dask, pandas and pyarrow are
imported when a sweep runs (``pip install rescon[dask]``)."""

from .run import sweep

__all__ = ["sweep"]
