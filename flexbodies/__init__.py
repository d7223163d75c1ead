"""Flexible connecting links: scikit-fem models reduced by Craig-Bampton for Exudyn.

The pieces, in the order a link passes through them::

    LinkGeometry / load_mesh  ->  mesh_link  ->  assemble (K, M)
        ->  couple_interfaces (RBE2 / RBE3 master nodes)
        ->  craig_bampton + decide_modes  ->  ReducedLink (file, cached)
        ->  add_link_to_exudyn (ObjectFFRFreducedOrder or rigid body)

:func:`reduce_link` runs the chain for a :class:`LinkModel` with caching;
:func:`reduce_link_set` does it once for several excitations (one
factorisation per link serves them all).
"""
from .assembly import FEModel, assemble
from .craig_bampton import CraigBamptonBasis, craig_bampton, elastic_modes
from .eigen import natural_frequencies
from .exudyn_body import ExudynLink, add_link_to_exudyn, export_exudyn_file, link_rotation
from .geometry import LinkGeometry
from .interfaces import InterfaceCoupling, couple_interfaces
from .link import LinkModel, MeshSource, build_fe_model, default_cache_dir, reduce_link, reduce_link_set
from .materials import STEEL, TITANIUM, Material, material
from .meshing import Bore, BoreSpec, LinkMesh, load_mesh, mesh_link
from .reduced import ReducedLink, ReducedLinkFileError, load_reduced_link, save_reduced_link
from .selection import ModeDecision, decide_modes

__all__ = [
    "FEModel", "assemble", "CraigBamptonBasis", "craig_bampton", "elastic_modes",
    "natural_frequencies", "ExudynLink", "add_link_to_exudyn", "export_exudyn_file", "link_rotation",
    "LinkGeometry", "InterfaceCoupling", "couple_interfaces", "LinkModel", "MeshSource",
    "build_fe_model", "default_cache_dir", "reduce_link", "reduce_link_set", "STEEL", "TITANIUM", "Material",
    "material", "Bore", "BoreSpec", "LinkMesh", "load_mesh", "mesh_link", "ReducedLink",
    "ReducedLinkFileError", "load_reduced_link", "save_reduced_link", "ModeDecision", "decide_modes",
]
