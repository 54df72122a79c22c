"""Graph robustness: bounds, exact search, MILP, generators, Sarymsakov and attack-model checks."""

from .._numba_cache import ensure_numba_cache

ensure_numba_cache()  # before any module of this package imports numba
