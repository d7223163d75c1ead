"""The reference mount (docs/physics.md, section 2): the bundled default case.

A CFM56-class engine (35 kN) hung from the pylon by 8 links and 16 ball-hinge
spring-dampers grouped in 14 pins; heading thrust 23 kN and gravity as the
static loads; the low-pressure (59 Hz, at the fan) and high-pressure
(248.5 Hz, near the centre of gravity) rotor imbalances of 1000 N rotating in
the lateral-vertical plane as the excitations. Every number is chosen and
justified in ``docs/reference-mount.md``.

Origin: on the engine axis in the front-mount plane; x heading (forward),
y lateral, z up (right-handed, so +y is the engine's left seen from behind).
"""
from __future__ import annotations

from typing import Any, Literal, cast, get_args

import numpy as np

from workbook.errors import CaseError
from workbook.model.case import ENGINE, PYLON, AnalysisSettings, Case, Engine, Gravity, Hinge, Link, PointForce, RotatingForce, Rotor, Sweep
from workbook.model.casing import CasingGeometry, EngineCasing, MountRing

__all__ = ["reference_case", "reference_sweep", "reference_casing", "HINGE_STIFFNESS", "HINGE_DAMPING_TIME", "HINGE_LOSS_FACTOR",
           "HINGE_DAMPING_MODELS",
           "LP_ROTOR", "HP_ROTOR", "LP_SPOOL", "HP_SPOOL"]

#: Engine weight 35 kN at g = 9.81 m/s^2, kg.
ENGINE_MASS = 3568.0
#: Centre of gravity: 0.55 m aft of the front mount, 30 mm below the axis
#: (accessory gearbox under the fan case), m.
ENGINE_CG = (-0.55, 0.0, -0.03)
#: Radii of gyration: 0.45 m in roll (rotors and casings of 0.4-0.85 m
#: radius), 0.75 m in pitch and yaw (a 2.5 m long body, L/sqrt(12) = 0.72 m,
#: with the heavy fan forward), m.
ROLL_GYRATION, PITCH_GYRATION = 0.45, 0.75

#: Ball-hinge stiffness (spherical bearing and fitting), N/m.
HINGE_STIFFNESS = 2.0e7
#: Hinge loss factor (structural damping, k (1 + i eta)): bolted and riveted
#: metal joints dissipate 0.02-0.1 of their strain energy per radian of a
#: cycle, nearly independent of frequency (docs/reference-mount.md, Hinges);
#: 0.05 is the middle of that range.
HINGE_LOSS_FACTOR = 0.05
#: The former viscous hinge damping as a stiffness-proportional time constant,
#: d = HINGE_DAMPING_TIME * k, s (``reference_case(hinge_damping="viscous")``).
HINGE_DAMPING_TIME = 1.0e-3
HingeDamping = Literal["loss factor", "viscous"]
#: The hinge damping models of :func:`reference_case`.
HINGE_DAMPING_MODELS: tuple[HingeDamping, ...] = get_args(HingeDamping)

FRONT_X, REAR_X, LATERAL_X, THRUST_FORWARD_X = 0.0, -1.60, -1.72, -0.55

LP_ROTOR = RotatingForce("LP rotor", point=(0.35, 0.0, 0.0), frequency_hz=59.0, amplitude=1000.0)
HP_ROTOR = RotatingForce("HP rotor", point=(-0.70, 0.0, 0.0), frequency_hz=248.5, amplitude=1000.0)

# The spools as gyroscopic rotors (reference_case(rotors=True); off by default).
# LP spool (fan, booster, LP turbine): 24 wide-chord fan blades of about 7 kg
# with a radius of gyration of about 0.5 m (1.55 m fan) give about 42 kg m^2;
# fan disk and spinner (about 100 kg at 0.25 m) 6, the 3-stage booster (about
# 100 kg at 0.4 m) 16, the 4-stage LP turbine (about 250 kg at 0.38 m) 36:
# about 100 kg m^2. HP spool (9-stage compressor and 1-stage turbine, about
# 250 kg at 0.25 m): about 15 kg m^2. Both spools turn clockwise seen from
# behind, i.e. right-handed about +x (heading), like the imbalance forces
# above, at the reference rotor frequencies at once.
LP_SPOOL = Rotor("LP spool", polar_inertia=100.0, frequency_hz=LP_ROTOR.frequency_hz)
HP_SPOOL = Rotor("HP spool", polar_inertia=15.0, frequency_hz=HP_ROTOR.frequency_hz)


