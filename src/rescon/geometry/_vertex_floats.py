"""Correctly rounded floats of the fast path's vertices, proven without the exact solve.

For a proposal of k rows h with exact integer rows a_h·x = b_h (x in scaled integer
coordinates; the public floats are z = x / scale, scale a power of two), the rows are
divided by 2^{t_h} (t_h: the bit length of the row's largest |entry|), so the system
is A z = b' with A_{hj} = a_{hj} / 2^{t_h}, b'_h = b_h / (scale · 2^{t_h}), |A| ≤ 1.
Floats: Af = fl(A) (each entry int / int, correctly rounded, |A − Af| ≤ u|Af|, u =
2^-53, in the normal range checked below), R ≈ Af⁻¹ and z0 ≈ Af⁻¹ fl(b'). Then:

1. The residual r = b' − A z0 in doubled precision, with a rigorous bound ρ ≥
   |r − rf|: A = Ahi + Alo and b' = bhi + blo (+ their roundings; ah + al = Ahi,
   Veltkamp's split), Ahi_j z0_j = p_j + e_j exactly (Dekker's product on the splits,
   exact as no partial product leaves the normal range), q_j = fl(Alo_j z0_j); the
   n = 3k + 2 terms bhi, blo, −p_j (j = 0..k−1), −e_j, −q_j, in that order, summed by
   Sum2 into rf (Ogita, Rump and Oishi 2005: a cascade of TwoSums, |res − s| ≤ u|s| +
   γ_{n−1}² Σ|terms| — additions err only relatively, as an addition whose result is
   subnormal is exact). With T = Σ|terms| and Q = |blo| + Σ_j |q_j| (as computed) the
   total error is |r − rf| ≤ (1 + 2u)(u|rf| + γ_{n−1}² (1 + γ_n) T +
   2u(1 + 2u)(1 + γ_n) Q) (the roundings of A and b', |ΔA| ≤ u|Alo|(1 + 2u), and of
   the q_j added) ≤ ρ = (2u|rf| + 2n²u² T + 3u Q)(1 + 4(k + 4)u). All scaled by 2^σ
   (σ per proposal, so that max |2^σ rf| ∈ [1/2, 1); ρ evaluated on rs, 2^σ T and
   2^σ Q): rs = 2^σ rf, ρ_s = 2^σ ρ, |2^σ r − rs| ≤ ρ_s.
2. β_i ≥ Σ_j |I − R A|_{ij}: |I − RA| ≤ |I − C| + |C − R Af| + |R| |A − Af| with
   C = fl(R Af), |C − R Af| ≤ γ_k |R||Af| (γ_k = ku / (1 − ku); any summation order,
   with or without fused multiply-adds), so, with sD = fl(row sums of fl|I − C|) and
   sN = fl(row sums of fl(|R| |Af|)), β_i ≤ (1 + (k+3)u)(sD_i + (k+2)u sN_i) (k ≤ 10:
   each computed nonnegative sum of m terms is ≥ (1 − γ_m) times its value, and
   |x| ≤ (1 + 2u)|fl(x)| for the subtraction); evaluated with the constants 2(k+2)u
   and 2(k+8)u, which also cover the rounding of that evaluation. β = max_i β_i ≤ 1/2
   is required: then RA is invertible, hence A, and e = z − z0 = A⁻¹ r.
3. With e_s = 2^σ e: e_s = R r_s + (I − RA) e_s (r_s = 2^σ r), so ‖e_s‖∞ ≤
   ‖|R||r_s|‖∞ / (1 − β) ≤ 2 ‖|R|(|rs| + ρ_s)‖∞ and, δ_s = fl(R rs),
   |e_s − δ_s|_i ≤ β_i ‖e_s‖∞ + (|R| ρ_s)_i + γ_k (|R||rs|)_i
   ≤ 2.5 β max(G + H) + 2 H_i + 2(k+2)u G_i with G = fl(|R| |rs|), H = fl(|R| ρ_s)
   (the true products are ≤ (1 + (k+1)u) times these); evaluated in floats and
   multiplied by 1 + 8u (four roundings) — the bound E_s,i —
   then E_i = E_s,i / 2^σ and δ = δ_s / 2^σ (exact: see the range checks).
4. f = fl(z0 + δ) and t = z0 + δ − f exactly (TwoSum: exact in binary floating point,
   whatever the magnitudes), so |z − f| ≤ E + |t|. If (E + |t|)(1 + 4u) (covering the
   two roundings of that evaluation) is **strictly** below half the distance from f to
   each neighbouring float (exact for normal f: a power of two), f is the float
   nearest to z and no other float is as near — the correctly rounded z whatever the
   tie rule, i.e. what y / (w · scale) (Python's int / int) gives for the exact vertex.

Range checks (else the proposal is left to the exact solve): every entry of Af, its
lo parts, R, z0, δ_s and rs is 0 or of magnitude in [2^-400, 2^400] (a product with a
factor 0 is an exact 0), every |f| in [2^-400, 2^400], |σ| ≤ 400, bound terms floored at 2^-300
(inflating a bound keeps it one) and E_s ≤ 2^300. Then every product of two factors
lies in [2^-800, 2^800]: no overflow and no underflow anywhere (sums of normal numbers
that fall below the normal range are exact), so the relative bounds above hold;
δ_s / 2^σ and E_s / 2^σ are exact (normal, ≥ 2^-900). The doubled-precision residual
also needs its rows' lo parts 0 or normal with an exact or normal remainder, and
2^σ T, 2^σ Q (step 1) 0 or in [2^-400, 2^400]. Anything non-finite fails
every comparison (NaN) or the range checks (inf): not certified.

The proofs run compiled, a proposal at a time (:func:`_rounded_nb`, the float
operations of each step in the order stated above, without fastmath: no fused
multiply-adds, no reassociation); the approximate inverse R, which the proof does not
trust, is its own Gauss–Jordan elimination. The tests keep a numpy statement of the
same steps, all proposals at once (tests/vertex_floats_reference.py), as their oracle
and as the proof they weaken to show the oracle catches it.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from .._rounding import UNIT_ROUNDOFF as _U

__all__ = ["rounded_points"]

#: factors of every product below lie in [2^-LIMIT, 2^LIMIT] (module docstring)
LIMIT = 400
#: the floor of the bound terms (β_i, E_s)
FLOOR = 2.0**-300
#: from this many proposals on, ranges of them (THREAD_CHUNKS) are proven on threads
#: (:func:`._candidates.on_threads`; :func:`_rounded_nb` runs without the GIL)
THREADS_MIN = 2000
THREAD_CHUNKS = 4

_bit_length = np.frompyfunc(int.bit_length, 1, 1)


def _in_range(x: np.ndarray, zero_ok: bool) -> np.ndarray:
    """Per leading index, whether every entry of x has |x| in [2^-LIMIT, 2^LIMIT]
    (or is 0, with ``zero_ok``); NaN fails."""
    a = np.abs(x)
    ok = (a >= 2.0**-LIMIT) & (a <= 2.0**LIMIT)
    if zero_ok:
        ok |= a == 0.0
    return ok.reshape(len(x), -1).all(axis=1)


def rounded_points(E: np.ndarray, at: np.ndarray, scale: int, k: int,
                   slack: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """For each proposal p (``at[p]``: its k rows, positions in E, the object array of
    homogeneous integer rows (−b_h, a_h)), the floats fl(z) of the point z = x / scale
    where its rows meet, and whether they are proven correctly rounded (module
    docstring); entries not proven are NaN. ``slack`` multiplies the bound E (1: the
    proven bound; tests pass < 1 to show a weakened bound is caught). The proofs run
    compiled (:func:`_rounded_nb`), from THREADS_MIN proposals on in THREAD_CHUNKS
    ranges on threads."""
    from ._candidates import on_threads  # looked up per call: tests replace it

    P = len(at)
    out = np.full((P, k), np.nan)
    ok = np.zeros(P, dtype=np.bool_)
    if not P or scale <= 0 or scale & (scale - 1):
        return out, ok
    with np.errstate(all="ignore"):
        Ahi, Alo, bhi, blo, _, split = map(np.ascontiguousarray, _row_floats(E, scale, k))
        ah, al = _split(Ahi)
        split = split & _in_range(Ahi, True) & _in_range(Alo, True)
    at = np.ascontiguousarray(at, dtype=np.int64)

    def scan(lo: int, hi: int) -> None:
        _rounded_nb(Ahi, Alo, bhi, blo, split, ah, al, at[lo:hi], k, slack, out[lo:hi],
                    ok[lo:hi])

    on_threads(scan, P, THREAD_CHUNKS if P >= THREADS_MIN else 1)
    return out, ok


@njit(cache=True, nogil=True, inline="always")
def _inr(x, zero_ok):
    """|x| in [2^-LIMIT, 2^LIMIT], or x = 0 with ``zero_ok`` (:func:`_in_range` for one
    float); NaN fails."""
    a = abs(x)
    return (a >= 2.0**-LIMIT and a <= 2.0**LIMIT) or (zero_ok and a == 0.0)


@njit(cache=True, nogil=True)
def _invert(Af, R, M):
    """R ≈ Af⁻¹ (k × k) by Gauss–Jordan elimination with partial pivoting on a copy M;
    False where a pivot is exactly 0. Only a guess: β checks it (the tests' numpy
    reference takes LAPACK's inverse, which it need not equal)."""
    k = Af.shape[0]
    for i in range(k):
        for j in range(k):
            M[i, j] = Af[i, j]
            R[i, j] = 1.0 if i == j else 0.0
    for c in range(k):
        piv = c
        big = abs(M[c, c])
        for i in range(c + 1, k):
            if abs(M[i, c]) > big:
                piv, big = i, abs(M[i, c])
        if not big > 0.0:  # 0 or NaN
            return False
        if piv != c:
            for j in range(k):
                M[c, j], M[piv, j] = M[piv, j], M[c, j]
                R[c, j], R[piv, j] = R[piv, j], R[c, j]
        inv = 1.0 / M[c, c]
        for j in range(k):
            M[c, j] *= inv
            R[c, j] *= inv
        for i in range(k):
            f = M[i, c]
            if i != c and f != 0.0:
                for j in range(k):
                    M[i, j] -= f * M[c, j]
                    R[i, j] -= f * R[c, j]
    return True


@njit(cache=True, nogil=True)
def _rounded_nb(Ahi, Alo, bhi, blo, split, ah, al, at, k, slack, out, ok):
    """The proof of the module docstring, compiled, one proposal at a time: its steps
    and bounds, each float operation in the order the steps state it (the order the
    tests' numpy reference performs them in, all proposals at once) — numba compiles
    without fastmath, so no contraction into fused multiply-adds and no reassociation:
    TwoSum, Veltkamp's split, Dekker's product and Sum2 stay error-free
    transformations — and where the steps leave the order open (the matrix products
    and row sums, the bounds of which hold for any order and with or without fused
    multiply-adds) a plain loop. R comes from :func:`_invert`, not LAPACK (the
    reference's): R is only a guess (any R with β ≤ 1/2 gives a proof), so
    a proposal may be proven here and not there or conversely, never with another
    float (correct rounding is a function of the point). ``split``: per row, split
    and its hi and lo parts in range; ``ah``, ``al``: the split of Ahi, (rows, k)."""
    n = 3 * k + 2
    c_rho = 2.0 * n * n * _U * _U
    grow = 1.0 + 4.0 * (k + 4) * _U
    c_sum = 2.0 * (k + 2) * _U
    c_beta = 1.0 + 2.0 * (k + 8) * _U
    Af = np.empty((k, k))
    R = np.empty((k, k))
    M = np.empty((k, k))
    z0 = np.empty(k)
    rf = np.empty(k)
    T = np.empty(k)
    Q = np.empty(k)
    rs = np.empty(k)
    rho = np.empty(k)
    G = np.empty(k)
    Hr = np.empty(k)
    for p in range(len(at)):
        good = True
        for i in range(k):
            good = good and split[at[p, i]]
        if not good:
            continue
        for i in range(k):
            for j in range(k):
                Af[i, j] = Ahi[at[p, i], j]
        if not _invert(Af, R, M):
            continue
        for i in range(k):
            s = 0.0
            for j in range(k):
                h = at[p, j]
                s += R[i, j] * (bhi[h] + blo[h])
            z0[i] = s
            good = good and _inr(s, True)
            for j in range(k):
                good = good and _inr(R[i, j], True)
        if not good:
            continue
        # 1. the residual (step 1, term by term in its Sum2 order), scaled by 2^σ
        for i in range(k):
            h = at[p, i]
            s = bhi[h]
            err = 0.0
            x = blo[h]  # the terms: blo, −p_j, −e_j, −q_j (j = 0..k−1), by Sum2
            s1 = s + x
            bb = s1 - s
            err = err + ((s - (s1 - bb)) + (x - bb))
            s = s1
            tp = 0.0
            tq = 0.0
            for part in range(3):
                for j in range(k):
                    pj = Ahi[h, j] * z0[j]
                    if part == 0:
                        x = -pj
                    elif part == 1:
                        c = 134217729.0 * z0[j]
                        zh = c - (c - z0[j])
                        zl = z0[j] - zh
                        x = -((((ah[h, j] * zh - pj) + ah[h, j] * zl) + al[h, j] * zh)
                              + al[h, j] * zl)
                        # T's term j: |p_j| + |e_j| + |q_j|, summed over j in turn
                        tp += (abs(pj) + abs(x)) + abs(Alo[h, j] * z0[j])
                    else:
                        x = -(Alo[h, j] * z0[j])
                        tq += abs(x)
                    s1 = s + x
                    bb = s1 - s
                    err = err + ((s - (s1 - bb)) + (x - bb))
                    s = s1
            rf[i] = s + err
            T[i] = (abs(bhi[h]) + abs(blo[h])) + tp
            Q[i] = abs(blo[h]) + tq
        top = 0.0
        for i in range(k):
            if abs(rf[i]) > top or rf[i] != rf[i]:
                top = abs(rf[i])
        sigma = -math.frexp(top)[1] if top > 0.0 else 0
        good = abs(sigma) <= LIMIT
        for i in range(k):
            rs[i] = math.ldexp(rf[i], sigma)
            ts = math.ldexp(T[i], sigma)
            qs = math.ldexp(Q[i], sigma)
            good = good and _inr(rs[i], True) and _inr(ts, True) and _inr(qs, True)
            rho[i] = (2.0 * _U * abs(rs[i]) + c_rho * ts + 3.0 * _U * qs) * grow
        if not good:
            continue
        # 2. β: the row sums of |I − R Af|, bounded
        beta = 0.0
        for i in range(k):
            sD = 0.0
            sN = 0.0
            for j in range(k):
                cij = 0.0
                nij = 0.0
                for m in range(k):
                    cij += R[i, m] * Af[m, j]
                    nij += abs(R[i, m]) * abs(Af[m, j])
                sD += abs((1.0 if i == j else 0.0) - cij)
                sN += nij
            b = (sD + c_sum * sN) * c_beta
            if b < FLOOR:
                b = FLOOR
            if not b <= 0.5:  # NaN too
                good = False
            elif b > beta:
                beta = b
        if not good:
            continue
        # 3. the correction and its bound, in units 2^-σ
        gh = 0.0
        for i in range(k):
            g = 0.0
            hr = 0.0
            for j in range(k):
                g += abs(R[i, j]) * abs(rs[j])
                hr += abs(R[i, j]) * rho[j]
            G[i] = g
            Hr[i] = hr
            if g + hr > gh or g + hr != g + hr:
                gh = g + hr
        for i in range(k):
            ds = 0.0
            for j in range(k):
                ds += R[i, j] * rs[j]
            es = 2.5 * beta * gh + 2.0 * Hr[i] + c_sum * G[i]
            if es < FLOOR:
                es = FLOOR
            es = es * (1.0 + 8.0 * _U) * slack
            if not (_inr(ds, True) and es <= 2.0**300):
                good = False
                break
            # 4. f = fl(z0 + δ), t = z0 + δ − f (TwoSum), against the half gaps at f
            delta = math.ldexp(ds, -sigma)
            eb = math.ldexp(es, -sigma)
            f = z0[i] + delta
            bb = f - z0[i]
            tw = (z0[i] - (f - bb)) + (delta - bb)
            gap = min(f - np.nextafter(f, -np.inf), np.nextafter(f, np.inf) - f) * 0.5
            if not (_inr(f, False) and (eb + abs(tw)) * (1.0 + 4.0 * _U) < gap):
                good = False
                break
            rf[i] = f
        if good:
            for i in range(k):
                out[p, i] = rf[i]
            ok[p] = True


def _row_floats(E: np.ndarray, scale: int, k: int):
    """Per row (−b, a) of E (the last, the row at infinity, left out): t (the bit
    length of its largest |entry|), A = a / 2^t and b' = b / (scale 2^t) as unevaluated
    sums hi + lo — hi = fl(v) / 2^e, lo = fl(v − fl(v)) / 2^e for each integer entry v
    (e = t, or s + t for b, scale = 2^s; float(int) is correctly rounded) — so hi is
    the correctly rounded entry and |entry − hi − lo| ≤ u |lo| when each is normal or
    0 for a zero integer / remainder (``split`` False for a row where one is not: the
    division by 2^e is then not exact, e.g. flushed to 0)."""
    rows = E[:-1]
    t = np.array([max(map(abs, row)).bit_length() for row in rows.tolist()],
                 dtype=np.int64)
    try:
        hi = rows.astype(np.float64)
    except OverflowError:  # an entry beyond the float range: row by row
        return _row_floats_slow(rows, t, scale, k)
    lo = _remainder(rows).astype(np.float64)
    e = np.repeat(-t[:, None], k + 1, axis=1)
    e[:, 0] -= scale.bit_length() - 1
    tiny = 2.0**-1000
    # 0 only for a zero entry / remainder (float(v) = 0 iff v = 0): a nonzero one
    # scaled below the normal range (flushed to 0 or subnormal) is not split
    ok_hi, ok_lo = hi == 0.0, lo == 0.0
    hi, lo = np.ldexp(hi, e), np.ldexp(lo, e)
    split = (ok_hi | (np.abs(hi) >= tiny)) & (ok_lo | (np.abs(lo) >= tiny))
    return hi[:, 1:], lo[:, 1:], -hi[:, 0], -lo[:, 0], t, split.all(axis=1)


#: v − fl(v) rounded, for a Python int v (|v| < 2^1024)
_remainder = np.frompyfunc(lambda v: float(v - int(float(v))), 1, 1)


def _row_floats_slow(rows: np.ndarray, t: np.ndarray, scale: int, k: int):
    """:func:`_row_floats` for rows with entries beyond the float range: int / int."""
    Ahi, Alo, bhi, blo, split = [], [], [], [], []
    tiny = 2.0**-1000
    for row, th in zip(rows.tolist(), t.tolist(), strict=True):
        good = True
        pairs = []
        for j, v in enumerate(row):
            den = (scale << th) if j == 0 else (1 << th)
            num = -v if j == 0 else v
            hi = num / den
            n, d = hi.as_integer_ratio()
            rem = num * d - n * den
            lo = rem / (den * d) if rem else 0.0
            if (num and not abs(hi) >= tiny) or (rem and not abs(lo) >= tiny):
                good = False
            pairs.append((hi, lo))
        bhi.append(pairs[0][0])
        blo.append(pairs[0][1])
        Ahi.append([p[0] for p in pairs[1:]])
        Alo.append([p[1] for p in pairs[1:]])
        split.append(good)
    return (np.array(Ahi, dtype=np.float64).reshape(-1, k),
            np.array(Alo, dtype=np.float64).reshape(-1, k), np.array(bhi, dtype=np.float64),
            np.array(blo, dtype=np.float64), t, np.array(split, dtype=np.bool_))


def _split(a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Veltkamp's split a = ah + al exactly, each half of at most 26 significant bits
    (|a| < 2^995, no underflow: the callers' range checks)."""
    c = 134217729.0 * a
    ah = c - (c - a)
    return ah, a - ah
