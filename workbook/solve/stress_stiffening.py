"""Stress stiffening of the flexible links by their axial preload.

A flexible link's modal stiffness is that of the unloaded link. After the
static preload each flexible link carries an axial force ``P`` (from the
hinge forces at its two eyes, :func:`~workbook.solve.preload.link_compression`),
which stiffens it in bending when it pulls and softens it when it pushes.
This stage:

1. computes each flexible link's geometric stiffness per newton of tension
   (:func:`flexbodies.geometric_stiffness.link_stiffening`: the FE stress
   field of a unit tension, its initial-stress form, projected on the link's
   mode basis and on a pinned-pinned Craig-Bampton model);
2. stops with :class:`~workbook.errors.BucklingError` when a link's
   compression reaches its buckling load;
3. decides which links to stiffen (``Effects.stress_stiffening``: "on"
   every flexible link, "auto" those whose first pinned-pinned mode moves by
   more than :data:`AUTO_SHIFT`, "off" none and no check at all);
4. rebuilds the scene with the stiffened modal stiffness ``K_r + P K_G,r``
   and solves the preload again. The new preload changes the tensions a
   little; while they change by more than :data:`TENSION_TOLERANCE` the
   links are stiffened again with the new tensions, at most
   :data:`MAX_PASSES` times.

The record (:class:`StressStiffening`) goes with the preload to the model
card: every link's tension, first mode before and after, buckling load, and
the passes.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from dataclasses import dataclass

from flexbodies.geometric_stiffness import LinkStiffening, link_stiffening, stiffened
from workbook.errors import BucklingError
from workbook.model.case import Case, Simultaneous, SingleFrequencyExcitation
from workbook.scene.build import Scene, build_scene
from workbook.solve.preload import Preload, link_compression, solve_preload

__all__ = ["AUTO_SHIFT", "TENSION_TOLERANCE", "MAX_PASSES", "LinkPreloadStiffening", "StressStiffening",
           "assess_links", "stiffen_links"]

log = logging.getLogger(__name__)

#: "auto" stiffens a link whose axial preload moves its first pinned-pinned
#: bending mode by more than this fraction.
AUTO_SHIFT = 0.005
#: Largest relative change of the stiffened links' tensions between two
#: preload solves that ends the passes (relative to the largest tension).
TENSION_TOLERANCE = 1e-3
#: Most rebuild-and-preload passes.
MAX_PASSES = 2


@dataclass(frozen=True)
class LinkPreloadStiffening:
    """One flexible link under its axial preload.

    Attributes
    ----------
    name : str
    tension : float
        Axial force at the preload, N (negative: compression).
    buckling_load : float
        Compression at which the first pinned-pinned mode vanishes, N.
    unloaded_hz, loaded_hz : float
        First pinned-pinned (both eyes pinned, spin held) frequency without
        and with the axial force, Hz.
    stiffened : bool
        The scene's link carries the stiffened modal stiffness.
    """

    name: str
    tension: float
    buckling_load: float
    unloaded_hz: float
    loaded_hz: float
    stiffened: bool

    @property
    def shift(self) -> float:
        """Relative change of the first pinned-pinned frequency."""
        return self.loaded_hz / self.unloaded_hz - 1.0

    @property
    def load_ratio(self) -> float:
        """Compression over buckling load (negative in tension)."""
        return -self.tension / self.buckling_load


@dataclass(frozen=True)
class StressStiffening:
    """What the stage did.

    Attributes
    ----------
    setting : {"auto", "on", "off"}
    links : tuple of LinkPreloadStiffening
        Every flexible link (empty when off or without a preload).
    passes : int
        Rebuild-and-preload passes (0: no link stiffened).
    tension_change : float
        Relative change of the stiffened links' tensions in the last pass.
    seconds : float
        Wall time of the stage, s.
    idle_reason : str
        Why no link was assessed although the effect is not off (empty
        otherwise).
    """

    setting: str
    links: tuple
    passes: int
    tension_change: float
    seconds: float
    idle_reason: str = ""

    @property
    def applied(self) -> bool:
        return any(link.stiffened for link in self.links)

    def describe(self) -> str:
        """One line for the model card."""
        if self.setting == "off":
            return "switched off: the links keep their unloaded modal stiffness (no buckling check)"
        if not self.links:
            return self.idle_reason
        how = ("on: every flexible link" if self.setting == "on" else
               f"auto: the links whose axial preload moves their first pinned-pinned mode by more than "
               f"{100 * AUTO_SHIFT:g} %")
        listing = "; ".join(
            f"{link.name} {link.tension / 1e3:+.4g} kN ({'tension' if link.tension >= 0 else 'compression'}), "
            f"f1 {link.unloaded_hz:.4g} -> {link.loaded_hz:.4g} Hz ({100 * link.shift:+.2f} %), buckling load "
            f"{link.buckling_load / 1e3:.4g} kN{'' if link.stiffened else ', not stiffened'}"
            for link in self.links)
        stiffened_names = [link.name for link in self.links if link.stiffened]
        outcome = (f"K_r + P K_G,r on {', '.join(stiffened_names)}; the preload solved again "
                   f"{self.passes} time(s), last change of their tensions {self.tension_change:.2g}"
                   if stiffened_names else "no link stiffened")
        return f"{how}: {outcome}; per link: {listing}; {self.seconds:.2g} s"


def _tensions(scene: Scene, preload: Preload) -> dict[str, float]:
    return {name: -force for name, force in link_compression(scene, preload.hinge_forces).items()}


def assess_links(scene: Scene, preload: Preload, stiffenings: dict[str, LinkStiffening]) -> tuple:
    """Each flexible link under its preload, with the buckling check.

    Parameters
    ----------
    scene : Scene
        Solved for its preload.
    preload : Preload
    stiffenings : dict of str to LinkStiffening
        Per flexible link.

    Returns
    -------
    tuple of LinkPreloadStiffening
        ``stiffened`` set as the case's setting decides.

    Raises
    ------
    BucklingError
        A link whose compression reaches its buckling load.
    """
    case = scene.case
    tensions = _tensions(scene, preload)
    setting = case.effects.stress_stiffening
    links = []
    for name, stiffening in stiffenings.items():
        tension = tensions[name]
        unloaded = float(stiffening.pinned_hz(0.0, 1)[0])
        if -tension >= stiffening.buckling_load:
            raise BucklingError(case.name, name, -tension, stiffening.buckling_load, unloaded)
        loaded = float(stiffening.pinned_hz(tension, 1)[0])
        shift = abs(loaded / unloaded - 1.0)
        links.append(LinkPreloadStiffening(name, tension, stiffening.buckling_load, unloaded, loaded,
                                           setting == "on" or shift > AUTO_SHIFT))
    return tuple(links)


def stiffen_links(case: Case, excitation: SingleFrequencyExcitation | Simultaneous | None, scene: Scene,
                  preload: Preload) -> tuple[Scene, Preload]:
    """Stiffen the flexible links by their axial preload (see the module).

    Parameters
    ----------
    case : Case
    excitation : RotatingForce or HarmonicForce or None
        The excitation *scene* was built with.
    scene : Scene
        Solved for its preload.
    preload : Preload

    Returns
    -------
    scene : Scene
        *scene* itself when no link is stiffened, else a rebuilt scene solved
        for its preload (*scene* is then closed).
    preload : Preload
        Carrying the :class:`StressStiffening` record (``preload.stiffening``).

    Raises
    ------
    BucklingError
        A link whose compression reaches its buckling load.
    """
    start = time.perf_counter()
    setting = case.effects.stress_stiffening
    flexible = [link for link in case.links if case.link_is_flexible(link.name)]
    if setting == "off" or not preload.solved or not flexible:
        idle = "" if setting == "off" else ("no flexible link" if not flexible else "no static preload solved")
        record = StressStiffening(setting, (), 0, 0.0, time.perf_counter() - start, idle)
        return scene, dataclasses.replace(preload, stiffening=record)
    stiffenings = {link.name: link_stiffening(link.model) for link in flexible}
    links = assess_links(scene, preload, stiffenings)
    chosen = [link.name for link in links if link.stiffened]
    passes, change = 0, 0.0
    original = scene.reduced
    tensions = {link.name: link.tension for link in links}
    while chosen and passes < MAX_PASSES:
        reduced = dict(original)
        reduced.update({name: stiffened(original[name], stiffenings[name], tensions[name]) for name in chosen})
        # rebuilt as the scene was: loss factors exact (left to the frequency domain) or as
        # their viscous equivalent at the excitation's frequency (time domain)
        rebuilt = build_scene(case, excitation, reduced=reduced, exact_loss_factors=scene.loss_factor_hz is None)
        try:
            preload = solve_preload(rebuilt)
        except BaseException:
            rebuilt.close()
            if passes:
                scene.close()  # a scene of an earlier pass; the caller's own is closed already
            raise
        scene.close()
        scene, passes = rebuilt, passes + 1
        new = _tensions(scene, preload)
        scale = max(abs(tensions[name]) for name in chosen)
        change = max(abs(new[name] - tensions[name]) for name in chosen) / scale
        tensions = new
        log.info("%s: stress stiffening pass %d, tensions changed by %.2g", case.name, passes, change)
        if change <= TENSION_TOLERANCE:
            break
    if passes:
        links = tuple(dataclasses.replace(link, tension=tensions[link.name],
                                          loaded_hz=float(stiffenings[link.name].pinned_hz(tensions[link.name], 1)[0]))
                      for link in links)
    record = StressStiffening(setting, links, passes, change, time.perf_counter() - start)
    return scene, dataclasses.replace(preload, stiffening=record)
