"""Put a reduced link into an Exudyn system.

The link is placed from its two eye centres: its frame origin sits at eye A,
its x axis points at eye B, its z axis (the bore axis) is the requested
``bore_axis`` made perpendicular. A flexible link becomes an
``ObjectFFRFreducedOrder`` (C++ path; Euler-parameter frame node); a rigid
link an ``ObjectRigidBody`` with the same mass properties. Either way the
link gets one position marker per eye, on the master node only (markers on
every bore node were measured 3-8 x slower).

A link with ball joints at both eyes can spin freely about its own axis, and
a static solve then fails or returns absurd forces. A torsional spring to
ground about the link axis removes that motion; its stiffness is chosen
from the link's spin inertia so that it adds one mode at
``spin_frequency_hz``. The default puts that mode at 2 kHz, well above the
rotor excitations (59 and 248.5 Hz) and the mount's modes. A restraint soft
enough to sit below the band (1-2 Hz, 0.02-0.07 N m/rad on the test link)
made Exudyn's Newton iteration diverge along the spin direction in several
of the placements tried; from 100 Hz up every one converged. Ball hinges pass no
moment and the spin does not move the hinge points, so no hinge force
depends on it.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import LinkModelError
from .reduced import ReducedBody

__all__ = ["ExudynLink", "add_link_to_exudyn", "exudyn_cms_interface", "modal_damping_matrix", "export_exudyn_file",
           "link_rotation", "DEFAULT_SPIN_FREQUENCY_HZ"]

#: Frequency of the spin mode the torsional restraint adds, Hz.
DEFAULT_SPIN_FREQUENCY_HZ = 2000.0
#: A link whose eye distance differs more than this from its end points is rejected, m.
LENGTH_TOLERANCE = 1e-6


@dataclass(frozen=True)
class ExudynLink:
    """Item numbers of a link in an Exudyn system.

    Attributes
    ----------
    name : str
    flexible : bool
    body : int
        ``ObjectFFRFreducedOrder`` or ``ObjectRigidBody`` number.
    nodes : tuple of int
        Frame (rigid-body) node, then the modal node of a flexible link.
    marker_a, marker_b : int
        Position markers at the eye centres.
    spin_restraint : int
        ``ObjectConnectorTorsionalSpringDamper`` number.
    spin_stiffness : float
        Torsional stiffness of the restraint, N m/rad.
    spin_frequency_hz : float
        Frequency of the spin mode it adds, Hz.
    dof : int
        Degrees of freedom of the body (6 + modal coordinates).
    mass : float
        kg.
    rotation : ndarray, shape (3, 3)
        Link frame to global.
    """

    name: str
    flexible: bool
    body: int
    nodes: tuple
    marker_a: int
    marker_b: int
    spin_restraint: int
    spin_stiffness: float
    spin_frequency_hz: float
    dof: int
    mass: float
    rotation: np.ndarray


def link_rotation(end_a, end_b, bore_axis=None) -> np.ndarray:
    """Rotation from the link frame to global coordinates.

    Parameters
    ----------
    end_a, end_b : array_like, shape (3,)
        Global positions of the eye centres, m.
    bore_axis : array_like, shape (3,), optional
        Wanted direction of the bore axis (link z). Default: global x
        (heading), or global y when the link itself runs along x.

    Returns
    -------
    ndarray, shape (3, 3)
        Columns are the link's x, y, z axes in global coordinates.
    """
    ex = np.asarray(end_b, dtype=float) - np.asarray(end_a, dtype=float)
    ex /= np.linalg.norm(ex)
    if bore_axis is None:
        bore_axis = [1.0, 0.0, 0.0] if abs(ex[0]) < 0.9 else [0.0, 1.0, 0.0]
    ez = np.asarray(bore_axis, dtype=float)
    ez = ez - ex * (ez @ ex)
    norm = np.linalg.norm(ez)
    if norm < 1e-6:
        raise LinkModelError(f"bore axis {list(bore_axis)} is parallel to the link axis {list(np.round(ex, 6))}")
    ez /= norm
    return np.column_stack([ex, np.cross(ez, ex), ez])


def _homogeneous(rotation, translation) -> np.ndarray:
    H = np.eye(4)
    H[:3, :3] = rotation
    H[:3, 3] = translation
    return H


#: Marker frame whose z axis is the link (node) x axis.
_SPIN_AXIS_FRAME = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def exudyn_cms_interface(body: ReducedBody, node_type: str = "NodeType.RotationEulerParameters"):
    """Exudyn's ``ObjectFFRFreducedOrderInterface`` filled from a reduced body (a link, the casing).

    Parameters
    ----------
    body : ReducedBody
    node_type : str
        Rotation parametrisation of the frame node (Euler parameters by default).

    Returns
    -------
    exudyn.FEM.ObjectFFRFreducedOrderInterface
        Ready for ``AddObjectFFRFreducedOrder`` or ``SaveToFile``.
    """
    from exudyn.FEM import ObjectFFRFreducedOrderInterface

    from .reduced import FFRF_KEYS

    n_rot = 4 if node_type.endswith("EulerParameters") else 3
    cms = ObjectFFRFreducedOrderInterface()
    data = {key: body.ffrf[key] for key in FFRF_KEYS}
    data.update(
        modeBasis=body.mode_basis,
        trigList=[],
        postProcessingModes={},
        rigidBodyNodeType=node_type,
        infoList=np.array([body.n_modes, len(body.nodes), 3, n_rot, 3 + n_rot, 3 + n_rot + body.n_modes]),
    )
    cms.SetWithDictionary(data)
    # Exudyn takes the triangles as an array as well; its own reader turns them into a list of lists,
    # which cost more than the rest of adding a body to a scene
    cms.trigList = body.surface_triangles
    return cms


def modal_damping_matrix(body: ReducedBody, ratio: float) -> np.ndarray:
    """Damping of a reduced body's modal coordinates that gives each elastic mode the damping ratio *ratio*.

    The body's modal coordinates are mass-normalised modes with a diagonal
    reduced stiffness, so the matrix is ``diag(2 zeta w_i)``, N s/m per unit
    modal mass (``w_i`` from the reduced stiffness, rad/s).
    """
    stiffness = np.diag(np.asarray(body.ffrf["stiffnessMatrixReduced"], dtype=float))
    mass = np.diag(np.asarray(body.ffrf["massMatrixReduced"], dtype=float))
    return np.diag(2.0 * ratio * np.sqrt(np.clip(stiffness, 0.0, None) * mass))


def _add_flexible(mbs, link: ReducedBody, position, rotation, stiffness_damping, mass_damping, modal_ratio, name):
    import exudyn as exu

    cms = exudyn_cms_interface(link)
    items = cms.AddObjectFFRFreducedOrder(
        mbs, positionRef=list(position), rotationMatrixRef=rotation,
        stiffnessProportionalDamping=stiffness_damping, massProportionalDamping=mass_damping,
        name=name,
    )
    body = items["oFFRFreducedOrder"]
    if modal_ratio > 0:
        damping = exu.MatrixContainer()
        damping.SetWithDenseMatrix(np.asarray(cms.dampingMatrixReduced, dtype=float)
                                   + modal_damping_matrix(link, modal_ratio), useDenseMatrix=False)
        mbs.SetObjectParameter(body, "dampingMatrixReduced", damping)
    markers = [
        mbs.AddMarker(exu.itemInterface.MarkerSuperElementPosition(
            bodyNumber=body, meshNodeNumbers=[int(i)], weightingFactors=[1.0]))
        for i in link.master_nodes[:2]
    ]
    return body, (items["nRigidBody"], items["nGenericODE2"]), markers


def _add_rigid(mbs, link: ReducedBody, position, rotation, name):
    import exudyn as exu
    from exudyn.rigidBodyUtilities import RotationMatrix2EulerParameters

    eii = exu.itemInterface
    node = mbs.AddNode(eii.NodeRigidBodyEP(
        referenceCoordinates=list(position) + list(RotationMatrix2EulerParameters(rotation)),
        name=f"NodeRigidBody:{name}" if name else "",
    ))
    inertia = link.inertia_at_origin
    body = mbs.AddObject(eii.ObjectRigidBody(
        name=name, nodeNumber=node, mass=link.mass, centerOfMass=list(link.centre_of_mass),
        inertia=[inertia[0, 0], inertia[1, 1], inertia[2, 2], inertia[1, 2], inertia[0, 2], inertia[0, 1]],
    ))
    markers = [
        mbs.AddMarker(eii.MarkerBodyPosition(bodyNumber=body, localPosition=list(link.master_position(i))))
        for i in range(2)
    ]
    return body, (node,), markers


def add_link_to_exudyn(
    mbs,
    link: ReducedBody,
    end_a,
    end_b,
    *,
    flexible: bool = True,
    bore_axis=None,
    stiffness_damping: float = 0.0,
    mass_damping: float = 0.0,
    modal_damping_ratio: float = 0.0,
    spin_frequency_hz: float = DEFAULT_SPIN_FREQUENCY_HZ,
    name: str = "",
) -> ExudynLink:
    """Add a reduced link between two eye centres.

    Parameters
    ----------
    mbs : exudyn.MainSystem
    link : ReducedBody
    end_a, end_b : array_like, shape (3,)
        Global positions of the centres of eye A and eye B, m. Their distance
        must equal the link's eye distance.
    flexible : bool
        Flexible (``ObjectFFRFreducedOrder``) or rigid body.
    bore_axis : array_like, optional
        Wanted bore-axis direction, see :func:`link_rotation`.
    stiffness_damping : float
        Rayleigh stiffness-proportional damping of the modal coordinates, s.
    mass_damping : float
        Rayleigh mass-proportional damping of the modal coordinates, 1/s.
    modal_damping_ratio : float
        Damping ratio of every elastic mode, added to the Rayleigh damping
        (:func:`modal_damping_matrix`), dimensionless.
    spin_frequency_hz : float
        Frequency of the spin mode the torsional restraint adds, Hz.
    name : str
        Name of the Exudyn items.

    Returns
    -------
    ExudynLink
    """
    import exudyn as exu

    eii = exu.itemInterface
    end_a = np.asarray(end_a, dtype=float)
    end_b = np.asarray(end_b, dtype=float)
    distance = float(np.linalg.norm(end_b - end_a))
    if abs(distance - link.length) > LENGTH_TOLERANCE:
        raise LinkModelError(
            f"link {name!r}: its eyes are {link.length * 1e3:.3f} mm apart but its end points "
            f"are {distance * 1e3:.3f} mm apart"
        )
    if not spin_frequency_hz > 0:
        raise LinkModelError(f"link {name!r}: spin_frequency_hz must be > 0, got {spin_frequency_hz}")
    rotation = link_rotation(end_a, end_b, bore_axis)
    if flexible:
        body, nodes, markers = _add_flexible(mbs, link, end_a, rotation, stiffness_damping, mass_damping,
                                             modal_damping_ratio, name)
    else:
        body, nodes, markers = _add_rigid(mbs, link, end_a, rotation, name)

    spin_inertia = float(link.inertia_at_origin[0, 0])
    spin_stiffness = spin_inertia * (2 * np.pi * spin_frequency_hz) ** 2
    ground = mbs.AddObject(eii.ObjectGround(referencePosition=list(end_a)))
    m_link = mbs.AddMarker(eii.MarkerNodeRigid(nodeNumber=nodes[0], localHT=_homogeneous(_SPIN_AXIS_FRAME, np.zeros(3))))
    m_ground = mbs.AddMarker(eii.MarkerBodyRigid(bodyNumber=ground, localHT=_homogeneous(rotation @ _SPIN_AXIS_FRAME, np.zeros(3))))
    spin = mbs.AddObject(eii.ObjectConnectorTorsionalSpringDamper(
        markerNumbers=[m_link, m_ground], stiffness=spin_stiffness,
        visualization=eii.VObjectConnectorTorsionalSpringDamper(show=False),
    ))
    return ExudynLink(
        name=name, flexible=flexible, body=body, nodes=nodes,
        marker_a=markers[0], marker_b=markers[1], spin_restraint=spin,
        spin_stiffness=spin_stiffness, spin_frequency_hz=float(spin_frequency_hz),
        dof=link.dof if flexible else 6, mass=link.mass, rotation=rotation,
    )


def export_exudyn_file(link: ReducedBody, path) -> Path:
    """Write a reduced link in Exudyn's own reduced-body format.

    A plain Exudyn script loads it without this package::

        from exudyn.FEM import ObjectFFRFreducedOrderInterface
        cms = ObjectFFRFreducedOrderInterface()
        cms.LoadFromFile("link.npz")
        cms.AddObjectFFRFreducedOrder(mbs, positionRef=..., rotationMatrixRef=...)

    The last two nodes are the master nodes of eye A and eye B, for
    ``MarkerSuperElementPosition`` markers.

    Parameters
    ----------
    link : ReducedBody
    path : str or Path
        Target file; ``.npz`` is appended when missing.

    Returns
    -------
    Path
        The file written.
    """
    from pathlib import Path

    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    path.parent.mkdir(parents=True, exist_ok=True)
    exudyn_cms_interface(link).SaveToFile(str(path))
    return path
