"""Through-numbering of branched networks (spec section 8.1): the order the block sweep needs.

A branched (tree) network is written as a main chain with side branches in one
through-numbering: the nodes in depth-first pre-order, main chain last at every
branch node.  Where two consecutive numbers are not joined by a link the
source inserts a *fictitious* node (zero mass, zero stiffness);
:func:`through_numbering` reports these positions.
"""
from __future__ import annotations

from collections import deque
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Topology:
    """Rooted forest of a network (ground links excluded).

    Attributes
    ----------
    order : ndarray (S,) int
        Through-numbering: node indices in depth-first pre-order.
    parent : ndarray (S,) int
        Parent node of each node (-1 for roots).
    parent_link : ndarray (S,) int
        Link joining each node to its parent (-1 for roots).
    fictitious : tuple of int
        Positions p in ``order`` after which the source inserts a fictitious
        node (``order[p + 1]`` is not linked to ``order[p]``).
    """

    order: np.ndarray
    parent: np.ndarray
    parent_link: np.ndarray
    fictitious: tuple[int, ...]


def _farthest(start: int, adj: list[list[tuple[int, int]]]) -> tuple[int, dict[int, int]]:
    dist = {start: 0}
    queue = deque([start])
    last = start
    while queue:
        u = queue.popleft()
        last = u
        for v, _ in adj[u]:
            if v not in dist:
                dist[v] = dist[u] + 1
                queue.append(v)
    return last, dist


def through_numbering(n_nodes: int, i: np.ndarray, j: np.ndarray,
                      prefer: np.ndarray | None = None) -> Topology | None:
    """Root each tree at one end of its longest path and number it (spec 8.1, B fig. 2).

    Parameters
    ----------
    n_nodes : int
    i, j : ndarray (E,) int
        Link ends; links with ``j = -1`` (ground) are not edges of the tree.
    prefer : ndarray (S,) bool, optional
        Nodes to root at instead (the first in each tree).  Rooting at a node of
        a nonlinear link keeps the blocks of linear side trees diagonal during
        the sweep (they fill only on the way to the root).

    Returns
    -------
    Topology, or None when the link graph has a loop (use sparse LU).
    """
    adj: list[list[tuple[int, int]]] = [[] for _ in range(n_nodes)]
    n_edges = 0
    for e, (a, b) in enumerate(zip(i.tolist(), j.tolist())):
        if b >= 0:
            adj[a].append((b, e))
            adj[b].append((a, e))
            n_edges += 1
    parent = np.full(n_nodes, -1)
    parent_link = np.full(n_nodes, -1)
    order: list[int] = []
    seen = np.zeros(n_nodes, bool)
    n_components = 0
    for start in range(n_nodes):
        if seen[start]:
            continue
        n_components += 1
        root, dist = _farthest(start, adj)
        if prefer is not None and prefer[list(dist)].any():
            root = min(u for u in dist if prefer[u])
        _, dist = _farthest(root, adj)
        # height of each subtree decides the main chain (deepest child last)
        height = {u: 0 for u in dist}
        for u in sorted(dist, key=dist.get, reverse=True):
            for v, _ in adj[u]:
                if dist[v] == dist[u] + 1:
                    height[u] = max(height[u], height[v] + 1)
        stack = [root]
        seen[root] = True
        while stack:
            u = stack.pop()
            order.append(u)
            children = [(v, e) for v, e in adj[u] if not seen[v]]
            children.sort(key=lambda ve: height[ve[0]])  # main chain visited last
            for v, e in reversed(children):
                seen[v] = True
                parent[v], parent_link[v] = u, e
                stack.append(v)
    if n_edges != n_nodes - n_components:
        return None
    order_arr = np.array(order)
    fict = tuple(p for p in range(n_nodes - 1) if parent[order_arr[p + 1]] != order_arr[p])
    return Topology(order_arr, parent, parent_link, fict)