def _short_link(length: float, element_size: float | None):
    """Front and rear links: steel, 50 x 40 mm shank, 38 mm eye radius, 19 mm bore."""
    from flexbodies import STEEL, LinkGeometry, LinkModel

    return LinkModel(geometry=LinkGeometry(length=length, eye_outer_radius=0.038, bore_radius=0.019,
                                           thickness=0.040, shank_width=0.050, shank_thickness=0.040),
                     material=STEEL, element_size=element_size)


def _thrust_rod(length: float, element_size: float | None):
    """Thrust rods: titanium, 60 x 50 mm shank, 40 mm eye radius, 20 mm bore."""
    from flexbodies import TITANIUM, LinkGeometry, LinkModel

    return LinkModel(geometry=LinkGeometry(length=length, eye_outer_radius=0.040, bore_radius=0.020,
                                           thickness=0.050, shank_width=0.060, shank_thickness=0.050),
                     material=TITANIUM, element_size=element_size)


def _mirror(point):
    x, y, z = point
    return (x, -y, z)


def _link_points() -> dict[str, tuple]:
    """Eye centres (engine-side or forward eye A, pylon-side or aft eye B) of every link, m."""
    left = {
        "front-left": ((FRONT_X, 0.100, 0.600), (FRONT_X, 0.220, 0.850)),
        "rear-left": ((REAR_X, 0.300, 0.400), (REAR_X, 0.300, 0.660)),
        "thrust-left": ((THRUST_FORWARD_X, 0.180, 0.500), (REAR_X, 0.300, 0.660)),
    }
    points = {}
    for name, (a, b) in left.items():
        points[name] = (a, b)
        points[name.replace("left", "right")] = (_mirror(a), _mirror(b))
    points["rear-middle"] = ((REAR_X, 0.0, 0.460), (REAR_X, 0.0, 0.720))
    points["rear-lateral"] = ((LATERAL_X, 0.130, 0.550), (LATERAL_X, -0.130, 0.550))
    return points


def _links(element_size: float | None) -> tuple[Link, ...]:
    links = []
    for name, (a, b) in _link_points().items():
        length = float(np.linalg.norm(np.subtract(b, a)))
        model = (_thrust_rod if name.startswith("thrust") else _short_link)(length, element_size)
        links.append(Link(name, a, b, model))
    return tuple(links)


def _hinges(damping_model: HingeDamping) -> tuple[Hinge, ...]:
    """16 spring-damper hinges; up = pylon side, down = engine side."""
    if damping_model not in HINGE_DAMPING_MODELS:
        raise CaseError("reference case", "hinge_damping", damping_model, " or ".join(map(repr, HINGE_DAMPING_MODELS)))
    points = _link_points()
    viscous = damping_model == "viscous"
    damping: dict[str, Any] = {"damping": HINGE_DAMPING_TIME * HINGE_STIFFNESS} if viscous else {"loss_factor": HINGE_LOSS_FACTOR}

    def hinge(name: str, body_a: str, body_b: str, point) -> Hinge:
        return Hinge(name, body_a, body_b, point, HINGE_STIFFNESS, **damping)

    hinges = []
    for side in ("left", "right"):
        hinges += [
            hinge(f"front-up-{side}", PYLON, f"front-{side}", points[f"front-{side}"][1]),
            hinge(f"front-down-{side}", ENGINE, f"front-{side}", points[f"front-{side}"][0]),
            hinge(f"rear-up-{side}", PYLON, f"rear-{side}", points[f"rear-{side}"][1]),
            hinge(f"rear-down-{side}", ENGINE, f"rear-{side}", points[f"rear-{side}"][0]),
            hinge(f"thrust-forward-{side}", ENGINE, f"thrust-{side}", points[f"thrust-{side}"][0]),
            # the thrust rod's aft eye rides on the rear link's pylon-side pin
            hinge(f"thrust-aft-{side}", f"rear-{side}", f"thrust-{side}", points[f"thrust-{side}"][1]),
        ]
    for name in ("middle", "lateral"):
        hinges += [
            hinge(f"rear-up-{name}", PYLON, f"rear-{name}", points[f"rear-{name}"][1]),
            hinge(f"rear-down-{name}", ENGINE, f"rear-{name}", points[f"rear-{name}"][0]),
        ]
    return tuple(hinges)


