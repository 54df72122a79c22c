"""rescon.geometry: exact safe kernels Ψ(X, F), their points, emptiness certificates and
Tverberg partitions (public entry points are re-exported by :mod:`rescon`)."""

from .._numba_cache import ensure_numba_cache

ensure_numba_cache()  # before any module of this package imports numba
