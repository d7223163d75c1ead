"""Limit load cases: named static loads on the engine, each checked for the links' strength.

A :class:`LoadCase` replaces the case's static loads for one static solve
(:mod:`workbook.solve.load_cases`): thrust along the engine axis, manoeuvre
load factors on the mass of every body, an engine torque about the axis and
any point forces and moments, at *limit* level; the factor of safety turns
them into ultimate loads for the ultimate margins. A fail-safe load case
removes one link (and its hinges) first.

Units: N, N m, m; load factors in g (:data:`STANDARD_GRAVITY`). Axes as the
case's: x heading, y lateral, z up.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from workbook.errors import CaseError
from workbook.model import fields
from workbook.model.field_spec import check_fields, documented, spec
from workbook.model.units import DIMENSIONLESS

__all__ = ["LoadCase", "STANDARD_GRAVITY", "DEFAULT_FACTOR_OF_SAFETY", "reference_load_cases"]

#: Standard gravity g0, m/s^2 (ISO 80000-3).
STANDARD_GRAVITY = 9.80665
#: Ultimate over limit load (CS 25.303 / 14 CFR 25.303).
DEFAULT_FACTOR_OF_SAFETY = 1.5


def _set(obj, name, value) -> None:
    object.__setattr__(obj, name, value)


@documented
@dataclass(frozen=True)
class LoadCase:
    """A named static limit load case."""

    name: str = field(metadata=spec("Unique name", type="str", check="own"))
    thrust: float = field(default=0.0, metadata=spec(
        "Engine thrust along +x (negative: reverse thrust), acting at *thrust_point*", unit="N",
        help="thrust along +x (negative: reverse thrust) (empty: 0)"))
    load_factors: tuple = field(default=(0.0, 0.0, -1.0), metadata=spec(
        "Load factors ``(n_x, n_y, n_z)`` in g: every body (engine and links) carries its mass times ``g0 n``; "
        "``(0, 0, -1)`` is the 1 g weight of level flight, ``(0, 0, -2.5)`` a 2.5 g pull-up",
        type="3 floats", check="vector3", unit=DIMENSIONLESS,
        help="load factor in g on every body; empty: 0 in x and y, -1 in z (1 g level flight)"))
    torque: float = field(default=0.0, metadata=spec("Engine torque about +x on the engine", unit="N*m",
                                                     help="engine torque about +x (empty: 0)"))
    forces: tuple = field(default=(), metadata=spec("Further point forces on the engine, N at m",
                                                    type="tuple of PointForce", check="own"))
    moments: tuple = field(default=(), metadata=spec("Further moments on the engine, N m",
                                                     type="tuple of PointMoment", check="own"))
    factor_of_safety: float = field(default=DEFAULT_FACTOR_OF_SAFETY, metadata=spec(
        "Ultimate load over limit load", check="own", unit=DIMENSIONLESS, minimum=1.0,
        help="ultimate over limit load, >= 1 (empty: 1.5)"))
    without_link: str | None = field(default=None, metadata=spec(
        "Fail-safe: the link removed, with its hinges, for this load case", type="str", check="own",
        optional=True))
    thrust_point: tuple | None = field(default=None, metadata=spec(
        "Where the thrust acts (None: the engine's centre of gravity)", type="3 floats", check="vector3",
        unit="m", optional=True, help="where the thrust acts (empty: the engine's CG)"))
    description: str = field(default="", metadata=spec("Free text: where the numbers come from", type="str",
                                                       check="own"))

    def __post_init__(self):
        from workbook.model.case import PointForce, PointMoment

        fields.nonempty_name("load case", self.name)
        item = f"load case {self.name!r}"
        check_fields(self, item)
        fos = fields.number(item, "factor_of_safety", self.factor_of_safety)
        if fos < 1.0:
            raise CaseError(item, "factor_of_safety", self.factor_of_safety, "a factor of safety >= 1")
        _set(self, "factor_of_safety", fos)
        for name, kind in (("forces", PointForce), ("moments", PointMoment)):
            items = tuple(getattr(self, name))
            for entry in items:
                if not isinstance(entry, kind):
                    raise CaseError(item, name, entry, f"a {kind.__name__}")
            _set(self, name, items)
        if self.without_link is not None and not (isinstance(self.without_link, str) and self.without_link.strip()):
            raise CaseError(item, "without_link", self.without_link, "a link name or None")

    def check(self, links) -> None:
        """Refuse a fail-safe link that is not one of *links* (names), naming the load case."""
        if self.without_link is not None and self.without_link not in links:
            raise CaseError(f"load case {self.name!r}", "without_link", self.without_link,
                            f"one of the case's links ({', '.join(links)})")

    def static_loads(self, engine) -> tuple:
        """The load case as the case's static loads (PointForce, PointMoment, Gravity).

        Parameters
        ----------
        engine : Engine
            Gives the default thrust point (its centre of gravity).
        """
        from workbook.model.case import Gravity, PointForce, PointMoment

        loads: list = []
        if self.thrust:
            point = self.thrust_point if self.thrust_point is not None else engine.center_of_mass
            loads.append(PointForce(f"{self.name}: thrust", (self.thrust, 0.0, 0.0), point))
        if any(self.load_factors):
            loads.append(Gravity(f"{self.name}: load factors",
                                 tuple(STANDARD_GRAVITY * n for n in self.load_factors)))
        if self.torque:
            loads.append(PointMoment(f"{self.name}: torque", (self.torque, 0.0, 0.0)))
        loads += [PointForce(f"{self.name}: {f.name}", f.force, f.point) for f in self.forces]
        loads += [PointMoment(f"{self.name}: {m.name}", m.moment) for m in self.moments]
        return tuple(loads)


#: Take-off thrust of the reference engine, N: an engine of its mass (3.6 t) in the
#: CFM56-7B class (about 120 kN rated); its cruise thrust in the case is 23 kN.
REFERENCE_TAKEOFF_THRUST = 110e3
#: Take-off torque reacted by the reference engine's mounts about its axis, N m (an assumed value).
REFERENCE_TORQUE = 30e3


def reference_load_cases() -> tuple[LoadCase, ...]:
    """The limit load cases the docs report for the reference mount.

    Illustrative numbers in the spirit of CS-25 (not a certification set):
    1 g cruise; take-off (thrust and torque); the 2.5 g pull-up of CS 25.337;
    the 1.33 g side load of CS 25.363; and take-off with the rear middle
    link failed (fail-safe). Factor of safety 1.5 throughout.
    """
    cruise = 23e3
    return (
        LoadCase("cruise 1 g", thrust=cruise, description="cruise thrust, 1 g"),
        LoadCase("take-off", thrust=REFERENCE_TAKEOFF_THRUST, torque=REFERENCE_TORQUE,
                 description="take-off thrust and torque, 1 g"),
        LoadCase("pull-up 2.5 g", thrust=cruise, load_factors=(0.0, 0.0, -2.5),
                 description="CS 25.337 positive limit manoeuvre load factor"),
        LoadCase("side 1.33 g", thrust=cruise, load_factors=(0.0, 1.33, -1.0),
                 description="CS 25.363 side load on the engine mount, with 1 g"),
        LoadCase("take-off, rear-middle failed", thrust=REFERENCE_TAKEOFF_THRUST, torque=REFERENCE_TORQUE,
                 without_link="rear-middle", description="fail-safe: take-off with the rear middle link removed"),
    )
