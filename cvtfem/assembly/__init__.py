"""Generic DOF maps and sparse assembly (COO triplets -> CSR in one call)."""
from cvtfem.assembly.sparse import assemble, dof_map_nodes, expand_blocks

__all__ = ["assemble", "dof_map_nodes", "expand_blocks"]
