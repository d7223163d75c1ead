"""The errors :mod:`flexbodies` raises on purpose.

Each is bad input (exit 2 of the ``mountwb`` command line): they derive
from :class:`workbook.errors.InputError`, the bad-input branch of the one
root of the package's errors, and from :class:`ValueError`. Any other
exception out of :mod:`flexbodies` is a defect, not the user's input.
"""
from __future__ import annotations

from workbook._renamed import renamed_names
from workbook.errors import InputError

__all__ = ["LinkModelError", "TangledElements", "ReducedBodyFileError"]


class LinkModelError(InputError):
    """A link or engine-casing model that cannot be used: its geometry,
    material, mesh (file, cells, bores, node sets), interfaces or mode
    selection. The message names the item and what was expected."""


class TangledElements(LinkModelError):
    """Elements whose Jacobian determinant vanishes or changes sign inside.

    Attributes
    ----------
    count, total : int
        Tangled elements, and all elements of the mesh.
    """

    def __init__(self, message: str, count: int, total: int):
        super().__init__(message)
        self.count, self.total = count, total


class ReducedBodyFileError(InputError):
    """A reduced-body file that cannot be trusted: unreadable, incomplete, altered or of another version."""


__getattr__ = renamed_names(__name__, {"ReducedLinkFileError": "ReducedBodyFileError"})
