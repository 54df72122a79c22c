"""The numpy statement of the proof in :mod:`rescon.geometry._vertex_floats`'s docstring
(the vertices' correctly rounded floats without the exact solve), all proposals at
once: the compiled kernel ``_rounded_nb`` mirrors it step by step. It is no part of the
library; it is kept here as the tests' oracle (they compare the kernel's floats and
verdicts with it) and as their mutation target (they weaken one of its steps — its
``np``, its :func:`_two_sum`, a line of :func:`_rounded`'s source — and show the exact
oracle catches the weakened proof). The shared pieces (the rows' floats, Veltkamp's
split, the range checks, the constants) are the library's own."""

from __future__ import annotations

import numpy as np

from rescon._rounding import UNIT_ROUNDOFF as _U
from rescon.geometry._vertex_floats import FLOOR, LIMIT, _in_range, _row_floats, _split


def rounded_points(E: np.ndarray, at: np.ndarray, scale: int, k: int,
                   slack: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """:func:`rescon.geometry._vertex_floats.rounded_points` by this reference: the
    same inputs, the floats and whether they are proven (NaN where not)."""
    P = len(at)
    out = np.full((P, k), np.nan)
    ok = np.zeros(P, dtype=np.bool_)
    if not P or scale <= 0 or scale & (scale - 1):
        return out, ok
    with np.errstate(all="ignore"):
        rows = _row_floats(E, scale, k)
        _rounded(rows, *_split(rows[0].T), np.asarray(at, dtype=np.int64), k, slack, out,
                 ok)
    return out, ok


def _rounded(rows: tuple, ah: np.ndarray, al: np.ndarray, at: np.ndarray, k: int,
             slack: float, out: np.ndarray, ok: np.ndarray) -> None:
    """rounded_points for the proposals ``at``, writing into ``out`` and ``ok``
    (views): ``rows`` from ``_row_floats``, (ah, al) the split of its Ahi's columns —
    in numpy, all proposals at once: the reference of the compiled ``_rounded_nb``
    (tests compare them, and weaken a step of this one to show the oracle catches
    it)."""
    Ahi, Alo, bhi, blo, _, split = rows
    split = split & _in_range(Ahi, True) & _in_range(Alo, True)
    Af = Ahi[at]  # (P, k, k)
    R = _inverses(Af)
    z0 = (R @ (bhi[at] + blo[at])[:, :, None])[:, :, 0]
    good = split[at].all(axis=1) & _in_range(R, True) & _in_range(z0, True)
    if not good.any():
        return
    idx = np.flatnonzero(good)
    Af, R, z0, at = Af[idx], R[idx], z0[idx], at[idx]
    # 1. the residual with its error bound, scaled by 2^σ
    rf, T, Q = _residual(Ahi.T[:, at], ah[:, at], al[:, at], Alo.T[:, at], bhi[at],
                         blo[at], z0)
    top = np.abs(rf).max(axis=1)
    sigma = np.where(top > 0.0, -np.frexp(top)[1], 0).astype(np.int64)
    rs = np.ldexp(rf, sigma[:, None])
    Ts, Qs = np.ldexp(T, sigma[:, None]), np.ldexp(Q, sigma[:, None])
    n = 3 * k + 2
    rho = (2.0 * _U * np.abs(rs) + 2.0 * n * n * _U * _U * Ts + 3.0 * _U * Qs) * (
        1.0 + 4.0 * (k + 4) * _U)
    good = ((np.abs(sigma) <= LIMIT) & _in_range(rs, True) & _in_range(Ts, True)
            & _in_range(Qs, True))
    # 2. β: the row sums of |I − RA|, bounded
    C = R @ Af
    D = np.abs(np.eye(k) - C)
    absR = np.abs(R)
    sN = (absR @ np.abs(Af)).sum(axis=2)
    beta = (D.sum(axis=2) + 2.0 * (k + 2) * _U * sN) * (1.0 + 2.0 * (k + 8) * _U)
    beta = np.maximum(beta, FLOOR).max(axis=1)
    good &= beta <= 0.5
    # 3. the correction and its bound, in units 2^-σ
    ds = (R @ rs[:, :, None])[:, :, 0]
    G = (absR @ np.abs(rs)[:, :, None])[:, :, 0]
    Hr = (absR @ rho[:, :, None])[:, :, 0]
    Es = (2.5 * beta * (G + Hr).max(axis=1))[:, None] + 2.0 * Hr + 2.0 * (k + 2) * _U * G
    Es = np.maximum(Es, FLOOR) * (1.0 + 8.0 * _U) * slack
    good &= _in_range(ds, True) & (Es <= 2.0**300).all(axis=1)
    sig = np.where(good, sigma, 0)[:, None]
    delta = np.ldexp(ds, -sig)
    Eb = np.ldexp(Es, -sig)
    # 4. f = fl(z0 + δ), t = z0 + δ − f (TwoSum), and the half gaps around f
    f, tw = _two_sum(z0, delta)
    gap = np.minimum(f - np.nextafter(f, -np.inf), np.nextafter(f, np.inf) - f) * 0.5
    good &= _in_range(f, False) & ((Eb + np.abs(tw)) * (1.0 + 4.0 * _U) < gap).all(axis=1)
    out[idx[good]] = f[good]
    ok[idx[good]] = True


def _two_sum(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """s = fl(a + b) and the exact error a + b − s (Knuth's TwoSum: exact in binary
    floating point with rounding to nearest, barring overflow)."""
    s = a + b
    bb = s - a
    return s, (a - (s - bb)) + (b - bb)


def _residual(Ahi: np.ndarray, ah: np.ndarray, al: np.ndarray, Alo: np.ndarray,
              bhi: np.ndarray, blo: np.ndarray, z0: np.ndarray
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """rf ≈ r = b' − A z0 for A = Ahi + Alo (+ its rounding; ah + al = Ahi, its split;
    these four as (column, proposal, row) arrays),
    b' = bhi + blo (+ its rounding): the n = 3k + 2 terms bhi, blo, −p_j, −e_j
    (Ahi_j z0_j = p_j + e_j exactly: Dekker's product on the splits, exact as no
    partial product leaves the normal range) and −q_j = −fl(Alo_j z0_j), summed by
    Sum2 (Ogita, Rump and Oishi 2005: a cascade of TwoSums, |res − s| ≤ u|s| +
    γ_{n−1}² Σ|terms| — additions err only relatively, as an addition whose result is
    subnormal is exact). With T = Σ|terms| and Q = |blo| + Σ_j |q_j| (as computed) the
    total error is |r − rf| ≤ (1 + 2u)(u|rf| + γ_{n−1}² (1 + γ_n) T + 2u(1 + 2u)(1 + γ_n) Q)
    (the roundings of A and b', |ΔA| ≤ u|Alo|(1 + 2u), and of the q_j added), which
    :func:`_rounded` bounds by ρ = (2u|rf| + 2n²u² T + 3u Q)(1 + 4(k + 4)u)."""
    z = z0.T[:, :, None]  # the arrays are (column j, proposal, row h)
    p = Ahi * z
    zh, zl = _split(z)
    e = ((ah * zh - p) + ah * zl + al * zh) + al * zl
    q = Alo * z
    s = bhi
    err = np.zeros_like(s)
    for x in (blo, *(-p), *(-e), *(-q)):
        s, d = _two_sum(s, x)
        err = err + d
    aq = np.abs(q)
    T = np.abs(bhi) + np.abs(blo) + (np.abs(p) + np.abs(e) + aq).sum(axis=0)
    Q = np.abs(blo) + aq.sum(axis=0)
    return s + err, T, Q


def _inverses(Af: np.ndarray) -> np.ndarray:
    """Approximate inverses of the (P, k, k) float matrices (NaN where numpy finds one
    singular): only a guess, which the bound β of :func:`_rounded` checks.

    numpy inverts a stack matrix by matrix but raises for the whole stack when one is
    exactly singular in its LU factorisation (common on degenerate clouds: the k rows
    a proposal chose are dependent) — those, found by the same factorisation
    (det = 0; a determinant that underflows to 0 only leaves its proposal unproven),
    are swapped for the identity and their inverses set to NaN, so the others are
    inverted in one call (one matrix at a time, 28 k calls, took 0.3 s on
    cube(5, 30, 3))."""
    with np.errstate(all="ignore"):
        try:
            return np.linalg.inv(Af)
        except np.linalg.LinAlgError:
            pass
        singular = np.linalg.det(Af) == 0.0
        try:
            R = np.linalg.inv(np.where(singular[:, None, None], np.eye(Af.shape[1]), Af))
            R[singular] = np.nan
            return R
        except np.linalg.LinAlgError:
            pass
        R = np.full(Af.shape, np.nan)
        for p in range(len(Af)):
            try:
                R[p] = np.linalg.inv(Af[p])
            except np.linalg.LinAlgError:
                pass
        return R
