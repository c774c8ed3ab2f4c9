"""Cross-section properties of arbitrary section meshes (scikit-fem, quadratic triangles)."""
from cvtfem.sections.meshes import annulus_mesh, disk_mesh, load_section_mesh, pin_mesh, rectangle_mesh
from cvtfem.sections.properties import SectionProperties, section_properties

__all__ = ["SectionProperties", "annulus_mesh", "disk_mesh", "load_section_mesh", "pin_mesh", "rectangle_mesh",
           "section_properties"]
