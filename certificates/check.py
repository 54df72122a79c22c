#!/usr/bin/env python3
"""Standalone checker for rescon certificates (format version 1, see FORMAT.md).

This file is the trusted part of rescon: it uses the Python standard library only,
never imports rescon, numpy or networkx, and re-derives every claim it can in exact
integer arithmetic.  Node sets are Python-int bitmasks (bit i = node i).

Usage::

    python certificates/check.py CERT.json
        exit 0  valid        every part verified (prints "valid")
        exit 1  invalid      a part is refuted or malformed ("invalid: <reason>" on stderr)
        exit 2  unreadable   ("unreadable: <reason>" on stderr)
        exit 3  unchecked    well-formed and nothing refuted, but some part was taken on
                             trust or exceeds the checker's limits (prints "unchecked" and
                             one "not checked: <part>" line per part)

API: ``check(cert) -> CheckResult(valid, reason, trusted, unchecked)`` (``.verdict`` is
"valid", "invalid" or "unchecked") and ``main(argv) -> int``.

JSON arrays may also be given as Python tuples when ``check`` is called directly.
"""

from __future__ import annotations

import itertools
import json
import math
import sys
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

__all__ = [
    "EXIT_CODES",
    "FORMAT_VERSION",
    "MAX_ENUM_N",
    "MAX_N",
    "VERDICTS",
    "CheckResult",
    "check",
    "load",
    "main",
]

FORMAT_VERSION = 1
MAX_ENUM_N = 20  # largest n the checker enumerates itself ("enumeration", "dp")
MAX_N = 1_000_000  # resource limit on graph / matrix size
MAX_GRAPH_WORK = 20_000_000  # (n + #edges) * ceil(n / 1024): reading a graph or support
MAX_SEARCH_WORK = 25_000_000  # steps replaying a search tree (_Replay; ~5 s)
ROW_SUMS = 1 << 16  # row sums a replay keeps (_Replay.row_sum)


VERDICTS = ("valid", "invalid", "unchecked")
EXIT_CODES = {"valid": 0, "invalid": 1, "unchecked": 3}  # 2: unreadable


@dataclass(frozen=True)
class CheckResult:
    """Outcome of :func:`check`: one of three verdicts (``.verdict``).

    * ``"valid"`` (``valid`` True, exit 0): every part of the certificate was verified
      in exact arithmetic; ``trusted`` and ``unchecked`` are empty.
    * ``"invalid"`` (exit 1): a part is malformed or refuted; ``reason`` says which.
    * ``"unchecked"`` (exit 3): well-formed and nothing refuted, but some part was taken
      on trust (e.g. a ``milp`` proof on n > 20 nodes) or exceeds the checker's limits
      (size, work, bit size). ``unchecked`` names those parts and ``trusted`` their
      short names (proof methods such as ``"milp"``, or limits such as
      ``"vertex enumeration"``). Never reported as valid, never as invalid.

    ``valid`` is True only for the first verdict, so ``bool(result)`` means "proved".
    ``reason``: what was proved (valid), why not (invalid), or what was shown apart
    from the unchecked parts.
    """

    valid: bool
    reason: str
    trusted: tuple[str, ...] = ()
    unchecked: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.valid and (self.trusted or self.unchecked):
            raise ValueError("a valid CheckResult has no trusted or unchecked parts")

    @property
    def verdict(self) -> str:
        """"valid", "invalid" or "unchecked" (see the class docstring)."""
        if self.valid:
            return "valid"
        return "unchecked" if self.unchecked else "invalid"

    def __bool__(self) -> bool:
        return self.valid


class Invalid(Exception):
    """Raised internally with the reason a certificate is invalid."""


class Unchecked(Exception):
    """Raised internally when a part that the rest depends on exceeds the checker's
    limits: ``Unchecked(name, part)``; the verdict is "unchecked", never "invalid"."""

    def __init__(self, name: str, part: str) -> None:
        super().__init__(part)
        self.name = name
        self.part = part


class _Ctx:
    """Per-check state: the parts not verified (taken on trust or beyond a limit)."""

    def __init__(self) -> None:
        self.trusted: list[str] = []
        self.unchecked: list[str] = []

    def trust(self, name: str, part: str) -> None:
        """Record that ``part`` was not verified; ``name`` is its short name."""
        if name not in self.trusted:
            self.trusted.append(name)
        if part not in self.unchecked:
            self.unchecked.append(part)


# --------------------------------------------------------------------------- #
# strict JSON-structure helpers
# --------------------------------------------------------------------------- #

_ARRAY = (list, tuple)


