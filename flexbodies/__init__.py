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
import sys
import types

from workbook._lazy import lazy_names

#: Where each name of the package's API lives. A name is imported on first use (PEP 562), so that
#: ``import flexbodies.cache`` or a run whose links are all cached does not load gmsh and scikit-fem.
_HOMES = {
    "craig_bampton": ("CraigBamptonBasis", "craig_bampton", "elastic_modes"),
    "assembly": ("FEModel", "assemble"),
    "eigen": ("natural_frequencies",),
    "errors": ("LinkModelError", "TangledElements", "ReducedLinkFileError"),
    "exudyn_body": ("ExudynLink", "add_link_to_exudyn", "export_exudyn_file", "link_rotation"),
    "geometry": ("LinkGeometry",),
    "interfaces": ("InterfaceCoupling", "couple_interfaces"),
    "link": ("LinkModel", "MeshSource", "build_fe_model", "default_cache_dir", "reduce_link", "reduce_link_set"),
    "materials": ("STEEL", "TITANIUM", "Material", "material"),
    "bores": ("Bore", "BoreSpec"),
    "meshing": ("LinkMesh", "load_mesh", "mesh_link"),
    "reduced": ("ReducedLink", "load_reduced_link", "save_reduced_link"),
    "selection": ("ModeDecision", "decide_modes"),
}
__getattr__, __dir__, _NAMES = lazy_names(__name__, _HOMES)


class _Package(types.ModuleType):
    """The package's module: the function ``craig_bampton`` keeps its name here when its module
    ``flexbodies.craig_bampton``, of the same name, is imported (which binds the module to the package)."""

    def __setattr__(self, name: str, value) -> None:
        if name == "craig_bampton" and isinstance(value, types.ModuleType):
            value = value.craig_bampton
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

__all__ = list(_NAMES)

