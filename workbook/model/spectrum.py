"""Speed spectra: the hours a rotor runs at each speed, for a Miner damage sum of the links.

A :class:`SpeedSpectrum` names a rotor excitation of the case (a rotating
force, an imbalance or a harmonic force, alone or as the template of a
sweep or run-up) and lists :class:`SpeedBand` rows: hours at one speed, or
hours spread evenly over a band of speeds. The excitation is solved at each
speed as it would be at that frequency (an unbalance's force grows as
U w^2, a force amplitude stays), and the cycles at a speed are
``speed [Hz] x 3600 x hours``: one stress cycle per revolution
(:mod:`workbook.solve.fatigue`). A band is solved at the midpoints of
:data:`BAND_POINTS` equal sub-bands, each with their share of the hours
(the midpoint rule of an even dwell). When the excitation is a sweep or a
run-up, its speeds bound the spectrum's.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from workbook.errors import CaseError
from workbook.model import fields
from workbook.model.field_spec import check_fields, documented, spec

__all__ = ["SpeedBand", "SpeedSpectrum", "BAND_POINTS", "SECONDS_PER_HOUR", "check_speed_spectra",
           "reference_speed_spectra"]

#: Speeds a band is solved at (the midpoints of this many equal sub-bands).
BAND_POINTS = 5
SECONDS_PER_HOUR = 3600.0
#: Relative slack of the check of a speed against a sweep's range.
_RANGE_SLACK = 1e-9


def _set(obj, name, value) -> None:
    object.__setattr__(obj, name, value)


@documented
@dataclass(frozen=True)
class SpeedBand:
    """Hours at one rotor speed, or spread evenly over a band of speeds."""

    hours: float = field(metadata=spec("Time at the speed (or in the band)", unit="h", minimum=0.0,
                                       help="time at the speed or in the band, >= 0"))
    speed_hz: float = field(metadata=spec("The speed, or the band's lower end", unit="Hz", minimum=0.0,
                                          strictly=True, help="the speed, or the band's lower end (Hz accepted)"))
    to_hz: float | None = field(default=None, metadata=spec(
        "The band's upper end, above *speed_hz* (None: one speed)", unit="Hz", minimum=0.0, strictly=True,
        optional=True, help="the band's upper end (empty: one speed)"))

    def __post_init__(self):
        item = "speed band"
        check_fields(self, item)
        if self.to_hz is not None and self.to_hz <= self.speed_hz:
            raise CaseError(item, "to_hz", self.to_hz, f"a speed above the band's lower end ({self.speed_hz:g} Hz)")

    def points(self) -> tuple[tuple[float, float], ...]:
        """``(speed Hz, hours)`` at which the band is solved (see the module)."""
        if self.to_hz is None:
            return ((self.speed_hz, self.hours),)
        width = (self.to_hz - self.speed_hz) / BAND_POINTS
        return tuple((self.speed_hz + (k + 0.5) * width, self.hours / BAND_POINTS) for k in range(BAND_POINTS))


@documented
@dataclass(frozen=True)
class SpeedSpectrum:
    """The hours one rotor excitation runs at each speed."""

    excitation: str = field(metadata=spec(
        "The name of a rotor excitation of the case (not a simultaneous one: give each of its rotors a spectrum "
        "of its own excitation)", type="str", check="own"))
    bands: tuple[SpeedBand, ...] = field(metadata=spec("At least one, with more than zero hours in all",
                                                       type="tuple of SpeedBand", check="own"))

    def __post_init__(self):
        fields.nonempty_name("speed spectrum", self.excitation)
        item = f"speed spectrum {self.excitation!r}"
        try:
            bands = tuple(self.bands)
        except TypeError:
            raise CaseError(item, "bands", self.bands, "a list of speed bands") from None
        if not bands or not all(isinstance(band, SpeedBand) for band in bands):
            raise CaseError(item, "bands", self.bands, "one or more SpeedBand")
        if sum(band.hours for band in bands) <= 0.0:
            raise CaseError(item, "bands[0]", 0.0, "more than zero hours in all")
        _set(self, "bands", bands)

    @property
    def hours(self) -> float:
        """Total hours of the spectrum, h."""
        return sum(band.hours for band in self.bands)

    def points(self) -> tuple[tuple[float, float], ...]:
        """``(speed Hz, hours)`` of every speed solved, band by band."""
        return tuple(point for band in self.bands for point in band.points())

    def check(self, excitations) -> None:
        """Refuse an excitation that is not a rotor excitation of *excitations* or a speed outside its sweep.

        Raises
        ------
        CaseError
            Naming the spectrum, the band and its end (``bands[k].speed_hz``).
        """
        from workbook.model.case import Simultaneous, Sweep

        item = f"speed spectrum {self.excitation!r}"
        known = {e.name: e for e in excitations}
        excitation = known.get(self.excitation)
        if excitation is None or isinstance(excitation, Simultaneous):
            names = [name for name, e in known.items() if not isinstance(e, Simultaneous)]
            raise CaseError(item, "excitation", self.excitation,
                            f"an excitation of the case that is not a simultaneous one ({', '.join(names)})")
        if not isinstance(excitation, Sweep):
            return
        low, high = excitation.frequencies_hz[0], excitation.frequencies_hz[-1]
        for k, band in enumerate(self.bands):
            for end in ("speed_hz", "to_hz"):
                speed = getattr(band, end)
                if speed is not None and not low * (1 - _RANGE_SLACK) <= speed <= high * (1 + _RANGE_SLACK):
                    raise CaseError(item, f"bands[{k}].{end}", speed,
                                    f"a speed within the speeds of {excitation.name!r}, {low:g} to {high:g} Hz")

    def template(self, excitations):
        """The single-frequency excitation solved at each speed (a sweep's template)."""
        from workbook.model.case import Sweep

        excitation = {e.name: e for e in excitations}[self.excitation]
        return excitation.template if isinstance(excitation, Sweep) else excitation

    def at(self, excitations, speed_hz: float):
        """The excitation at *speed_hz*, named ``"<excitation> @ <speed> Hz"``."""
        return dataclasses.replace(self.template(excitations), name=f"{self.excitation} @ {speed_hz:.6g} Hz",
                                   frequency_hz=speed_hz, rpm=None)


def check_speed_spectra(case) -> None:
    """Refuse speed spectra *case* cannot answer.

    Raises
    ------
    CaseError
        A spectrum naming no rotor excitation of the case or a speed outside
        its sweep (``speed spectrum '<excitation>'``, field ``bands[k].speed_hz``
        or ``.to_hz``), or,
        when the case has spectra, a flexible link whose material lacks the
        endurance or ultimate strength or an S-N parameter
        (``link '<name>'``, field ``material.<field>``).
    """
    from flexbodies.materials import FATIGUE_FIELDS

    for spectrum in case.speed_spectra:
        spectrum.check(case.excitations)
    if not case.speed_spectra:
        return
    for link in case.links:
        if link.model is None or not case.link_is_flexible(link.name):
            continue
        material = link.model.material
        for what in ("endurance_strength", "ultimate_strength", *FATIGUE_FIELDS):
            if getattr(material, what) is None:
                raise CaseError(f"link {link.name!r}", f"material.{what}", None,
                                f"the {what.replace('_', ' ')} of material {material.name!r}: the Miner damage sum "
                                "of a speed spectrum needs the material's S-N curve")


def reference_speed_spectra() -> tuple[SpeedSpectrum, ...]:
    """The speed spectra the docs report for the reference mount's LP and HP rotors.

    Illustrative, not a measured duty: per 1000 flight hours, ground idle,
    take-off and climb near the top speed, and cruise, spread evenly over
    each band (LP top speed 59 Hz = 3540 rpm, HP 248.5 Hz = 14910 rpm).
    """
    return (
        SpeedSpectrum("LP rotor", (SpeedBand(150.0, 15.0, 25.0), SpeedBand(100.0, 55.0, 59.0),
                                   SpeedBand(750.0, 48.0, 54.0))),
        SpeedSpectrum("HP rotor", (SpeedBand(150.0, 150.0, 170.0), SpeedBand(100.0, 240.0, 248.5),
                                   SpeedBand(750.0, 225.0, 238.0))),
    )