def _obj(x: Any, where: str, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> dict:
    if not isinstance(x, dict):
        raise Invalid(f"{where} must be a JSON object, got {_tname(x)}")
    for k in x:
        if not isinstance(k, str):
            raise Invalid(f"{where} has a non-string key {k!r}")
    for k in required:
        if k not in x:
            raise Invalid(f"{where}: missing key '{k}'")
    allowed = set(required) | set(optional)
    extra = sorted(k for k in x if k not in allowed)
    if extra:
        raise Invalid(f"{where}: unknown key '{extra[0]}'")
    return x


def _tname(x: Any) -> str:
    if x is None:
        return "null"
    if isinstance(x, bool):
        return "boolean"
    if isinstance(x, int):
        return "integer"
    if isinstance(x, float):
        return "number (not an integer)"
    if isinstance(x, str):
        return "string"
    if isinstance(x, _ARRAY):
        return "array"
    if isinstance(x, dict):
        return "object"
    return type(x).__name__


def _is_int(x: Any) -> bool:
    return isinstance(x, int) and not isinstance(x, bool)


def _int(x: Any, where: str, lo: int | None = None, hi: int | None = None) -> int:
    if not _is_int(x):
        raise Invalid(f"{where} must be an integer, got {_tname(x)}")
    if lo is not None and x < lo:
        raise Invalid(f"{where} = {x} is out of range (must be >= {lo})")
    if hi is not None and x > hi:
        raise Invalid(f"{where} = {x} is out of range (must be <= {hi})")
    return int(x)


def _array(x: Any, where: str) -> list | tuple:
    if not isinstance(x, _ARRAY):
        raise Invalid(f"{where} must be an array, got {_tname(x)}")
    return x


def _node_set(x: Any, where: str, n: int, nonempty: bool = True) -> int:
    """A duplicate-free list of node indices -> bitmask."""
    _array(x, where)
    if nonempty and not x:
        raise Invalid(f"{where} is empty")
    mask = 0
    for k, v in enumerate(x):
        v = _int(v, f"{where}[{k}]", 0, n - 1)
        if mask >> v & 1:
            raise Invalid(f"{where} lists node {v} twice")
        mask |= 1 << v
    return mask


def _perm(x: Any, where: str, n: int) -> list[int]:
    _array(x, where)
    if len(x) != n:
        raise Invalid(f"{where} is not a permutation of 0..{n - 1}: it has {len(x)} entries")
    seen = 0
    for k, v in enumerate(x):
        v = _int(v, f"{where}[{k}]", 0, n - 1)
        if seen >> v & 1:
            raise Invalid(f"{where} is not a permutation of 0..{n - 1}: {v} appears twice")
        seen |= 1 << v
    return [int(v) for v in x]


def _fmt(mask: int) -> str:
    return "{" + ", ".join(str(i) for i in _bits(mask)) + "}"


def _bits(mask: int) -> list[int]:
    out = []
    while mask:
        low = mask & -mask
        out.append(low.bit_length() - 1)
        mask ^= low
    return out


def _store_key(q: int) -> bytes:
    """The key of the packed set q in a replay's row-sum store: its bytes. Python hashes
    an int as q mod 2^61 − 1, so packed sets differing in fields p and p + 61 would hash
    alike and a certificate could make every look-up probe the whole store; bytes hash
    with SipHash, salted per process."""
    return q.to_bytes((q.bit_length() + 7) // 8, "little")


# --------------------------------------------------------------------------- #
# graphs and the two set operations everything rests on
# --------------------------------------------------------------------------- #


class Graph:
    """Nodes 0..n-1; ``inmask[i]`` = bitmask of the in-neighbours N(i) of i."""

    __slots__ = ("_outmask", "inmask", "m", "n")

    def __init__(self, n: int, inmask: list[int], m: int) -> None:
        self.n = n
        self.inmask = inmask
        self.m = m  # number of edges
        self._outmask: list[int] | None = None

    def outmask(self) -> list[int]:
        """``outmask()[u]`` = bitmask of the out-neighbours of u (computed once)."""
        if self._outmask is None:
            out = [0] * self.n
            for v, mk in enumerate(self.inmask):
                for u in _bits(mk):
                    out[u] |= 1 << v
            self._outmask = out
        return self._outmask

    @property
    def full(self) -> int:
        return (1 << self.n) - 1

    def induced(self, nodes: list[int]) -> Graph:
        """Subgraph induced on ``nodes``, re-indexed so that ``nodes[j]`` becomes j."""
        pos = {v: j for j, v in enumerate(nodes)}
        inmask = []
        m = 0
        for v in nodes:
            mk = 0
            for u in _bits(self.inmask[v]):
                j = pos.get(u)
                if j is not None:
                    mk |= 1 << j
            inmask.append(mk)
            m += mk.bit_count()
        return Graph(len(nodes), inmask, m)


def _size(x: Any, where: str) -> int:
    """A graph / matrix size n >= 1; beyond MAX_N the certificate is not read (unchecked)."""
    n = _int(x, where, 1)
    if n > MAX_N:
        raise Unchecked("size limit", f"{where} = {n} exceeds the checker's limit of {MAX_N} "
                        "nodes: the certificate was not read further")
    return n


def _mask_work(n: int, entries: int, where: str) -> None:
    """Refuse (unchecked) a graph / support whose n + entries mask operations on n-bit
    masks (each reading one entry or one node; counted in operations on 1024-bit
    masks) exceed MAX_GRAPH_WORK: node sets are n-bit masks, so a large sparse graph
    costs n (n + m)."""
    work = (n + entries) * max(1, -(-n // 1024))
    if work > MAX_GRAPH_WORK:
        raise Unchecked("size limit", f"{where}: n = {n} with {entries} entries needs work "
                        f"{work} > {MAX_GRAPH_WORK} on n-bit node sets: the certificate "
                        "was not read further")


def _graph(x: Any, where: str = "graph") -> Graph:
    _obj(x, where, ("n", "edges"), ("nodes",))
    n = _size(x["n"], f"{where}.n")
    if isinstance(x["edges"], _ARRAY):
        _mask_work(n, len(x["edges"]), where)
    if "nodes" in x:
        labels = _array(x["nodes"], f"{where}.nodes")
        if len(labels) != n:
            raise Invalid(f"{where}.nodes has {len(labels)} labels, expected n = {n}")
        for k, lab in enumerate(labels):
            if not (isinstance(lab, str) or _is_int(lab)):
                raise Invalid(f"{where}.nodes[{k}] must be a string or an integer, "
                              f"got {_tname(lab)}")
    edges = _array(x["edges"], f"{where}.edges")
    inmask = [0] * n
    for k, e in enumerate(edges):
        w = f"{where}.edges[{k}]"
        _array(e, w)
        if len(e) != 2:
            raise Invalid(f"{w} must be a pair [u, v], got {len(e)} entries")
        u = _int(e[0], f"{w}[0]", 0, n - 1)
        v = _int(e[1], f"{w}[1]", 0, n - 1)
        if u == v:
            raise Invalid(f"{w} = [{u}, {v}] is a self-loop")
        if inmask[v] >> u & 1:
            raise Invalid(f"{w} = [{u}, {v}] is a duplicate edge")
        inmask[v] |= 1 << u
    return Graph(n, inmask, len(edges))


def reach(g: Graph, S: int, r: int) -> int:
    """reach_r(S) = {i in S : |N(i) \\ S| >= r}."""
    inmask = g.inmask
    out = 0
    m = S
    while m:
        low = m & -m
        if (inmask[low.bit_length() - 1] & ~S).bit_count() >= r:
            out |= low
        m ^= low
    return out


def _pair_failure(g: Graph, r: int, s: int, S1: int, S2: int) -> str | None:
    """None if the disjoint nonempty pair (S1, S2) violates (r, s); else why not."""
    R1 = reach(g, S1, r)
    R2 = reach(g, S2, r)
    if R1 == S1:
        return f"S1 is fully {r}-reachable (every node of S1 has >= {r} in-neighbours outside S1)"
    if R2 == S2:
        return f"S2 is fully {r}-reachable (every node of S2 has >= {r} in-neighbours outside S2)"
    c1, c2 = R1.bit_count(), R2.bit_count()
    if c1 + c2 >= s:
        return (f"|reach_{r}(S1)| + |reach_{r}(S2)| = {c1} + {c2} = {c1 + c2} >= s = {s} "
                f"(reach_{r}(S1) = {_fmt(R1)}, reach_{r}(S2) = {_fmt(R2)})")
    return None


def _witness_pair(x: dict, where: str, g: Graph, k1: str = "S1", k2: str = "S2") -> tuple[int, int]:
    S1 = _node_set(x[k1], f"{where}.{k1}", g.n)
    S2 = _node_set(x[k2], f"{where}.{k2}", g.n)
    common = S1 & S2
    if common:
        raise Invalid(f"{where}: {k1} and {k2} intersect at node {_bits(common)[0]}")
    return S1, S2


def _check_violation(g: Graph, r: int, s: int, S1: int, S2: int, where: str) -> None:
    why = _pair_failure(g, r, s, S1, S2)
    if why is not None:
        raise Invalid(f"{where}: the pair S1 = {_fmt(S1)}, S2 = {_fmt(S2)} does not violate "
                      f"({r}, {s}): {why}")


# --------------------------------------------------------------------------- #
# exhaustive re-verification (n <= 20), bit-parallel over all 2^n subsets
# --------------------------------------------------------------------------- #
#
# A "family" is a Python int with 2^n bits: bit S is set iff the node set with
# bitmask S belongs to the family.  Every operation below acts on all subsets at
# once, so the whole enumeration costs O(n^2 * s) big-int operations.

_BITREV = bytes(int(f"{b:08b}"[::-1], 2) for b in range(256))


def _members(j: int, n: int) -> int:
    """Family of the subsets of {0..n-1} that contain node j."""
    N = 1 << n
    half = 1 << j
    x = ((1 << half) - 1) << half  # one period: 2^j absent, then 2^j present
    length = half << 1
    while length < N:
        x |= x << length
        length <<= 1
    return x


def _complement_family(x: int, n: int) -> int:
    """{V \\ S : S in x}: bit S moves to bit (2^n - 1 - S), i.e. reverse 2^n bits."""
    N = 1 << n
    nb = max(1, N // 8)
    y = int.from_bytes(x.to_bytes(nb, "little")[::-1].translate(_BITREV), "little")
    return y >> (8 * nb - N)


def _up_closure(x: int, n: int, members: list[int]) -> int:
    """Family of all U containing some member of x (subset-OR transform)."""
    for j in range(n):
        x |= (x & ~members[j]) << (1 << j)
    return x


def enumerate_violation(g: Graph, r: int, s: int) -> tuple[int, int] | None:
    """A pair violating (r, s), or None if g is (r, s)-robust.  Exhaustive, n <= 20.

    For every S: c(S) = |reach_r(S)| and f(S) = [reach_r(S) != S].  A violating pair
    is S1, S2 disjoint with f(S1), f(S2) and c(S1) + c(S2) <= s - 1; taking
    c(S1) <= c(S2) we need, for some a <= (s-1)/2, S1 in F(a) with some member of
    F(s-1-a) inside V \\ S1, where F(b) = {S : f(S), c(S) <= b}.  (f(empty) is false,
    so both sets are nonempty.)  For s = 1 this is: two disjoint nonempty closed sets.
    """
    n = g.n
    if n < 2:
        return None
    ALL = (1 << (1 << n)) - 1
    members = [_members(j, n) for j in range(n)]
    rr = min(r, n)  # |N(i) \ S| <= n - 1
    kmax = min(s, n + 1)
    # A[t] = family of S with c(S) >= t, t = 0..kmax
    A = [ALL] + [0] * kmax
    notfull = 0
    for i in range(n):
        nb = _bits(g.inmask[i])
        if rr == 0:
            R = members[i]
        elif rr > len(nb):
            R = 0
        else:
            # T[t] = family of S with at least t in-neighbours of i outside S
            T = [ALL] + [0] * rr
            for j in nb:
                out_j = ALL ^ members[j]
                for t in range(rr, 0, -1):
                    T[t] |= T[t - 1] & out_j
            R = members[i] & T[rr]  # S with i in reach_r(S)
        notfull |= members[i] ^ R
        if R:
            for t in range(kmax, 0, -1):
                A[t] |= A[t - 1] & R

    def F(b: int) -> int:
        return notfull if b + 1 > kmax else notfull & ~A[b + 1]

    for a in range(min((s - 1) // 2, n) + 1):
        b = s - 1 - a
        Fb = F(b)
        cand = F(a) & _complement_family(_up_closure(Fb, n, members), n)
        if cand:
            S1 = (cand & -cand).bit_length() - 1
            sub = ALL  # family of the subsets of V \ S1
            for j in _bits(S1):
                sub &= ~members[j]
            hit = Fb & sub
            S2 = (hit & -hit).bit_length() - 1
            return S1, S2
    return None


# --------------------------------------------------------------------------- #
# proofs of (r, s)-robustness: method -> function
# --------------------------------------------------------------------------- #


def _proof_trivial(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method",))
    if r != 0 and g.n != 1:
        raise Invalid(f"{where}: method 'trivial' needs r = 0 or n = 1 (r = {r}, n = {g.n})")
    return "trivial"


def _proof_degree(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method",))
    need = g.n // 2 + r - 1
    for i, mk in enumerate(g.inmask):
        d = mk.bit_count()
        if d < need:
            raise Invalid(f"{where}: node {i} has in-degree {d} < floor(n/2) + r - 1 = {need}")
    return "degree"


def _proof_complete(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method",))
    full = g.full
    for i, mk in enumerate(g.inmask):
        missing = full & ~mk & ~(1 << i)
        if missing:
            u = _bits(missing)[0]
            raise Invalid(f"{where}: graph is not complete: edge [{u}, {i}] is missing")
    if g.n < 2 * r - 1:
        raise Invalid(f"{where}: K_n with n = {g.n} < 2r - 1 = {2 * r - 1} is not {r}-robust")
    return "complete"


def _proof_construction(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method", "order", "seed_size", "seed_proof"))
    order = _perm(p["order"], f"{where}.order", g.n)
    m = _int(p["seed_size"], f"{where}.seed_size", 1, g.n)
    need = r + s - 1
    earlier = 0
    for k, v in enumerate(order):
        if k >= m:
            c = (g.inmask[v] & earlier).bit_count()
            if c < need:
                raise Invalid(f"{where}: node order[{k}]={v} has {c} in-neighbours among earlier "
                              f"nodes, needs {need} (r + s - 1)")
        earlier |= 1 << v
    seed = g.induced(order[:m])
    sub = _proof(p["seed_proof"], f"{where}.seed_proof", seed, r, s, ctx)
    return f"construction({sub})"


def _proof_search(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method", "order", "tree"), ("info",))
    _info(p, where)
    if s != 1:
        raise Invalid(f"{where}: method 'search' proves r-robustness only (s = 1), got s = {s}")
    order = _perm(p["order"], f"{where}.order", g.n)
    if p["tree"] is None:  # tree too large to record
        return _enumerate_or_trust("search", where, g, r, s, ctx)
    tree = _tokens(p["tree"], f"{where}.tree", g.n)
    stopped = _Replay(g, r, where).run(order, tree)
    if stopped:
        return _enumerate_or_trust("search", where, g, r, s, ctx, stopped)
    return "search"


def _tokens(x: Any, where: str, n: int, least: int = -3) -> list[int] | tuple[int, ...]:
    """The token list of a search tree: integers in least..n-1 (checked in C when they
    are)."""
    tree = _array(x, where)
    if tree and ({type(t) for t in tree} != {int} or min(tree) < least or max(tree) >= n):
        k, t = next((k, t) for k, t in enumerate(tree) if not _is_int(t) or not least <= t < n)
        raise Invalid(f"{where}[{k}] = {t!r} is not a token ({least}..-1 or a node "
                      f"0..{n - 1})")
    return tree


@dataclass(frozen=True, eq=False)
class _Side:
    """Per-node thresholds of one side of a replayed search (:class:`_Replay`): a member
    v of a closed set has fewer than t[v] in-neighbours outside it, so a closed set
    holding v has at least m_v = max(1, d_v − t[v] + 2) members. Packed sets:
    ``cut[k]`` / ``keep[k]`` hold the fields with m_v > k / ≤ k; ``D`` is the deficit
    table of V (a member's field 2^(w−1) + min(t[v], n) − 1, all ones for the nodes of
    ``gone``, those with t[v] ≤ 0, never in a closed set); ``charged``: the nodes the
    ``crowded`` leaf checks besides the earlier roots (a ``charged_tree``'s Q_k);
    ``most``: max_v min(t[v], n), so that a member's deficit is below it."""

    t: list[int]
    cut: list[int]
    keep: list[int]
    D: int
    gone: int
    charged: list[int]
    most: int

    def least_in(self, Q: int, n: int) -> int:
        """min_{v∈Q} m_v for a packed Q (n + 1 when Q = ∅): a binary search on ``keep``."""
        if not Q:
            return n + 1
        lo, hi = 1, n + 1
        while lo < hi:
            mid = (lo + hi) // 2
            if Q & self.keep[mid]:
                hi = mid
            else:
                lo = mid + 1
        return lo


class _Replay:
    """Replays a ``search`` tree (FORMAT.md) and checks every leaf exactly.

    Each state (S, X) under root k (B = order[:k]) needs P = core_r(V \\ X) and
    Q = core_r(V \\ S \\ B). A child differs from its parent by one node u, removed from
    Q (u into S) or from P (u into X); as core_r(U') = core_r(core_r(U) ∩ U') for
    U' ⊆ U, the child's set is its parent's minus u, re-peeled (:meth:`shrink`). A
    stack entry keeps its parent's P and Q: a closed superset of the exact set, with
    core_r(P \\ X) = core_r(V \\ X) and core_r(Q \\ S) = core_r(V \\ S \\ B), so a set is
    brought up to date (removing at most u) only when the state needs it: a -1 leaf
    needs only Q, a -2 leaf only P, branches and -3 leaves both. Between roots,
    P_{k+1} = core_r(P_k \\ {order[k]}) and Q_k = core_r(P_k \\ {order[k]}).

    **Packed sets.** Nodes are ranked by in-degree (ties by index), node[p] the p-th;
    it owns the w-bit field p of an integer, w = bitlength(n) + 1, and a node set is
    the integer with the top (guard) bits of its nodes' fields set (:meth:`pack`), so
    the lowest bit of a set is its member of least in-degree. A closed set U comes
    with D, whose field holds 2^(w−1) + δ_j for a member j, δ_j = min(r, n) − 1 −
    |N(j) \\ U| ≥ 0 (its deficit; r ≥ n never peels), and 2^w − 1 for a non-member.
    Subtracting from D the fields of the out-neighbours of removed nodes lowers every
    deficit at once; no field borrows from the next (0 ≤ δ_j, at most n − 1 < 2^(w−1)
    decrements; a non-member absorbs n − 1), and the members whose guard bit is
    cleared are those now with r in-neighbours outside.

    ``work`` counts steps, each a few operations on packed sets of n·w bits and
    weighted by ⌈n·w / 1024⌉: one per token, per round of :meth:`shrink` and per node
    whose out-neighbours it subtracts, per member of S at a -3 leaf, and n + |E| + n
    to set up the tables and the first root; besides, one step per 64 bits of memory:
    the table ``less`` (up to n·w bits per node with out-neighbours) and the stack
    (at most n + 1 levels, as each fixes one more node in S ∪ X, each with up to four
    packed sets of its own: S or X with the new node, and a re-peeled set with its D),
    and each row sum stored by :meth:`row_sum` (2·n·w bits, with its key), so memory
    stays below 64·MAX_SEARCH_WORK bits.
    """

    def __init__(self, g: Graph, r: int, where: str) -> None:
        n = g.n
        self.g, self.where = g, where
        self.w = w = n.bit_length() + 1
        self.deg = deg = [mk.bit_count() for mk in g.inmask]
        self.ones = (1 << w) - 1
        self.node = sorted(range(n), key=lambda v: (deg[v], v))
        field = [0] * n
        for p, v in enumerate(self.node):
            field[v] = p
        self.field = field
        self.top = [w * field[v] + w - 1 for v in range(n)]  # v's guard bit
        self.unit = max(1, -(-n * w // 1024))
        out = g.outmask()
        senders = sum(1 for mk in out if mk)
        self.work = (n + g.m) * self.unit + (senders + 4 * n + 4) * n * w // 64
        if self.work > MAX_SEARCH_WORK:
            return  # the tables alone are beyond the limit: run() stops before using them
        # indexed by w (p + 1), the bit length of the guard bit of field p (node v):
        # less = the lowest bits of the fields of v's out-neighbours
        self.less = [0] * (w * (n + 1))
        for v in range(n):
            self.less[w * (field[v] + 1)] = sum(1 << (w * field[j]) for j in _bits(out[v]))
        self.full = self.pack(g.full)
        self.side = self.threshold_side([r] * n)
        self.pin: list[int] = []
        self.rows: list[int] = []
        self.sums: dict[bytes, int] = {}

    def capped_tables(self) -> None:
        """The tables of the capped leaves (:meth:`capped`): ``pin[i]``, the packed N(i),
        and ``rows[i]``, the Σ of the ``less`` rows of N(i) (field v: |N(i) ∩ N(v)|);
        n + |E| steps and n·w bits each (nothing when the tables were beyond the limit)."""
        g, w, field = self.g, self.w, self.field
        if self.work > MAX_SEARCH_WORK:
            return
        self.work += (g.n + g.m) * self.unit + 2 * g.n * g.n * w // 64
        self.pin = [self.pack(mk) for mk in g.inmask]
        self.rows = [sum(self.less[w * (field[u] + 1)] for u in _bits(mk)) for mk in g.inmask]

    def threshold_side(self, t: list[int], charged: int = 0) -> _Side:
        """The :class:`_Side` of the per-node thresholds ``t`` (t[v] for node v): a member
        v of a closed set has fewer than t[v] in-neighbours outside it; ``charged`` (a
        bitmask): the side's charged nodes."""
        n, w, top = self.g.n, self.w, self.top
        least = [max(1, d - tv + 2) for d, tv in zip(self.deg, t)]
        cut, acc = [0] * (n + 2), [0] * (n + 2)
        for v in range(n):
            acc[min(least[v], n + 1)] |= 1 << top[v]
        for k in range(1, n + 2):
            acc[k] |= acc[k - 1]
            cut[k] = self.full & ~acc[k]
        D = gone = 0
        for v in range(n):
            if t[v] >= 1:
                D |= ((1 << (w - 1)) + min(t[v], n) - 1) << (w * self.field[v])
            else:
                D |= self.ones << (w * self.field[v])
                gone |= 1 << top[v]
        self.work += 3 * n * self.unit
        return _Side(t, cut, acc, D, gone, _bits(charged), min(max(t), n))

    def pack(self, mask: int) -> int:
        """The packed form of the node set ``mask`` (a bitmask)."""
        return sum(1 << self.top[v] for v in _bits(mask))

    def unpack(self, packed: int) -> int:
        """The node-set bitmask of a packed set."""
        return sum(1 << self.node[b // self.w] for b in _bits(packed))

    def shrink(self, U: int, D: int, gone: int, side: _Side, watch: int = 0) -> tuple[int, int]:
        """core(U \\ gone) for the thresholds of ``side`` and its D, for a closed U with D
        (packed sets).

        Each round removes ``todo`` from U, makes their fields all ones and subtracts
        the fields of their out-neighbours; the members whose guard bit is then cleared
        have r in-neighbours outside, and are the next round's ``todo``. Every removed
        node had r in-neighbours outside a superset of the result, which is closed:
        the result is the core. Every member j of a nonempty closed C ⊆ U has at most
        r − 1 in-neighbours outside C, so |C| ≥ m_j = max(1, d_j − r + 2) ("least"):
        C ⊆ U' = {j ∈ U : m_j ≤ |U|}, then C ⊆ {j ∈ U' : m_j ≤ |U'|}, and so on (each
        cuts the fields of ``side.cut``); when this reaches ∅, the core is
        empty (and D is not used again). With ``watch``, the peeling stops once a
        member of ``watch`` is peeled: the set returned then lies between the core and
        U, without that member (enough to show watch ⊄ core; D is not used again).
        Work: one step per round, per cut and per node whose out-neighbours are
        subtracted."""
        less, cut, keep, ones, w = self.less, side.cut, side.keep, self.ones, self.w
        todo = gone & U
        steps = 0
        while todo:
            U ^= todo
            C = U
            k = C.bit_count()
            while C & cut[k]:  # members j with m_j > k = |C|: cut them
                C &= keep[k]
                k = C.bit_count()
                steps += 1
            if not C:
                U = 0
                steps += 1
                break
            steps += 1 + todo.bit_count()
            while todo:  # each removed node: its field all ones, its out-neighbours' lowered
                low = todo & -todo
                todo ^= low
                b = low.bit_length()
                D = (D | ones << (b - w)) - less[b]
            todo = U & ~D
            if todo & watch:
                U ^= todo
                break
        self.work += steps * self.unit
        return U, D

    def run(self, order: list[int], tree: list[int] | tuple[int, ...],
            configs: Iterable[tuple[int, _Side, _Side]] | None = None) -> str:
        """Check every leaf of ``tree``; '' when all are justified, raise Invalid on
        the first that is not, or say why the replay stopped (beyond MAX_SEARCH_WORK).
        ``configs``: the (gone, side1, side2) of the subtrees in turn (:meth:`config`);
        default the one of a ``search`` tree, (∅, r, r)."""
        ntok = len(tree)
        self.work += ntok * self.unit
        if self.work > MAX_SEARCH_WORK:
            return self.beyond(0, ntok)
        pos = 0
        for gone, a, b in configs or [(0, self.side, self.side)]:
            pos = self.config(order, tree, pos, self.pack(gone), a, b)
            if pos < 0:
                return self.beyond(-1 - pos, ntok)
        if pos != ntok:
            raise Invalid(f"{self.where}: search tree has {ntok - pos} unused tokens after "
                          f"the last root")
        return ""

    def config(self, order: list[int], tree: list[int] | tuple[int, ...], pos: int,
               gone: int, a: _Side, b: _Side) -> int:
        """Replay, from token ``pos``, the subtrees of the roots order[k] ∉ ``gone``
        (packed; B = gone ∪ order[:k]): with order[k] ∈ S1 for the thresholds of ``a`` on
        S1's side and ``b`` on S2's, then, unless a is b, with the sides swapped. The
        position after them, or −1 − pos when the replay stops at pos (work limit)."""
        shrink, top, ntok, n = self.shrink, self.top, len(tree), self.g.n
        chain = {side: shrink(self.full, side.D, side.gone | gone, side) for side in (a, b)}
        B, before = gone, []
        for k in range(self.g.n):
            S0 = 1 << top[order[k]]
            if S0 & gone:
                continue
            for s1, s2 in ((a, b),) if a is b else ((a, b), (b, a)):
                P, PD = chain[s1]
                Q, QD = shrink(*chain[s2], S0, s2)
                stack = [(S0, B, P, PD, Q, QD)]
                while stack:
                    if self.work > MAX_SEARCH_WORK:
                        return -1 - pos
                    if pos >= ntok:
                        raise Invalid(f"{self.where}: search tree ends early (in the subtree "
                                      f"of root {k})")
                    S, X, P1, PD1, Q1, QD1 = stack.pop()
                    t = tree[pos]
                    if t >= 0:
                        bit = 1 << top[t]
                        if (S | X) & bit:
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                        if P1 & X:
                            P1, PD1 = shrink(P1, PD1, X, s1)
                        if Q1 & S:
                            Q1, QD1 = shrink(Q1, QD1, S, s2)
                        stack.append((S, X | bit, P1, PD1, Q1, QD1))  # second: u out of S1
                        stack.append((S | bit, X, P1, PD1, Q1, QD1))  # first: u in S1
                    elif t <= -5:  # Q1 \\ S is peeled inside capped()
                        if P1 & X:
                            P1 = shrink(P1, PD1, X, s1)[0]
                        i, j = divmod(-5 - t, n)
                        if (i > j or not S >> top[i] & S >> top[j] & 1
                                or self.capped(i, j, S, P1, Q1, QD1, s1, s2)):
                            if Q1 & S:
                                Q1 = shrink(Q1, QD1, S, s2)[0]
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                    elif t == -1:
                        if Q1 & S:
                            Q1 = shrink(Q1, QD1, S, s2)[0]
                        if Q1:
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                    elif t == -2:
                        if P1 & X:
                            P1 = shrink(P1, PD1, X, s1, S)[0]
                        if not S & ~P1:
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                    elif t == -4:
                        if self.crowded(S, before, s1) is None:
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                    else:
                        if Q1 & S:
                            Q1 = shrink(Q1, QD1, S, s2)[0]
                        if P1 & X:
                            P1 = shrink(P1, PD1, X, s1)[0]
                        if sum(self.sizes(S, Q1, s1, s2)) <= (P1 | Q1).bit_count():
                            raise Invalid(self.why(t, pos, S, X, B, P1, Q1, s1, s2))
                    pos += 1
            B |= S0
            before.append(order[k])
            chain = {side: shrink(*chain[side], S0, side) for side in chain}
        return pos

    def capped(self, i: int, j: int, S: int, P: int, Q: int, D: int, s1: _Side,
               s2: _Side) -> int:
        """The capped core (packed, exact) for the members i, j of the packed S (i = j:
        one member) of the state's Q = core(Q \\ S) (``s2``'s thresholds; Q closed, with
        its D, as on the stack of :meth:`config`; S ∩ Q = ∅ for the exact Q): the largest
        Q' ⊆ Q \\ S whose members v have, for m = i, j,
        |N(v) ∩ Q' \\ c_m| + min(sl_m, |N(v) ∩ Q' ∩ c_m|) ≥ need_v = d_v − t_v + 1
        (t: ``s2``'s thresholds), c_m = N(m) ∩ P \\ S, sl_m = |c_m| − need_m,
        need_m = |N(m) \\ S| − t_m + 1 (t: ``s1``'s); 0 (empty) when an sl_m < 0.

        Every U2 of the state lies in it (FORMAT.md, the −5 − (i·n + j) leaf): U1 ⊆ P
        holds m and ≥ need_m nodes of c_m, so |U2 ∩ c_m| ≤ sl_m, and each v ∈ U2 has
        ≥ d_v − t_v + 1 in-neighbours in U2, at most min(sl_m, |N(v) ∩ U2 ∩ c_m|) of
        them in c_m; the conditions only weaken as Q' shrinks, so peeling keeps U2.
        They include |N(v) ∩ Q'| ≥ need_v, so the peel of Q \\ S is the peel of its
        core, the state's Q (one peel instead of two). (sl_m may be lowered to
        |c_m ∩ Q|: min(sl_m, e) is the same for every e ≤ |c_m ∩ Q|.)

        Packed (when sl_m + ``s2.most`` ≤ 2^(w−1), else :meth:`capped_slow`): D's field v
        is 2^(w−1) + δ_v, δ_v = min(t_v, n) − 1 − |N(v) \\ U| (U: the set being peeled;
        = |N(v) ∩ U| − need_v when t_v ≤ n, else δ_v ≥ |N(v) ∩ U| and v is never
        peeled for it, rightly); F_m's field v is 2^(w−1) + δ_v − e_v,
        e_v = |N(v) ∩ U ∩ c_m|: F_m = D − E_m at the start (E_m: the ``less`` rows of
        c_m ∩ Q, :meth:`row_sum`), and a removed node's row is subtracted from D, and
        from F_m when it is not in c_m. v ∈ U is peeled when δ_v < 0 or
        δ_v − e_v + sl_m < 0: the guard bit of its field in D or in F_m + sl_m·[U].
        No field borrows or carries: a member's δ_v ≥ −need_v ≥ 1 − n (t_v ≥ 1) and
        δ_v − e_v = |N(v) ∩ U \\ c_m| − need_v ≥ 1 − n, while 2^(w−1) > n; δ_v < most,
        so δ_v − e_v + sl_m < 2^(w−1); the field of a node outside U stays in
        (0, 2^w): once all ones (:meth:`shrink`) or a member's, it loses at most one
        per in-neighbour removed afterwards, and E_m's field counts only in-neighbours
        still in Q.

        A nonempty Z ⊆ C meeting the conditions has, for each member v,
        d_v − t_v + 1 ≤ min(|Z| − 1, |Z \\ c_m| + sl_m), so m_v ≤
        min(|C|, |C \\ c_m| + sl_m + 1) (m_v as in :meth:`shrink`): the same cut as
        there leaves a superset of the capped core (∅: it is empty; the cut nodes are
        peeled with the next round's). Work: one step per round, cut, node of c_m ∩ Q
        and removed node."""
        pin, room, t1 = self.pin, (1 << (self.w - 1)) - s2.most, s1.t
        need = pin[i] & ~S
        c1 = need & P
        q1 = c1 & Q
        sl1 = min(c1.bit_count() - need.bit_count() + t1[i] - 1, q1.bit_count())
        if sl1 < 0:
            return 0
        if i == j:
            if sl1 <= room:
                E = self.sums.get(_store_key(q1))
                if E is None:
                    E = self.row_sum(i, q1)
                return self.capped_one(c1, sl1, D - E, Q, D, S & Q, s2)
            return self.capped_wide(i, j, S, P, Q, D, s1, s2)
        need = pin[j] & ~S
        c2 = need & P
        q2 = c2 & Q
        sl2 = min(c2.bit_count() - need.bit_count() + t1[j] - 1, q2.bit_count())
        if sl2 < 0:
            return 0
        if sl1 <= room and sl2 <= room:
            return self.capped_two((c1, sl1, D - self.row_sum(i, q1)),
                                   (c2, sl2, D - self.row_sum(j, q2)), Q, D, S & Q, s2)
        return self.capped_wide(i, j, S, P, Q, D, s1, s2)

    def capped_wide(self, i: int, j: int, S: int, P: int, Q: int, D: int, s1: _Side,
                    s2: _Side) -> int:
        """:meth:`capped` when a lowered sl_m + ``s2.most`` > 2^(w−1) (both sl_m ≥ 0):
        lowered again to |c_m ∩ core(Q \\ S)|, then packed or :meth:`capped_slow`."""
        pin, t1 = self.pin, s1.t
        if Q & S:
            Q, D = self.shrink(Q, D, S, s2)
        c1, c2 = pin[i] & P & ~S, pin[j] & P & ~S
        sl1 = min(c1.bit_count() - (pin[i] & ~S).bit_count() + t1[i] - 1,
                  (c1 & Q).bit_count())
        sl2 = min(c2.bit_count() - (pin[j] & ~S).bit_count() + t1[j] - 1,
                  (c2 & Q).bit_count())
        if max(sl1, sl2) + s2.most > 1 << (self.w - 1):
            return self.capped_slow((c1, sl1, c2, sl2), Q, s2)
        if i == j:
            return self.capped_one(c1, sl1, D - self.row_sum(i, c1 & Q), Q, D, 0, s2)
        return self.capped_two((c1, sl1, D - self.row_sum(i, c1 & Q)),
                               (c2, sl2, D - self.row_sum(j, c2 & Q)), Q, D, 0, s2)

    def capped_one(self, c: int, sl: int, F: int, U: int, D: int, todo: int,
                   s2: _Side) -> int:
        """:meth:`capped`'s packed peel for one member (c, sl and F = D − E), of U
        without ``todo`` (a node failing the conditions in U fails them in U \\ todo)."""
        less, sh, cut, keep = self.less, self.w - 1, s2.cut, s2.keep
        out = ~c  # the nodes outside c: their rows are taken from F too
        steps = 1
        todo |= U & ~(D & (F + sl * (U >> sh)))
        while todo:
            U ^= todo
            k = U.bit_count()
            k2 = (U & out).bit_count() + sl + 1
            if k2 < k:
                k = k2
            if U & cut[k]:
                C = U
                while C & cut[k]:
                    C &= keep[k]
                    k = C.bit_count()
                    k2 = (C & out).bit_count() + sl + 1
                    if k2 < k:
                        k = k2
                    steps += 1
                if not C:
                    U = 0
                    break
                todo |= U ^ C
                U = C
            steps += 1 + todo.bit_count()
            rest = todo & out
            todo &= c
            while todo:
                low = todo & -todo
                todo ^= low
                D -= less[low.bit_length()]
            while rest:
                low = rest & -rest
                rest ^= low
                row = less[low.bit_length()]
                D -= row
                F -= row
            todo = U & ~(D & (F + sl * (U >> sh)))
        self.work += steps * self.unit
        return U

    def capped_two(self, m1: tuple[int, int, int], m2: tuple[int, int, int], U: int, D: int,
                   todo: int, s2: _Side) -> int:
        """:meth:`capped`'s packed peel for two members, each (c, sl, F = D − E), of U
        without ``todo``."""
        less, sh, cut, keep = self.less, self.w - 1, s2.cut, s2.keep
        (c1, sl1, F1), (c2, sl2, F2) = m1, m2
        steps, M = 1, U >> sh
        todo |= U & ~(D & (F1 + sl1 * M) & (F2 + sl2 * M))
        while todo:
            U ^= todo
            k = U.bit_count()
            k1 = (U & ~c1).bit_count() + sl1 + 1
            k2 = (U & ~c2).bit_count() + sl2 + 1
            k = k if k < k1 else k1
            k = k if k < k2 else k2
            if U & cut[k]:
                C = U
                while C & cut[k]:
                    C &= keep[k]
                    k = min(C.bit_count(), (C & ~c1).bit_count() + sl1 + 1,
                            (C & ~c2).bit_count() + sl2 + 1)
                    steps += 1
                if not C:
                    U = 0
                    break
                todo |= U ^ C
                U = C
            steps += 1 + todo.bit_count()
            while todo:
                low = todo & -todo
                todo ^= low
                row = less[low.bit_length()]
                D -= row
                if not c1 & low:
                    F1 -= row
                if not c2 & low:
                    F2 -= row
            M = U >> sh
            todo = U & ~(D & (F1 + sl1 * M) & (F2 + sl2 * M))
        self.work += steps * self.unit
        return U

    def row_sum(self, i: int, q: int) -> int:
        """Σ of the ``less`` rows of the packed set q ⊆ N(i): field v holds the number
        of its members that send to v (< n: no carry); from ``rows[i]``, the sum over
        N(i), when N(i) \\ q is the smaller (work: one step per row added or taken).
        Kept in ``sums`` (q's bytes → Σ, :func:`_store_key`; one step to look up,
        2·n·w bits each, the key q and Σ, at most ROW_SUMS of them: emptied when full),
        as nearby leaves share most q
        (88 % of the look-ups of the ER(30, 0.5) s* = 3 proof); :meth:`capped` looks up
        a single member's itself, charged with its peel's first step."""
        key = _store_key(q)
        E = self.sums.get(key)
        if E is not None:
            self.work += self.unit
            return E
        if len(self.sums) >= ROW_SUMS:
            self.sums.clear()
        self.work += 2 * self.g.n * self.w // 64
        self.sums[key] = E = self._row_sum(i, q)
        return E

    def _row_sum(self, i: int, q: int) -> int:
        """:meth:`row_sum`, computed."""
        less, rest = self.less, self.pin[i] & ~q
        sign = q.bit_count() > rest.bit_count()
        E, m = (self.rows[i], rest) if sign else (0, q)
        self.work += m.bit_count() * self.unit
        while m:
            low = m & -m
            m ^= low
            if sign:
                E -= less[low.bit_length()]
            else:
                E += less[low.bit_length()]
        return E

    def capped_slow(self, caps: tuple[int, int, int, int], Q: int, s2: _Side) -> int:
        """:meth:`capped` by peeling node by node on unpacked sets (any sl; work: one
        step per node examined); ``caps`` = (c1, sl1, c2, sl2), packed c."""
        inmask, deg, t = self.g.inmask, self.deg, s2.t
        c1, sl1, c2, sl2 = caps
        c1, c2, U = self.unpack(c1), self.unpack(c2), self.unpack(Q)
        steps, changed = 0, True
        while changed and U:
            changed = False
            for v in _bits(U):
                steps += 1
                inside, want = inmask[v] & U, deg[v] - t[v] + 1
                if any((inside & ~c).bit_count() + min(sl, (inside & c).bit_count()) < want
                       for c, sl in ((c1, sl1), (c2, sl2))):
                    U &= ~(1 << v)
                    changed = True
        self.work += steps * self.unit
        return self.pack(U)

    def crowded(self, S: int, before: list[int], side: _Side) -> int | None:
        """A node j of ``before`` or of the side's charged nodes with more than d_j − t_j
        in-neighbours in the packed set S (t: the thresholds of ``side``), or None."""
        self.work += (S.bit_count() + len(before) + len(side.charged)) * self.unit
        S = self.unpack(S)
        inmask, deg, t = self.g.inmask, self.deg, side.t
        return next((j for j in before + side.charged
                     if (inmask[j] & S).bit_count() > deg[j] - t[j]), None)

    @staticmethod
    def beyond(pos: int, ntok: int) -> str:
        """Why the replay stopped at token ``pos`` of ``ntok``."""
        return (f"replaying its tree needs more than {MAX_SEARCH_WORK} steps "
                f"(the checker's work limit; stopped at token {pos} of {ntok})")

    def sizes(self, S: int, Q: int, s1: _Side, s2: _Side) -> tuple[int, int]:
        """(need1, need2) for packed S, Q: the sizes of a closed S1 ⊇ S (thresholds of
        ``s1``) and of a closed nonempty S2 ⊆ Q (``s2``) are at least these.

        |S1| ≥ |S| + max_{i∈S} (|N(i) \\ S| − t_i + 1)⁺ (each i ∈ S keeps ≤ t_i − 1 of
        its in-neighbours outside) and |S2| ≥ min_{j∈Q} max(1, d_j − t_j + 2) (n + 1 when
        Q = ∅)."""
        inmask, t = self.g.inmask, s1.t
        self.work += S.bit_count() * self.unit
        S = self.unpack(S)
        need1 = S.bit_count() + max(
            [0] + [(inmask[i] & ~S).bit_count() - t[i] + 1 for i in _bits(S)])
        return need1, s2.least_in(Q, self.g.n)

    def why(self, t: int, pos: int, S: int, X: int, B: int, P: int, Q: int, s1: _Side,
            s2: _Side) -> str:
        """Why token ``t`` at ``pos`` is wrong at the state (S, X) of root B, with the
        exact P = core(V \\ X) for a -2 or -3 leaf and Q = core(V \\ S \\ B) for a
        -1 or -3 leaf (packed sets)."""
        fmt = self.fmt
        if t >= 0:
            side = "S" if S >> self.top[t] & 1 else "X"
            return (f"{self.where}: search tree branches at token {pos} on node {t}, which "
                    f"is already in {side} = {fmt(S if side == 'S' else X)}")
        head = f"{self.where}: search tree leaf {t} at token {pos} is not justified"
        if t == -1:
            return f"{head}: core(V \\ S \\ B) = {fmt(Q)} is nonempty (S = {fmt(S)}, B = {fmt(B)})"
        if t == -2:
            return f"{head}: S = {fmt(S)} is inside core(V \\ X) = {fmt(P)} (X = {fmt(X)})"
        if t == -4:
            return (f"{head}: no earlier root or charged node of its side has more than "
                    f"d_j - t_j in-neighbours in S = {fmt(S)}")
        if t <= -5:
            i, j = divmod(-5 - t, self.g.n)
            if i > j or not S >> self.top[i] & S >> self.top[j] & 1:
                return f"{head}: nodes {i} <= {j} are not both in S = {fmt(S)}"
            return (f"{head}: the capped core of Q = {fmt(Q)} for nodes {i}, {j} is "
                    f"nonempty (S = {fmt(S)}, P = {fmt(P)})")
        need1, need2 = self.sizes(S, Q, s1, s2)
        return (f"{head}: |S1| >= {need1} and |S2| >= {need2} fit in |P u Q| = "
                f"{(P | Q).bit_count()} (S = {fmt(S)}, X = {fmt(X)}, B = {fmt(B)})")

    def fmt(self, packed: int) -> str:
        """A packed set as {i, j, ...} in node indices."""
        return _fmt(self.unpack(packed))


def _proof_implied(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    """(r', s')-robust implies (r, s)-robust when r' >= r and s <= s' + r' - r: an
    (r, s)-violating pair minus up to r' - r reachable members of each set violates
    (r', s') (a remaining unreachable member gains at most r' - r outside neighbours,
    and at least min(s - 1, r' - r) reachable members are gone). Special cases:
    r' >= r and s' >= s; r' >= r + s - 1; (r', s') implies (r' - 1, s' + 1)."""
    _obj(p, where, ("method", "r", "s", "proof"))
    r2 = _int(p["r"], f"{where}.r", 0)
    s2 = _int(p["s"], f"{where}.s", 1, g.n)
    if not (r2 >= r and s <= s2 + r2 - r):
        raise Invalid(f"{where}: ({r2}, {s2})-robustness does not imply ({r}, {s})-robustness")
    sub = _proof(p["proof"], f"{where}.proof", g, r2, s2, ctx)
    return f"implied({sub})"


def _enumerate_or_fail(where: str, g: Graph, r: int, s: int) -> None:
    hit = enumerate_violation(g, r, s)
    if hit is not None:
        S1, S2 = hit
        raise Invalid(f"{where}: graph is not ({r}, {s})-robust: S1 = {_fmt(S1)}, "
                      f"S2 = {_fmt(S2)} violate it (found by enumeration)")


def _proof_enumeration(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method",))
    if g.n > MAX_ENUM_N:
        return _unreplayed("enumeration", where, g, r, s, ctx,
                           f"too large to enumerate (n = {g.n} > {MAX_ENUM_N})")
    _enumerate_or_fail(where, g, r, s)
    return "enumeration"


def _cheap_pairs(g: Graph) -> list[tuple[int, int]]:
    """Candidate violating pairs found in linear time (n >= 2):

    * ({i}, V \\ {i}) for a node i of least in-degree: for r >= 2, V \\ {i} has no
      r-reachable node, so (r, s)-robust with r >= 2 needs r <= min in-degree;
    * ({i}, {j}) for the two nodes of least in-degree;
    * a balanced split (first floor(n/2) nodes, the rest): no node of either half has
      more than ceil(n/2) in-neighbours outside it, so it violates (ceil(n/2) + 1, s)
      for every s (rho <= ceil(n/2)).
    """
    n = g.n
    low = sorted(range(n), key=lambda i: g.inmask[i].bit_count())[:2]
    i, j = low
    half = (1 << (n // 2)) - 1
    return [(1 << i, g.full ^ (1 << i)), (1 << i, 1 << j), (half, g.full ^ half)]


def _refute_cheaply(where: str, g: Graph, r: int, s: int) -> None:
    """Raise Invalid if a pair of :func:`_cheap_pairs` violates (r, s)."""
    if g.n < 2:
        return
    for S1, S2 in _cheap_pairs(g):
        if _pair_failure(g, r, s, S1, S2) is None:
            raise Invalid(f"{where}: graph is not ({r}, {s})-robust: S1 = {_fmt(S1)}, "
                          f"S2 = {_fmt(S2)} violate it (the checker's linear-time witness "
                          "pairs refute even a proof it cannot replay)")


def _unreplayed(method: str, where: str, g: Graph, r: int, s: int, ctx: _Ctx,
                why: str) -> str:
    """A proof the checker does not replay: it must still survive the linear-time witness
    pairs (a violating pair refutes the claim); then it is recorded as not checked."""
    _refute_cheaply(where, g, r, s)
    ctx.trust(method, f"{where}: '{method}' proof of ({r}, {s})-robustness not checked: {why}")
    return f"{method} (not checked)"


def _info(p: dict, where: str) -> None:
    if "info" in p and not isinstance(p["info"], dict):
        raise Invalid(f"{where}.info must be a JSON object, got {_tname(p['info'])}")


def _enumerate_or_trust(method: str, where: str, g: Graph, r: int, s: int, ctx: _Ctx,
                        why: str = "") -> str:
    """A proof the checker cannot replay (``why``, if given, says why not): re-verified
    by enumeration when n ≤ 20, otherwise accepted on trust (and reported)."""
    if g.n > MAX_ENUM_N:
        return _unreplayed(method, where, g, r, s, ctx,
                           (f"{why}; " if why else "") + f"accepted on trust (n = {g.n} > "
                           f"{MAX_ENUM_N}, beyond the checker's own enumeration)")
    _enumerate_or_fail(where, g, r, s)
    return f"{method} (re-verified by enumeration)"


def _proof_dp(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method",), ("info",))
    _info(p, where)
    return _enumerate_or_trust("dp", where, g, r, s, ctx)


MAX_SPECTRAL_N = 200
MAX_SPECTRAL_WORK = 12_000_000  # n^3/6 eliminations weighted by (bits / 1024)^2


def _positive_definite(M: list[list[int]]) -> int:
    """-1 when the symmetric integer matrix M is positive definite, else the index k of
    the first leading principal minor det M[:k+1, :k+1] that is <= 0 (Sylvester).

    Fraction-free (Bareiss) elimination: after step k − 1 the pivot A[k][k] is that
    minor, and every division is exact. The matrix stays symmetric, so only the upper
    triangle is updated (A[i][k] = A[k][i])."""
    A = [row[:] for row in M]
    n = len(A)
    prev = 1
    for k in range(n):
        Ak = A[k]
        akk = Ak[k]
        if akk <= 0:
            return k
        for i in range(k + 1, n):
            Ai = A[i]
            aik = Ak[i]
            for j in range(i, n):
                Ai[j] = (akk * Ai[j] - aik * Ak[j]) // prev
        prev = akk
    return -1


def _spectral_work(n: int, entry_bits: int) -> int:
    """About n^3/6 products of minors of up to n (entry_bits + log2 n) bits (Hadamard),
    counted in 1024-bit products."""
    bits = n * (entry_bits + n.bit_length())
    return n ** 3 // 6 * max(1, -(-bits // 1024)) ** 2


def _proof_spectral(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    """Undirected G: rho >= ceil(lambda2 / 2) (for |S| <= n/2 the edge boundary is
    >= lambda2 |S| (n - |S|) / n >= lambda2 |S| / 2). Valid iff G is symmetric,
    c >= 2(r - 1) and lambda2 > c, shown by L - c I + (c/n + 1) J positive definite
    (J = all ones: the ones vector gets n > 0, its complement the eigenvalues of L
    minus c)."""
    _obj(p, where, ("method", "c"))
    if s != 1:
        raise Invalid(f"{where}: method 'spectral' proves r-robustness only (s = 1), got s = {s}")
    n = g.n
    if not isinstance(p["c"], str) or len(p["c"]) > 64 or \
            not all(ch in "0123456789/" for ch in p["c"]):
        raise Invalid(f"{where}.c must be a nonnegative rational string like \"13/4\" "
                      f"(at most 64 characters), got {p['c']!r}")
    try:
        c = Fraction(p["c"])
    except (ValueError, ZeroDivisionError):
        raise Invalid(f"{where}.c = {p['c']!r} is not a rational number") from None
    if c < 2 * (r - 1):
        raise Invalid(f"{where}: c = {c} < 2(r - 1) = {2 * (r - 1)}: lambda2 > c does not give r")
    for i, mk in enumerate(g.inmask):
        for j in _bits(mk):
            if not g.inmask[j] >> i & 1:
                raise Invalid(f"{where}: graph is not undirected: edge [{j}, {i}] has no reverse")
    if n > MAX_SPECTRAL_N:
        return _unreplayed("spectral", where, g, r, s, ctx,
                           f"too large for the exact spectral check (n = {n} > "
                           f"{MAX_SPECTRAL_N})")
    # M = q n (L - c I + (c/n + 1) J) for c = a/q: integer, positive definite iff the
    # matrix above is
    a, q = c.numerator, c.denominator
    off = a + q * n  # q n (c/n + 1)
    M = [[off - (q * n if g.inmask[i] >> j & 1 else 0) for j in range(n)] for i in range(n)]
    for i in range(n):
        M[i][i] = q * n * g.inmask[i].bit_count() - a * n + off
    work = _spectral_work(n, max(abs(t).bit_length() for row in M for t in row))
    if work > MAX_SPECTRAL_WORK:
        return _unreplayed("spectral", where, g, r, s, ctx,
                           f"the exact spectral check needs work {work} > {MAX_SPECTRAL_WORK} "
                           f"(n = {n}, c = {c})")
    k = _positive_definite(M)
    if k >= 0:
        raise Invalid(f"{where}: lambda2 > c = {c} fails (L - cI + (c/n+1)J has a "
                      f"non-positive pivot at {k})")
    return "spectral"


def _configurations(n: int, c: int) -> Iterator[tuple[int, int]]:
    """The configurations (Q1, Q2) (bitmasks) of a ``charged_tree``, in its order
    (FORMAT.md): (∅, ∅), then by size k = 1..c, Q = Q1 ∪ Q2 in lexicographic order of
    its sorted nodes, Q1 = {min Q} ∪ T for the subsets T of the rest of Q by their
    bitmask over it (bit j: its j-th node)."""
    yield 0, 0
    for k in range(1, c + 1):
        for Q in itertools.combinations(range(n), k):
            for mask in range(1 << (k - 1)):
                Q1 = 1 << Q[0]
                Q2 = 0
                for j, v in enumerate(Q[1:]):
                    if mask >> j & 1:
                        Q1 |= 1 << v
                    else:
                        Q2 |= 1 << v
                yield Q1, Q2


def _charged_replay(g: Graph, r: int, s: int, order: list[int], tree: list[int] | tuple,
                    where: str, uniform: bool = False) -> str:
    """Replay a ``charged_tree`` (FORMAT.md): '' when every configuration's subtrees are
    justified, else why the replay stopped (work limit); raises Invalid on a fault.

    A pair of cost c < s whose sets keep closed members U_k = S_k \\ reach_r(S_k) ≠ ∅
    has the configuration Q_k = reach_r(S_k), |Q1| + |Q2| = c, and U_k avoids
    Q1 ∪ Q2 with fewer than t_k(i) = r + |N(i) ∩ Q_k| in-neighbours outside U_k for
    each member (|N(i) \\ S_k| < r); such sets are closed under union, so the
    ``search`` replay with these per-side thresholds and B ⊇ Q1 ∪ Q2 excludes them.
    In a violating pair of least cost, grown maximal, each j ∈ Q_k stays r-reachable
    (else a cheaper violating pair), so the -4 leaf also checks the charged nodes of
    the enumerated side.

    ``uniform``: one part per type (c1, c2), c1 + c2 = s − 1, c1 ≥ c2 (by c2), with the
    thresholds t_k(i) = r + min(c_k, d_i) ≥ r + |N(i) ∩ Q_k| for every configuration
    with |Q1| ≤ c1, |Q2| ≤ c2, no charged nodes (closed sets for smaller thresholds are
    closed for these, so its pairs are among the part's)."""
    rp = _Replay(g, r, f"{where}.charged_tree")
    rp.capped_tables()

    def uniform_types() -> Iterator[tuple[int, _Side, _Side]]:
        sides = {c: rp.threshold_side([r + min(c, d) for d in rp.deg]) if c else rp.side
                 for c in range(s)}
        for c2 in range((s - 1) // 2 + 1):
            yield 0, sides[s - 1 - c2], sides[c2]

    def configs() -> Iterator[tuple[int, _Side, _Side]]:
        for Q1, Q2 in _configurations(g.n, s - 1):
            if not Q1:
                yield 0, rp.side, rp.side
                continue
            a, b = (rp.threshold_side([r + (mk & Q).bit_count() for mk in g.inmask], Q)
                    if Q else rp.side for Q in (Q1, Q2))
            yield Q1 | Q2, a, b

    return rp.run(order, tree, uniform_types() if uniform else configs())


def _proof_cost_search(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method", "order"), ("info", "tree", "charged_tree", "uniform"))
    order = _perm(p["order"], f"{where}.order", g.n)
    _info(p, where)
    if "uniform" in p and (p["uniform"] is not True or p.get("charged_tree") is None):
        raise Invalid(f"{where}.uniform must be true, and only with a charged_tree")
    if p.get("charged_tree") is not None:
        if p.get("tree") is not None:
            raise Invalid(f"{where}: 'tree' and 'charged_tree' are exclusive")
        tree = _tokens(p["charged_tree"], f"{where}.charged_tree", g.n, -4 - g.n * g.n)
        stopped = _charged_replay(g, r, s, order, tree, where, "uniform" in p)
        if not stopped:
            return "cost_search (charged tree replayed)"
        return _enumerate_or_trust("cost_search", where, g, r, s, ctx, stopped)
    if p.get("tree") is not None:  # the sized search's tree (cost_tree.py)
        tree = _tokens(p["tree"], f"{where}.tree", g.n)
        if _cost_tree.replay(g.inmask, r, s, order, tree, where):
            return "cost_search (tree replayed)"
        return _enumerate_or_trust("cost_search", where, g, r, s, ctx, "tree beyond the "
                                   f"replay limit ({_cost_tree.MAX_COST_TREE_WORK} steps)")
    return _enumerate_or_trust("cost_search", where, g, r, s, ctx)


def _proof_milp(p: dict, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    _obj(p, where, ("method", "solver"), ("info",))
    if not isinstance(p["solver"], str) or not p["solver"]:
        raise Invalid(f"{where}.solver must be a nonempty string")
    _info(p, where)
    return _enumerate_or_trust("milp", where, g, r, s, ctx)


ProofFn = Callable[[dict, str, Graph, int, int, _Ctx], str]

METHODS: dict[str, ProofFn] = {
    "trivial": _proof_trivial,
    "degree": _proof_degree,
    "complete": _proof_complete,
    "construction": _proof_construction,
    "search": _proof_search,
    "enumeration": _proof_enumeration,
    "dp": _proof_dp,
    "implied": _proof_implied,
    "milp": _proof_milp,
    "cost_search": _proof_cost_search,
    "spectral": _proof_spectral,
}


def _method(p: Any, where: str) -> str:
    if not isinstance(p, dict):
        raise Invalid(f"{where} must be a JSON object, got {_tname(p)}")
    if "method" not in p:
        raise Invalid(f"{where}: missing key 'method'")
    m = p["method"]
    if not isinstance(m, str):
        raise Invalid(f"{where}.method must be a string, got {_tname(m)}")
    return m


def _proof(p: Any, where: str, g: Graph, r: int, s: int, ctx: _Ctx) -> str:
    """Check that PROOF ``p`` proves g is (r, s)-robust; returns a short description.

    ``s`` may exceed g.n inside a construction seed (the definition still makes sense:
    then every pair must contain a fully reachable set)."""
    m = _method(p, where)
    fn = METHODS.get(m)
    if fn is None:
        raise Invalid(f"{where}: unknown proof method '{m}'")
    return fn(p, where, g, r, s, ctx)


# --------------------------------------------------------------------------- #
# kinds: kind -> function
# --------------------------------------------------------------------------- #

_HEAD = ("rescon_certificate", "kind")


def _r_s(c: dict, g: Graph) -> tuple[int, int]:
    r = _int(c["r"], "r", 0)
    s = _int(c["s"], "s", 1, g.n)
    return r, s


def _kind_not_rs_robust(c: dict, ctx: _Ctx) -> str:
    _obj(c, "certificate", _HEAD + ("graph", "r", "s", "witness"))
    g = _graph(c["graph"])
    r, s = _r_s(c, g)
    w = _obj(c["witness"], "witness", ("S1", "S2"))
    S1, S2 = _witness_pair(w, "witness", g)
    _check_violation(g, r, s, S1, S2, "witness")
    return f"G (n={g.n}) is not ({r}, {s})-robust"


def _kind_rs_robust(c: dict, ctx: _Ctx) -> str:
    _obj(c, "certificate", _HEAD + ("graph", "r", "s", "proof"))
    g = _graph(c["graph"])
    r, s = _r_s(c, g)
    how = _proof(c["proof"], "proof", g, r, s, ctx)
    return f"G (n={g.n}) is ({r}, {s})-robust [{how}]"


def _upper(u: Any, where: str, g: Graph, r: int, s: int, allow_half: bool) -> str:
    """UPPER object proving g is not (r, s)-robust."""
    m = _method(u, where)
    if m == "witness":
        _obj(u, where, ("method", "S1", "S2"))
        S1, S2 = _witness_pair(u, where, g)
        _check_violation(g, r, s, S1, S2, where)
        return "witness"
    if m == "half" and allow_half:
        _obj(u, where, ("method",))
        if g.n < 2:
            raise Invalid(f"{where}: method 'half' needs n >= 2 (n = {g.n})")
        h = (g.n + 1) // 2
        if r != h + 1 or s != 1:
            raise Invalid(f"{where}: method 'half' proves only 'not (ceil(n/2) + 1)-robust' = "
                          f"not {h + 1}-robust, but not ({r}, {s})-robust is claimed")
        return "half"
    raise Invalid(f"{where}: unknown method '{m}' (expected 'witness'"
                  + (" or 'half')" if allow_half else ")"))


_S_KEYS = ("s_lower", "s_upper", "lower_s", "upper_s")


def _s_bounds(c: dict, g: Graph, r: int, lo: int, hi: int, ctx: _Ctx) -> None:
    """lower_s proves (r, lo)-robust (null iff lo = 1); upper_s violates (r, hi + 1)
    (null iff hi = n)."""
    if lo > hi:
        raise Invalid(f"s lower bound {lo} > s upper bound {hi}")
    if c["lower_s"] is None:
        if lo != 1:
            raise Invalid(f"lower_s is null but s = {lo} > 1 needs a proof")
    else:
        _proof(c["lower_s"], "lower_s", g, r, lo, ctx)
    if hi == g.n:
        if c["upper_s"] is not None:
            raise Invalid(f"upper_s must be null when the s upper bound is n = {g.n}")
    else:
        if c["upper_s"] is None:
            raise Invalid(f"upper_s is null but the s upper bound {hi} < n = {g.n}")
        _upper(c["upper_s"], "upper_s", g, r, hi + 1, allow_half=False)


def _kind_robustness(c: dict, ctx: _Ctx) -> str:
    if not isinstance(c.get("exact"), bool):
        if "exact" not in c:
            raise Invalid("certificate: missing key 'exact'")
        raise Invalid(f"exact must be a boolean, got {_tname(c['exact'])}")
    if c["exact"]:
        _obj(c, "certificate",
             _HEAD + ("graph", "exact", "r_max", "s_max", "lower", "lower_s", "upper_r",
                      "upper_s"))
        g = _graph(c["graph"])
        r = _int(c["r_max"], "r_max", 0)
        s = _int(c["s_max"], "s_max", 1, g.n)
        if r == 0:
            if s != g.n:
                raise Invalid(f"r_max = 0 requires s_max = n = {g.n}, got s_max = {s}")
            if _method(c["lower"], "lower") != "trivial":
                raise Invalid("r_max = 0 requires lower = {\"method\": \"trivial\"}")
        _proof(c["lower"], "lower", g, r, 1, ctx)
        _upper(c["upper_r"], "upper_r", g, r + 1, 1, allow_half=True)
        _s_bounds(c, g, r, s, s, ctx)
        return f"rho(G) = {r} and s*({r}) = {s} (n={g.n})"
    _obj(c, "certificate", _HEAD + ("graph", "exact", "r_lower", "r_upper", "lower", "upper_r"),
         optional=_S_KEYS)
    g = _graph(c["graph"])
    lo = _int(c["r_lower"], "r_lower", 0)
    hi = _int(c["r_upper"], "r_upper", 0)
    if lo > hi:
        raise Invalid(f"r_lower = {lo} > r_upper = {hi}")
    _proof(c["lower"], "lower", g, lo, 1, ctx)
    _upper(c["upper_r"], "upper_r", g, hi + 1, 1, allow_half=True)
    present = [k for k in _S_KEYS if k in c]
    if not present:
        return f"{lo} <= rho(G) <= {hi} (n={g.n})"
    if len(present) < len(_S_KEYS):
        missing = next(k for k in _S_KEYS if k not in c)
        raise Invalid(f"certificate: missing key '{missing}' (s bounds need all of "
                      f"{', '.join(_S_KEYS)})")
    if lo != hi or lo == 0:
        raise Invalid("s bounds are allowed only when rho is settled (r_lower = r_upper >= 1)")
    s_lo = _int(c["s_lower"], "s_lower", 1, g.n)
    s_hi = _int(c["s_upper"], "s_upper", 1, g.n)
    _s_bounds(c, g, lo, s_lo, s_hi, ctx)
    return f"rho(G) = {lo} and {s_lo} <= s*({lo}) <= {s_hi} (n={g.n})"


def _support_rows(c: dict) -> tuple[int, list[int]]:
    """(n, row) with row[i] = mask of the j with a_ij > 0, validated."""
    n = _size(c["n"], "n")
    sup = _array(c["support"], "support")
    _mask_work(n, len(sup), "support")
    row = [0] * n  # row[i] = mask of the j with a_ij > 0
    for k, e in enumerate(sup):
        w = f"support[{k}]"
        _array(e, w)
        if len(e) != 2:
            raise Invalid(f"{w} must be a pair [i, j], got {len(e)} entries")
        i = _int(e[0], f"{w}[0]", 0, n - 1)
        j = _int(e[1], f"{w}[1]", 0, n - 1)
        if row[i] >> j & 1:
            raise Invalid(f"{w} = [{i}, {j}] is a duplicate")
        row[i] |= 1 << j
    for i in range(n):
        if not row[i]:
            raise Invalid(f"row {i} has no entry in support (a row-stochastic matrix has one)")
    return n, row


def _kind_not_sarymsakov(c: dict, ctx: _Ctx) -> str:
    _obj(c, "certificate", _HEAD + ("n", "support", "witness"))
    n, row = _support_rows(c)
    w = _obj(c["witness"], "witness", ("V1", "V2"))
    V1, V2 = _witness_pair(w, "witness", Graph(n, [], 0), "V1", "V2")
    I1 = I2 = 0
    for i in _bits(V1):
        I1 |= row[i]
    for i in _bits(V2):
        I2 |= row[i]
    if I1 & I2:
        raise Invalid(f"witness: I(V1) and I(V2) intersect at index {_bits(I1 & I2)[0]}")
    cu, cv = (I1 | I2).bit_count(), (V1 | V2).bit_count()
    if cu > cv:
        raise Invalid(f"witness: |I(V1) u I(V2)| = {cu} > |V1 u V2| = {cv}")
    return f"the {n}x{n} matrix is not Sarymsakov"


def _source_components(n: int, pred: list[int]) -> int:
    """Number of source strongly connected components of the digraph whose node i has
    in-neighbour mask pred[i] (iterative Kosaraju on bitmasks)."""
    succ = [0] * n
    for i in range(n):
        for u in _bits(pred[i]):
            succ[u] |= 1 << i
    seen, finish = 0, []
    for v in range(n):
        if seen >> v & 1:
            continue
        seen |= 1 << v
        stack = [(v, succ[v])]
        while stack:
            u, rest = stack[-1]
            rest &= ~seen
            if rest:
                w = (rest & -rest).bit_length() - 1
                stack[-1] = (u, rest & ~(1 << w))
                seen |= 1 << w
                stack.append((w, succ[w]))
            else:
                stack.pop()
                finish.append(u)
    comp = [-1] * n
    ncomp = 0
    for v in reversed(finish):
        if comp[v] >= 0:
            continue
        todo = [v]
        comp[v] = ncomp
        while todo:
            u = todo.pop()
            for w in _bits(pred[u]):
                if comp[w] < 0:
                    comp[w] = ncomp
                    todo.append(w)
        ncomp += 1
    fed = [False] * ncomp
    for i in range(n):
        for u in _bits(pred[i]):
            if comp[u] != comp[i]:
                fed[comp[i]] = True
    return fed.count(False)


MAX_SARYMSAKOV_ENUM_N = 12


def _sarymsakov_unchecked(method: str, n: int, row: list[int], ctx: _Ctx, why: str) -> str:
    """A Sarymsakov claim the checker does not verify. The linear-time witness first: two
    rows i, j with one support entry each, in different columns, fail the condition
    (V1 = {i}, V2 = {j}: I(V1), I(V2) disjoint and |I(V1) u I(V2)| = 2 <= 2)."""
    single: dict[int, int] = {}  # column -> a row whose only entry it is
    for i in range(n):
        if row[i].bit_count() == 1:
            single.setdefault(row[i], i)
            if len(single) == 2:
                i1, i2 = single.values()
                raise Invalid(f"V1 = {{{i1}}}, V2 = {{{i2}}} fail the Sarymsakov condition "
                              "(rows with one entry each, in different columns)")
    ctx.trust(method, f"method '{method}' not checked: {why}")
    return f"Sarymsakov ({method}: not checked)"


def _kind_sarymsakov(c: dict, ctx: _Ctx) -> str:
    """The matrix is Sarymsakov. Method ``matching``: a permutation sigma with
    a_{u,sigma(u)} > 0; then I(V) ⊇ sigma(V), so a failing pair needs I(V_k) = sigma(V_k),
    i.e. each V_k has no in-edge from outside in the digraph D (u -> i iff
    a_{i,sigma(u)} > 0); two disjoint such sets exist iff D has two source components.
    Method ``enumeration`` (n <= 12): all pairs. Method ``min_cut``: trusted."""
    m = _method(c, "certificate")
    if m == "matching":
        _obj(c, "certificate", _HEAD + ("method", "n", "support", "matching"))
        n, row = _support_rows(c)
        sigma = _perm(c["matching"], "matching", n)
        for u, j in enumerate(sigma):
            if not row[u] >> j & 1:
                raise Invalid(f"matching: a[{u}][{j}] is not in the support")
        where = [0] * n
        for u, j in enumerate(sigma):
            where[j] = u  # where[j] = sigma^-1(j)
        pred = [0] * n
        for i in range(n):
            for j in _bits(row[i]):
                if where[j] != i:
                    pred[i] |= 1 << where[j]
        k = _source_components(n, pred)
        if k != 1:
            raise Invalid(f"the matching digraph has {k} source components: not Sarymsakov")
        return f"the {n}x{n} matrix is Sarymsakov (matching)"
    if m == "enumeration":
        _obj(c, "certificate", _HEAD + ("method", "n", "support"))
        n, row = _support_rows(c)
        if n > MAX_SARYMSAKOV_ENUM_N:
            return _sarymsakov_unchecked(
                "enumeration", n, row, ctx,
                f"too large to enumerate (n = {n} > {MAX_SARYMSAKOV_ENUM_N})")
        infl = [0] * (1 << n)  # I(V) for every V
        for V in range(1, 1 << n):
            low = V & -V
            infl[V] = infl[V ^ low] | row[low.bit_length() - 1]
        full = (1 << n) - 1
        for V1 in range(1, 1 << n):
            rest = full & ~V1
            V2 = rest
            while V2:
                if not infl[V1] & infl[V2] and \
                        (infl[V1] | infl[V2]).bit_count() <= (V1 | V2).bit_count():
                    raise Invalid(f"V1 = {_fmt(V1)}, V2 = {_fmt(V2)} fail the Sarymsakov "
                                  "condition (found by enumeration)")
                V2 = (V2 - 1) & rest
        return f"the {n}x{n} matrix is Sarymsakov (enumeration)"
    if m == "min_cut":
        _obj(c, "certificate", _HEAD + ("method", "n", "support"))
        n, row = _support_rows(c)
        return _sarymsakov_unchecked("min_cut", n, row, ctx, "accepted on trust")
    raise Invalid(f"certificate: unknown method '{m}' for kind 'sarymsakov'")


KINDS: dict[str, Callable[[dict, _Ctx], str]] = {
    "not_rs_robust": _kind_not_rs_robust,
    "rs_robust": _kind_rs_robust,
    "robustness": _kind_robustness,
    "not_sarymsakov": _kind_not_sarymsakov,
    "sarymsakov": _kind_sarymsakov,
}


def _sibling(name: str) -> Any:
    """The sibling module ``name``.py (stdlib only; its kinds are bound to the helpers
    above by its ``install``): ``from . import name`` inside the package, otherwise
    (script, or this file loaded by path) loaded from this file's directory."""
    if __package__:
        import importlib
        return importlib.import_module(f".{name}", __package__)
    import importlib.util
    import os
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), f"{name}.py")
    spec = importlib.util.spec_from_file_location(f"{__name__}_{name}", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


_kernels = _sibling("kernels")  # safe kernels
_cost_tree = _sibling("cost_tree")  # s*(r) search trees
_cost_tree.install(Invalid)
KINDS.update(_kernels.install(Invalid, _obj, _int, _array, _tname, unchecked=Unchecked))
KINDS.update(_sibling("redundancy").install(  # redundancy of costs
    Invalid, _obj, _int, _array, _tname, unchecked=Unchecked, rat=_kernels._rat))


def check(cert: Any) -> CheckResult:
    """Check a certificate (the parsed JSON object).  Never raises on bad input."""
    ctx = _Ctx()
    try:
        if not isinstance(cert, dict):
            raise Invalid(f"a certificate must be a JSON object, got {_tname(cert)}")
        if "rescon_certificate" not in cert:
            raise Invalid("certificate: missing key 'rescon_certificate'")
        v = cert["rescon_certificate"]
        if not _is_int(v) or v != FORMAT_VERSION:
            raise Invalid(f"unsupported rescon_certificate version {v!r} "
                          f"(expected {FORMAT_VERSION})")
        if "kind" not in cert:
            raise Invalid("certificate: missing key 'kind'")
        kind = cert["kind"]
        fn = KINDS.get(kind) if isinstance(kind, str) else None
        if fn is None:
            raise Invalid(f"unknown kind {kind!r}")
        what = fn(cert, ctx)
    except Invalid as e:
        return CheckResult(False, str(e))
    except Unchecked as e:
        ctx.trust(e.name, e.part)
        what = e.part
    except RecursionError:
        return CheckResult(False, "proof nested too deeply")
    if ctx.unchecked:
        return CheckResult(False, f"not fully checked: {what}", tuple(ctx.trusted),
                           tuple(ctx.unchecked))
    return CheckResult(True, what)


# --------------------------------------------------------------------------- #
# command line
# --------------------------------------------------------------------------- #


def _no_duplicate_keys(pairs: list[tuple[str, Any]]) -> dict:
    d: dict = {}
    for k, v in pairs:
        if k in d:
            raise ValueError(f"duplicate key {k!r}")
        d[k] = v
    return d


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not JSON")


def _finite_float(text: str) -> float:
    """A JSON number with a fraction or exponent, as a double; one beyond the double range
    (``1e400``) is unreadable, exactly like ``Infinity``, and so is a nonzero one that
    underflows to zero (``1e-400``: read as 0 it would turn a claim about a nonzero
    value into one about 0; subnormal doubles such as ``5e-324`` are read)."""
    x = float(text)
    if not math.isfinite(x):
        raise ValueError(f"the number {text[:40]} overflows a double: like Infinity, "
                         "it is not a finite JSON number")
    if x == 0.0 and text.lower().split("e")[0].strip("-+0.") != "":
        raise ValueError(f"the nonzero number {text[:40]} underflows a double to zero")
    return x


def _json_int(text: str) -> int:
    """A JSON integer of any length: up to the checker's MAX_DIGITS digits converted in
    chunks (``kernels._decimal``: Python's int() refuses more than 4300 digits); a
    longer one, beyond the limit whatever its digits, is read as ±2^(MAX_NUMBER_BITS + 1)
    without converting it — a number every check refuses to work with (a rational:
    unchecked, as any number over the limit; an integer field: out of range)."""
    digits = text.lstrip("-")
    sign = -1 if text.startswith("-") else 1
    if len(digits) > _kernels.MAX_DIGITS:
        return sign << (_kernels.MAX_NUMBER_BITS + 1)
    return sign * _kernels._decimal(digits, "a JSON integer")


def load(path: str) -> dict:
    """Read a certificate file; raises ValueError/OSError if unreadable."""
    with open(path, "rb") as f:
        data = f.read()
    obj = json.loads(data.decode("utf-8"), object_pairs_hook=_no_duplicate_keys,
                     parse_constant=_no_constant, parse_float=_finite_float,
                     parse_int=_json_int)
    if not isinstance(obj, dict):
        raise ValueError(f"top level is a JSON {_tname(obj)}, not an object")  # noqa: TRY004
    return obj


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    if len(args) != 1 or args[0] in ("-h", "--help"):
        print("usage: python certificates/check.py CERT.json", file=sys.stderr)
        return 0 if args[:1] in (["-h"], ["--help"]) else 2
    path = args[0]
    try:
        cert = load(path)
    except (OSError, ValueError, RecursionError) as e:
        print(f"unreadable: {path}: {e}", file=sys.stderr)
        return 2
    res = check(cert)
    if res.verdict == "invalid":
        print(f"invalid: {res.reason}", file=sys.stderr)
        return 1
    print(res.verdict)
    for part in res.unchecked:
        print(f"not checked: {part}")
    return EXIT_CODES[res.verdict]


if __name__ == "__main__":
    sys.exit(main())