#: The reference casing: a titanium tube of 0.5 m outer radius and 25 mm wall (a
#: smeared flanged and ribbed wall), 2.5 m long around the centre of gravity, with a
#: front mount ring at the front mount plane and a rear one at the lateral link's
#: plane; the rotors sit on it at the fan (LP imbalance plane) and aft of the HP
#: rotor. The engine-side eyes are 0.46-0.64 m from the axis, so the casing is one
#: of core size, not the 0.9 m fan case.
CASING_GEOMETRY = dict(radius=0.5, thickness=0.025, x_start=-1.8, x_end=0.7)
CASING_RINGS = ((FRONT_X, 0.08, 0.62), (LATERAL_X, 0.08, 0.58))
CASING_BEARINGS = (0.35, -1.2)


def reference_casing(element_size: float | None = 0.1, **changes):
    """The reference engine's casing as a flexible body (``Engine.casing``).

    Parameters
    ----------
    element_size : float, optional
        Mesh size, m (None: the flexbodies default, two wall thicknesses).
    **changes
        Other :class:`~workbook.model.casing.EngineCasing` fields.

    Returns
    -------
    EngineCasing
    """
    from flexbodies import TITANIUM

    geometry = CasingGeometry(**CASING_GEOMETRY, rings=tuple(MountRing(*ring) for ring in CASING_RINGS))
    fields = dict(geometry=geometry, material=TITANIUM, element_size=element_size, bearing_band=0.04)
    fields.update(changes)
    return EngineCasing(CASING_BEARINGS, **fields)


def reference_sweep(points: int = 25) -> Sweep:
    """Lateral + vertical rotating 1000 N at the centre of gravity, 5 to 300 Hz."""
    template = RotatingForce("sweep", point=ENGINE_CG, frequency_hz=1.0, amplitude=1000.0)
    return Sweep.band("sweep", template, 5.0, 300.0, points, spacing="log")


def reference_case(*, sweep: bool = False, analysis: AnalysisSettings | None = None,
                   element_size: float | None = None, rotors: bool = False,
                   hinge_damping: HingeDamping = "loss factor") -> Case:
    """The reference mount with the LP and HP rotor cases.

    Parameters
    ----------
    sweep : bool
        Add the lateral + vertical sweep of :func:`reference_sweep`.
    analysis : AnalysisSettings, optional
        Settings other than the defaults.
    element_size : float, optional
        Mesh element size of the links, m (None: the flexbodies default).
    rotors : bool
        Add the LP and HP spools (:data:`LP_SPOOL`, :data:`HP_SPOOL`) as
        gyroscopic rotors; off by default (their inertia is then only lumped
        in the engine, as in the bundled case).
    hinge_damping : {"loss factor", "viscous"}
        The hinges' damping: the loss factor :data:`HINGE_LOSS_FACTOR` (the
        default), or the former viscous model d = :data:`HINGE_DAMPING_TIME` k,
        whose damping grows with the frequency.

    Returns
    -------
    Case
    """
    inertia = ENGINE_MASS * np.diag([ROLL_GYRATION ** 2, PITCH_GYRATION ** 2, PITCH_GYRATION ** 2])
    engine = Engine(ENGINE_MASS, ENGINE_CG, cast(Any, tuple(map(tuple, inertia))))
    static_loads = (PointForce("thrust", force=(23_000.0, 0.0, 0.0), point=(ENGINE_CG[0], 0.0, 0.0)),
                    Gravity("gravity", (0.0, 0.0, -9.81)))
    excitations = (LP_ROTOR, HP_ROTOR) + ((reference_sweep(),) if sweep else ())
    return Case(
        name="reference mount", engine=engine, links=_links(element_size), hinges=_hinges(hinge_damping),
        static_loads=static_loads, excitations=excitations,
        analysis=analysis or AnalysisSettings(), rotors=(LP_SPOOL, HP_SPOOL) if rotors else (),
        description="CFM56-class engine on 8 links and 16 ball hinges (14 pins); see docs/reference-mount.md",
    )
