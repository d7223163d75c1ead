"""Linear elastic, isotropic materials for the flexible links (SI units)."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from .errors import LinkModelError

__all__ = ["Material", "STEEL", "TITANIUM", "material", "STRENGTH_FIELDS", "FATIGUE_FIELDS", "sn_line_exponent"]

#: The S-N curve's fields of a :class:`Material`: the knee's cycles and the Basquin exponent.
FATIGUE_FIELDS = ("endurance_cycles", "fatigue_exponent")
#: The scalar strength fields of a :class:`Material` (one Links-sheet column each).
STRENGTH_FIELDS = ("yield_strength", "ultimate_strength", "endurance_strength", *FATIGUE_FIELDS)
#: Fields of a :class:`Material` no reduction depends on (left out of a link's fingerprint).
_NOT_ELASTIC = (*STRENGTH_FIELDS, "haigh_curve")


@dataclass(frozen=True)
class Material:
    """An isotropic linear elastic material.

    Parameters
    ----------
    name : str
        Name used in reports and for :func:`material` look-up.
    youngs_modulus : float
        Young's modulus E in Pa; must be positive.
    poisson_ratio : float
        Poisson's ratio nu (dimensionless); must satisfy -1 < nu < 0.5.
    density : float
        Mass density rho in kg/m^3; must be positive.
    yield_strength : float or None
        Tensile yield strength (0.2 % proof) in Pa, for the margins of
        safety at limit load (:mod:`flexbodies.stress`); None: not known.
    ultimate_strength : float or None
        Tensile ultimate strength in Pa, for the margins at ultimate load;
        None: not known. At least the yield strength.
    endurance_strength : float or None
        Fully reversed (R = -1) fatigue strength of unnotched specimens at
        10^7 cycles or more, in Pa, for the fatigue safety factors
        (:mod:`workbook.solve.fatigue`); None: not known. At most the
        ultimate strength.
    endurance_cycles : float or None
        Cycles N_e at the knee of the S-N curve, where the endurance
        strength is reached (None: not known).
    fatigue_exponent : float or None
        Basquin exponent b < 0 of the finite-life S-N curve
        ``sigma_a = S_e (N / N_e)^b`` for ``N < N_e`` (Basquin's
        ``sigma_f' (2N)^b`` with ``sigma_f' = S_e (2 N_e)^-b``); None: not
        known. Both are needed for a Miner damage sum
        (:mod:`workbook.solve.fatigue`).
    haigh_curve : tuple of (float, float) or None
        The material's Haigh diagram: the allowable ``(mean, alternating)``
        stress amplitudes, Pa, as a polyline from the alternating axis
        ``(0, S_a0)`` to the mean axis ``(S_m, 0)`` (e.g. ``(0, S_e)`` to
        ``(S_u, 0)`` through measured points): means strictly increasing,
        alternating stresses not increasing and positive but the last, which is
        zero. It is not extrapolated: a load line meets it between its ends.
        Compressive means get no credit (the curve's value at zero mean, as
        the Goodman and Gerber factors do). For the Haigh factor
        (:func:`flexbodies.stress.haigh_factor`); None: not given.

    Raises
    ------
    ValueError
        If a value is not finite or lies outside its physical range.
    """

    name: str
    youngs_modulus: float
    poisson_ratio: float
    density: float
    yield_strength: float | None = None
    ultimate_strength: float | None = None
    endurance_strength: float | None = None
    endurance_cycles: float | None = None
    fatigue_exponent: float | None = None
    haigh_curve: tuple | None = None

    def __post_init__(self):
        if self.haigh_curve is not None:
            object.__setattr__(self, "haigh_curve", _checked_haigh_curve(self.name, self.haigh_curve))
        _check_positive(self.name, "Young's modulus", self.youngs_modulus, "Pa")
        _check_positive(self.name, "density", self.density, "kg/m^3")
        for what in ("yield_strength", "ultimate_strength", "endurance_strength", "endurance_cycles"):
            if getattr(self, what) is not None:
                _check_positive(self.name, what.replace("_", " "), getattr(self, what), "Pa")
        if (self.yield_strength is not None and self.ultimate_strength is not None
                and self.ultimate_strength < self.yield_strength):
            raise LinkModelError(f"material {self.name!r}: the ultimate strength ({self.ultimate_strength!r} Pa) "
                                 f"is below the yield strength ({self.yield_strength!r} Pa)")
        if (self.endurance_strength is not None and self.ultimate_strength is not None
                and self.endurance_strength > self.ultimate_strength):
            raise LinkModelError(f"material {self.name!r}: the endurance strength ({self.endurance_strength!r} Pa) "
                                 f"is above the ultimate strength ({self.ultimate_strength!r} Pa)")
        b = self.fatigue_exponent
        if b is not None and not (isinstance(b, (int, float)) and math.isfinite(b) and -1.0 < b < 0.0):
            raise LinkModelError(f"material {self.name!r}: the fatigue exponent (Basquin b) must lie between -1 and 0, "
                                 f"got {b!r}")
        nu = self.poisson_ratio
        if not (math.isfinite(nu) and -1.0 < nu < 0.5):
            raise LinkModelError(
                f"material {self.name!r}: Poisson's ratio must lie strictly between -1 and 0.5 "
                f"(0.5 would be incompressible), got {nu!r}"
            )

    @property
    def lame_lambda(self) -> float:
        """First Lame parameter lambda = E nu / ((1 + nu)(1 - 2 nu)), in Pa."""
        e, nu = self.youngs_modulus, self.poisson_ratio
        return e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu))

    @property
    def shear_modulus(self) -> float:
        """Shear modulus G = E / (2 (1 + nu)), in Pa."""
        return self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))

    def elastic_inputs(self) -> dict:
        """The fields a reduction depends on (all but the strengths and the Haigh curve), JSON-able."""
        return {key: value for key, value in dataclasses.asdict(self).items() if key not in _NOT_ELASTIC}


def _checked_haigh_curve(name: str, curve) -> tuple:
    """*curve* as a tuple of ``(mean, alternating)`` float pairs, Pa, or a LinkModelError naming what is wrong."""
    where = f"material {name!r}: the Haigh curve"
    try:
        points = tuple((float(m), float(a)) for m, a in curve)
    except (TypeError, ValueError):
        raise LinkModelError(f"{where} must be a sequence of (mean, alternating) stress pairs in Pa, "
                             f"got {curve!r}") from None
    if len(points) < 2:
        raise LinkModelError(f"{where} needs at least two points, from (0, S_a0) to (S_m, 0), got {len(points)}")
    for k, (m, a) in enumerate(points):
        if not (math.isfinite(m) and math.isfinite(a)):
            raise LinkModelError(f"{where}: point {k + 1} {(m, a)!r} is not finite")
    if points[0][0] != 0.0 or not points[0][1] > 0.0:
        raise LinkModelError(f"{where} must start on the alternating axis, at (0, S_a0) with S_a0 > 0 Pa, "
                             f"got {points[0]!r}")
    if points[-1][1] != 0.0:
        raise LinkModelError(f"{where} must end on the mean axis, at (S_m, 0) (it is not extrapolated), "
                             f"got {points[-1]!r}")
    for k in range(1, len(points)):
        (m0, a0), (m1, a1) = points[k - 1], points[k]
        if not m1 > m0:
            raise LinkModelError(f"{where}: the means must increase strictly, point {k + 1} {points[k]!r} "
                                 f"follows {points[k - 1]!r}")
        if a1 > a0:
            raise LinkModelError(f"{where}: the alternating stresses must not increase, point {k + 1} "
                                 f"{points[k]!r} follows {points[k - 1]!r}")
        if k < len(points) - 1 and not a1 > 0.0:
            raise LinkModelError(f"{where}: only its last point lies on the mean axis, point {k + 1} is "
                                 f"{points[k]!r}")
    return points


def _check_positive(name: str, what: str, value: float, unit: str) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
        raise LinkModelError(f"material {name!r}: {what} must be a positive number in {unit}, got {value!r}")


def sn_line_exponent(ultimate: float, endurance: float, endurance_cycles: float, fraction: float = 0.9) -> float:
    """Basquin exponent b of the S-N line from ``fraction S_u`` at 10^3 cycles to ``S_e`` at *endurance_cycles*.

    Shigley's construction (Budynas and Nisbett, *Shigley's Mechanical
    Engineering Design*, 10th ed., eqs. 6-13 and 6-14, with the fatigue
    strength fraction f = 0.9 of S_u below 490 MPa):
    ``b = -log10(f S_u / S_e) / log10(N_e / 10^3)``.

    Parameters
    ----------
    ultimate, endurance : float
        Ultimate strength S_u and endurance strength S_e, Pa.
    endurance_cycles : float
        Cycles N_e at the knee.
    fraction : float
        f, the fatigue strength at 10^3 cycles over S_u.
    """
    return -math.log10(fraction * ultimate / endurance) / math.log10(endurance_cycles / 1e3)


STEEL = Material("steel", youngs_modulus=210e9, poisson_ratio=0.3, density=7850.0,
                 yield_strength=355e6, ultimate_strength=470e6, endurance_strength=235e6,
                 endurance_cycles=1e6, fatigue_exponent=sn_line_exponent(470e6, 235e6, 1e6))
"""Structural steel: E = 210 GPa, nu = 0.3, rho = 7850 kg/m^3; the strengths
are the minimum values of grade S355 (EN 10025-2:2019, table 7): yield
strength R_eH = 355 MPa (nominal thickness up to 16 mm) and tensile strength
R_m = 470 MPa (the lower end of 470 to 630 MPa, thickness 3 to 100 mm). The
endurance strength, 235 MPa, is the rotating-beam estimate
S_e' = 0.5 R_m for steels with R_m up to 1400 MPa (Budynas and Nisbett,
*Shigley's Mechanical Engineering Design*, 10th ed., eq. 6-8), with no
surface, size or reliability factors. The S-N curve is Shigley's line from
0.9 R_m at 10^3 cycles to the endurance strength at N_e = 10^6 cycles (the
knee of steels there, eqs. 6-13 and 6-14; :func:`sn_line_exponent`):
Basquin exponent b = -log10(1.8) / 3 = -0.0851."""

TITANIUM = Material("titanium", youngs_modulus=114e9, poisson_ratio=0.34, density=4430.0,
                    yield_strength=828e6, ultimate_strength=895e6, endurance_strength=510e6,
                    endurance_cycles=1e7, fatigue_exponent=sn_line_exponent(895e6, 510e6, 1e7))
"""Titanium alloy Ti-6Al-4V: E = 114 GPa, nu = 0.34, rho = 4430 kg/m^3; the
strengths are the minimum values of ASTM B265 grade 5 (annealed sheet and
plate): yield strength (0.2 % offset) 828 MPa, tensile strength 895 MPa. The
endurance strength, 510 MPa, is the unnotched (K_t = 1) fatigue strength at
10^7 cycles of annealed Ti-6Al-4V in ASM's property data (ASM Aerospace
Specification Metals data sheet "Titanium Ti-6Al-4V (Grade 5), Annealed";
240 MPa with a K_t = 3.3 notch; the stress ratio is not stated there and is
taken as fully reversed), a typical, not a minimum value. The S-N curve is
Shigley's line (:func:`sn_line_exponent`) from 0.9 R_m at 10^3 cycles to the
endurance strength at N_e = 10^7 cycles, the cycles of ASM's value: Basquin
exponent b = -log10(0.9 x 895 / 510) / 4 = -0.0496."""

_PRESETS = {m.name: m for m in (STEEL, TITANIUM)}


def material(name: str) -> Material:
    """Look up a preset material by name (case-insensitive).

    Parameters
    ----------
    name : str
        Preset name, e.g. ``"steel"`` or ``"Titanium"``.

    Returns
    -------
    Material
        The preset.

    Raises
    ------
    ValueError
        If no preset has that name; the message lists the known names.
    """
    key = str(name).strip().lower()
    try:
        return _PRESETS[key]
    except KeyError:
        known = ", ".join(sorted(_PRESETS))
        raise LinkModelError(f"unknown material {name!r}; known materials: {known}") from None
