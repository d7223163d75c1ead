"""Flexible bodies: scikit-fem models reduced by Craig-Bampton for Exudyn.

The links, the engine casing and the mesh pylon pass through one chain and
share one cache (:class:`~flexbodies.cache.BodyCache`). The pieces, in the
order a link passes through them::

    LinkGeometry / load_mesh  ->  mesh_link  ->  assemble (K, M)
        ->  couple_interfaces (RBE2 / RBE3 master nodes)
        ->  craig_bampton + decide_modes  ->  ReducedBody (file, cached)
        ->  add_link_to_exudyn (ObjectFFRFreducedOrder or rigid body)

:func:`reduce_link` runs the chain for a :class:`LinkModel` with caching;
:func:`reduce_link_set` does it once for several excitations (one
factorisation per link serves them all). The casing's reduction is
:mod:`flexbodies.casing_reduction`, the mesh pylon's
:mod:`flexbodies.pylon_reduction`.
"""
import sys
import types

from workbook._lazy import lazy_names
from workbook._renamed import renamed_names

#: Where each name of the package's API lives. A name is imported on first use (PEP 562), so that
#: ``import flexbodies.cache`` or a run whose links are all cached does not load gmsh and scikit-fem.
_HOMES = {
    "craig_bampton": ("CraigBamptonBasis", "craig_bampton", "elastic_modes"),
    "assembly": ("FEModel", "assemble"),
    "eigen": ("natural_frequencies",),
    "errors": ("LinkModelError", "TangledElements", "ReducedBodyFileError"),
    "exudyn_body": ("ExudynLink", "add_link_to_exudyn", "export_exudyn_file", "link_rotation"),
    "geometry": ("LinkGeometry",),
    "interfaces": ("InterfaceCoupling", "couple_interfaces"),
    "link": ("LinkModel", "MeshSource", "build_fe_model", "default_cache_dir", "reduce_link", "reduce_link_set"),
    "materials": ("STEEL", "TITANIUM", "Material", "material"),
    "bores": ("Bore", "BoreSpec"),
    "meshing": ("BodyMesh", "load_mesh", "mesh_link"),
    "reduced": ("ReducedBody", "load_reduced_body", "save_reduced_body"),
    "selection": ("ModeDecision", "decide_modes"),
}
_lazy_getattr, __dir__, _NAMES = lazy_names(__name__, _HOMES)
#: Former names of the general machinery, kept for one release with a DeprecationWarning.
__getattr__ = renamed_names(__name__, {"ReducedLink": "ReducedBody", "ReducedLinkFileError": "ReducedBodyFileError",
                                       "LinkMesh": "BodyMesh", "load_reduced_link": "load_reduced_body",
                                       "save_reduced_link": "save_reduced_body"}, _lazy_getattr)


class _Package(types.ModuleType):
    """The package's module: the function ``craig_bampton`` keeps its name here when its module
    ``flexbodies.craig_bampton``, of the same name, is imported (which binds the module to the package)."""

    def __setattr__(self, name: str, value) -> None:
        if name == "craig_bampton" and isinstance(value, types.ModuleType):
            value = value.craig_bampton
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

__all__ = list(_NAMES)

