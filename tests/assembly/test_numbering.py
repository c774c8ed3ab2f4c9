"""Through-numbering of branched networks: pre-order, main chain last, fictitious nodes."""
from __future__ import annotations

import numpy as np

from cvtfem.assembly.numbering import through_numbering


def test_through_numbering_and_fictitious_nodes():
    # main chain 0..9, side branch 10..13 from node 4, branch 14..16 from node 7, twig 17 from 11
    parents = [-1] + list(range(9)) + [4, 10, 11, 12, 7, 14, 15, 11]
    i = np.array([s for s in range(len(parents)) if parents[s] >= 0])
    j = np.array([parents[s] for s in i])
    topo = through_numbering(len(parents), i, j)
    order = topo.order.tolist()
    # pre-order: every parent is numbered before its children
    pos = {s: k for k, s in enumerate(order)}
    assert all(pos[topo.parent[s]] < pos[s] for s in order if topo.parent[s] >= 0)
    # one fictitious node per return from the end of a side branch (3 leaves besides the chain end)
    assert len(topo.fictitious) == 3
    for p in topo.fictitious:
        assert topo.parent[order[p + 1]] != order[p]
    # the root is an end of the longest path (main chain numbered without fictitious jumps)
    assert topo.parent[order[0]] == -1
