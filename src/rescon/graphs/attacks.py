"""Checks users run before a simulation: the attack model and Assumption 2 (SPEC §1).

Graph convention: a DiGraph edge ``(u, v)`` means v receives u's state (u is an
in-neighbour of v); undirected edges count both ways; self-loops are ignored.
"""

from __future__ import annotations

from collections.abc import Hashable, Iterable
from dataclasses import dataclass
from typing import Any

from .._validate import integer
from ..errors import InputError
from .indexed import IndexedGraph, index_graph

__all__ = ["AttackModelReport", "Assumption2Report", "check_attack_model", "check_assumption2"]

_MODELS = ("local", "total")


@dataclass(frozen=True)
class AttackModelReport:
    """Answer of :func:`check_attack_model`.

    Attributes
    ----------
    holds : bool
        The adversary set fits the model.
    model : str
        ``"local"`` or ``"total"``.
    F : int
        The bound checked.
    violations : tuple of (node, tuple of nodes)
        ``"local"``: one entry ``(i, adversarial in-neighbours of i)`` for every
        benign agent i with more than F of them, in node order. ``"total"``: the
        single entry ``(None, all adversaries)`` when there are more than F.
        Empty iff ``holds``.
    """

    holds: bool
    model: str
    F: int
    violations: tuple[tuple[Hashable | None, tuple[Hashable, ...]], ...]


@dataclass(frozen=True)
class Assumption2Report:
    """Answer of :func:`check_assumption2`.

    Attributes
    ----------
    holds : bool
        Every benign agent has at least ``required`` in-neighbours.
    required : int
        :math:`(d + 1)F + 1`.
    violations : tuple of (node, int)
        ``(i, |N_i^in|)`` for every benign agent below ``required``, in node order.
    """

    holds: bool
    required: int
    violations: tuple[tuple[Hashable, int], ...]


def check_attack_model(G: Any, adversaries: Iterable[Hashable], F: int, *,
                       model: str = "local") -> AttackModelReport:
    """Check that an adversary set is F-local or F-total.

    With adversaries :math:`\\mathcal{A}` and benign agents
    :math:`\\mathcal{B} = V \\setminus \\mathcal{A}`:

    * F-local: :math:`|N_i^{in} \\cap \\mathcal{A}| \\le F` for every
      :math:`i \\in \\mathcal{B}`;
    * F-total: :math:`|\\mathcal{A}| \\le F`.

    Parameters
    ----------
    G : networkx.Graph or networkx.DiGraph
        Edge ``(u, v)``: v receives u.
    adversaries : iterable of nodes of G
        Duplicates count once.
    F : int
        Nonnegative bound.
    model : {"local", "total"}

    Returns
    -------
    AttackModelReport

    Raises
    ------
    InputError
        G is not a graph with at least one node, an adversary is not a node of G,
        F is not a nonnegative int, or model is unknown.

    Examples
    --------
    >>> import networkx as nx
    >>> G = nx.DiGraph([(1, 3), (2, 3), (1, 2)])
    >>> check_attack_model(G, [1, 2], 1).violations
    ((3, (1, 2)),)
    """
    ig = index_graph(G, min_nodes=1)
    F = integer("F", F, low=0)
    if model not in _MODELS:
        raise InputError(f"model must be one of {_MODELS}; got {model!r}")
    adv = _adversary_indices(ig, adversaries)
    if model == "total":
        bad = [(None, tuple(ig.labels(adv)))] if len(adv) > F else []
    else:
        bad = [
            (ig.nodes[i], tuple(ig.labels(ig.in_nbrs[i] & adv)))
            for i in range(ig.n)
            if i not in adv and len(ig.in_nbrs[i] & adv) > F
        ]
    return AttackModelReport(holds=not bad, model=model, F=F, violations=tuple(bad))


def check_assumption2(G: Any, d: int, F: int, *,
                      adversaries: Iterable[Hashable] = ()) -> Assumption2Report:
    """Check Assumption 2: every benign agent has :math:`|N_i^{in}| \\ge (d + 1)F + 1`.

    With it, agent i can form the sets Y and Z of :math:`(d + 1)F + 1` received
    points that Algorithm 1 needs, whose safe kernels :math:`\\Psi(Y, F)`,
    :math:`\\Psi(Z, F)` are nonempty by Tverberg's theorem.

    Parameters
    ----------
    G : networkx.Graph or networkx.DiGraph
        Edge ``(u, v)``: v receives u.
    d : int
        State dimension, nonnegative.
    F : int
        Adversary bound, nonnegative.
    adversaries : iterable of nodes of G, optional
        Agents exempt from the check.

    Returns
    -------
    Assumption2Report

    Raises
    ------
    InputError
        G is not a graph with at least one node, d or F is not a nonnegative int,
        or an adversary is not a node of G.

    Examples
    --------
    >>> import networkx as nx
    >>> check_assumption2(nx.complete_graph(7), d=2, F=2).violations
    ((0, 6), (1, 6), (2, 6), (3, 6), (4, 6), (5, 6), (6, 6))
    """
    ig = index_graph(G, min_nodes=1)
    d = integer("d", d, low=0)
    F = integer("F", F, low=0)
    adv = _adversary_indices(ig, adversaries)
    required = (d + 1) * F + 1
    bad = [
        (ig.nodes[i], len(ig.in_nbrs[i]))
        for i in range(ig.n)
        if i not in adv and len(ig.in_nbrs[i]) < required
    ]
    return Assumption2Report(holds=not bad, required=required, violations=tuple(bad))


def _adversary_indices(ig: IndexedGraph, adversaries: Any) -> frozenset[int]:
    if isinstance(adversaries, (str, bytes)) or not isinstance(adversaries, Iterable):
        raise InputError(
            f"adversaries must be an iterable of nodes of G; got {type(adversaries).__name__}"
        )
    pos = {v: i for i, v in enumerate(ig.nodes)}
    out = set()
    for a in adversaries:
        try:
            out.add(pos[a])
        except (KeyError, TypeError):
            raise InputError(f"adversaries contains {a!r}, which is not a node of G") from None
    return frozenset(out)
