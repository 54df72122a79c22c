"""Hostile review of the checker's adjacency / normal-fan path (issue 13 §4): forged
safe-kernel certificates must never be valid, rescon's own must never be invalid.

The forgeries are built here in exact rationals, independently of rescon; the truth of
a claim "v ∈ Ψ(X, F)" is decided by brute force (Carathéodory + hitting sets)."""

from __future__ import annotations

from fractions import Fraction

from rescon_certificates.check import check


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _sub(a, b):
    return [x - y for x, y in zip(a, b)]


def _dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def _mat(A, x):
    return [_dot(row, x) for row in A]


def _forged_pyramid(F: int, A: list[list[int]]) -> dict:
    """P = the pyramid over an octagon with apex v = (0, 0, 1), mapped by x -> A x.

    Each base corner is a data point F + 1 times (depth >= F + 1) and F points sit just
    outside the middle of each side facet: every facet has <= F points strictly outside,
    but nothing lies above v, so the halfspace {z >= 1} holds no point: v has depth 0 and
    the claim Ψ = P is false.  A is chosen so that the axis depth test does not see it."""
    base = [(3, 0), (2, 2), (0, 3), (-2, 2), (-3, 0), (-2, -2), (0, -3), (2, -2)]
    B = [[Fraction(x), Fraction(y), Fraction(0)] for x, y in base]
    v = [Fraction(0), Fraction(0), Fraction(1)]
    m = len(B)
    facets = [([0, 0, -1], 0)]
    points = [b for b in B for _ in range(F + 1)]
    for k in range(m):
        b1, b2 = B[k], B[(k + 1) % m]
        a = _cross(_sub(b1, v), _sub(b2, v))
        if a[2] < 0:
            a = [-t for t in a]
        facets.append((a, _dot(a, v)))
        centre = [(x + y + z) / 3 for x, y, z in zip(b1, b2, v)]
        points += [[c + t / 50 for c, t in zip(centre, a)]] * F
    V = B + [v]
    adj = [[(k - 1) % m, (k + 1) % m, m] for k in range(m)] + [list(range(m))]
    # x -> A x maps a·x <= b to (a A^-1)·x <= b; with the adjugate: (a adj(A))·x <= b det(A)
    cols = [[row[j] for row in A] for j in range(3)]
    adjA = [_cross(cols[(i + 1) % 3], cols[(i + 2) % 3]) for i in range(3)]  # rows of adj(A)
    det = _dot(cols[0], _cross(cols[1], cols[2]))
    s = 1 if det > 0 else -1

    def q(t):
        return str(Fraction(t))

    return {"rescon_certificate": 1, "kind": "safe_kernel", "F": F, "dim": 3,
            "points": [[q(t) for t in _mat(A, p)] for p in points],
            "vertices": [[q(t) for t in _mat(A, x)] for x in V],
            "equalities": [],
            "facets": [{"a": [q(s * t) for t in [_dot(a, [adjA[i][j] for i in range(3)])
                                                 for j in range(3)]],
                        "b": q(s * b * det)} for a, b in facets],
            "adjacency": adj, "proof": {"method": "halfspaces"}}


def test_zero_facet_does_not_blind_the_normal_fan():
    """A facet 0·x <= 0 (valid, tight everywhere) listed first made the d = 3 normal fan
    sweep a degenerate arc (both ends the zero vector) and call the depth-0 apex of this
    pyramid a kernel vertex: the false certificate was 'valid'."""
    for F, A in ((1, [[2, 0, -2], [0, -2, -2], [0, 1, -2]]),
                 (2, [[-3, 2, 3], [-2, -2, -2], [3, 1, 0]])):
        cert = _forged_pyramid(F, A)
        res = check(cert)
        assert res.verdict == "invalid" and "Tukey depth is at most 0" in res.reason, res.reason
        cert["facets"].insert(0, {"a": [0, 0, 0], "b": 0})
        res = check(cert)
        assert res.verdict == "invalid" and "Tukey depth is at most 0" in res.reason, res.reason
