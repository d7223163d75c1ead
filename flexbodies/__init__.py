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
import importlib

#: Where each name of the package's API lives. A name is imported on first use (PEP 562), so that
#: ``import flexbodies.cache`` or a run whose links are all cached does not load gmsh and scikit-fem.
_HOMES = {
    "assembly": ("FEModel", "assemble"),
    "eigen": ("natural_frequencies",),
    "errors": ("LinkModelError", "ReducedLinkFileError"),
    "exudyn_body": ("ExudynLink", "add_link_to_exudyn", "export_exudyn_file", "link_rotation"),
    "geometry": ("LinkGeometry",),
    "interfaces": ("InterfaceCoupling", "couple_interfaces"),
    "link": ("LinkModel", "MeshSource", "build_fe_model", "default_cache_dir", "reduce_link", "reduce_link_set"),
    "materials": ("STEEL", "TITANIUM", "Material", "material"),
    "meshing": ("Bore", "BoreSpec", "LinkMesh", "load_mesh", "mesh_link"),
    "reduced": ("ReducedLink", "load_reduced_link", "save_reduced_link"),
    "selection": ("ModeDecision", "decide_modes"),
}
_MODULE_OF = {name: module for module, names in _HOMES.items() for name in names}

# Imported at once: the function ``craig_bampton`` shares its name with its module, which would
# otherwise stand in the package's namespace once any module imported it.
from .craig_bampton import CraigBamptonBasis, craig_bampton, elastic_modes  # noqa: E402

__all__ = ["CraigBamptonBasis", "craig_bampton", "elastic_modes", *_MODULE_OF]


def __getattr__(name: str):
    if name not in _MODULE_OF:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_MODULE_OF[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(__all__))
