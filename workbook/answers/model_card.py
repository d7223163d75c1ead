"""The model card of a run: what was modelled, how it was solved, what it cost.

DOF per body, the modes kept and why, every physical effect on or off with
the reason, the solver settings, the mounted modes and the wall time of each
stage (docs/physics.md, section 4: "Simulate only the effects a scene calls for").
"""
from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np

from workbook.model.case import ENGINE
from workbook.model.casing import CASING
from workbook.scene import hinge_laws
from workbook.scene.build import Scene, loss_factors

__all__ = ["BodyEntry", "EffectEntry", "ModelCard", "model_card"]


@dataclass(frozen=True)
class BodyEntry:
    """One body of the scene.

    Attributes
    ----------
    name : str
    model : str
        ``"rigid body"``, ``"rigid link"``, ``"flexible link (Craig-Bampton)"``
        or ``"force transducer (point mass)"``.
    dof : int
        Degrees of freedom in the scene.
    modes : int
        Fixed-interface normal modes kept (flexible links), else 0.
    mass : float
        kg.
    reason : str
        Why these modes (or why rigid).
    """

    name: str
    model: str
    dof: int
    modes: int
    mass: float
    reason: str


@dataclass(frozen=True)
class EffectEntry:
    """One physical effect: on or off, and why."""

    name: str
    on: bool
    detail: str


@dataclass
class ModelCard:
    """Model card of one run.

    Attributes
    ----------
    case_name, run_name : str
    bodies : list of BodyEntry
    effects : list of EffectEntry
    solver : dict of str to value
        Integrator and Newton settings, step, durations.
    mounted_modes : list of (float, float, str)
        Frequency (Hz), damping ratio and description of each mounted mode.
    timings : dict of str to float
        Wall time per stage, s.
    method : str
        The analysis that answered: ``"time"`` or ``"frequency"``.
    method_reason : str
        Why that analysis answered.
    """

    case_name: str
    run_name: str
    bodies: list
    effects: list
    solver: dict
    mounted_modes: list
    timings: dict = field(default_factory=dict)
    method: str = ""
    method_reason: str = ""

    @property
    def total_dof(self) -> int:
        return sum(body.dof for body in self.bodies)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready data."""
        return {"case": self.case_name, "run": self.run_name,
                "method": {"analysis": f"{self.method} domain", "reason": self.method_reason},
                "total_dof": self.total_dof,
                "bodies": [asdict(b) for b in self.bodies], "effects": [asdict(e) for e in self.effects],
                "solver": dict(self.solver),
                "mounted_modes": [{"frequency_hz": f, "damping_ratio": z, "description": d}
                                  for f, z, d in self.mounted_modes],
                "timings_s": dict(self.timings)}

    def to_text(self) -> str:
        """A plain-text card for the console."""
        lines = [f"Model card: {self.case_name} / {self.run_name}", "",
                 f"Method: {self.method} domain ({self.method_reason})", "",
                 f"Bodies ({self.total_dof} DOF):"]
        width = max(len(b.name) for b in self.bodies)
        for b in self.bodies:
            lines.append(f"  {b.name:<{width}}  {b.model:<29} {b.dof:4d} DOF  {b.modes:3d} modes  "
                         f"{b.mass:8.2f} kg  {b.reason}")
        lines += ["", "Effects:"]
        for e in self.effects:
            lines.append(f"  [{'on ' if e.on else 'off'}] {e.name}: {e.detail}")
        lines += ["", "Mounted modes (engine on its mount):"]
        for frequency, zeta, description in self.mounted_modes:
            lines.append(f"  {frequency:7.2f} Hz  zeta {100 * zeta:5.2f} %  {description}")
        lines += ["", "Solver:"]
        lines += [f"  {key}: {value}" for key, value in self.solver.items()]
        lines += ["", "Wall time:"]
        lines += [f"  {stage:<22} {seconds:8.3f} s" for stage, seconds in self.timings.items()]
        lines.append(f"  {'total':<22} {sum(self.timings.values()):8.3f} s")
        return "\n".join(lines)


def model_card(scene: Scene, preload, mounted: list, plan, timings: dict[str, float], method,
               solver: dict | None = None) -> ModelCard:
    """Fill the model card of a run.

    Parameters
    ----------
    scene : workbook.scene.build.Scene
    preload : workbook.solve.preload.Preload
    mounted : list of workbook.solve.modes.Mode
    plan : workbook.solve.time_domain.TimePlan or None
        The time-domain plan (None for a frequency-domain run).
    timings : dict of str to float
    method : workbook.solve.method.MethodChoice
        The analysis method and why.
    solver : dict, optional
        Solver settings to record instead of those of *plan*.
    """
    case = scene.case
    bodies = _engine_bodies(scene)
    for link in case.links:
        reduced, item = scene.reduced[link.name], scene.links[link.name]
        if case.link_is_flexible(link.name):
            bodies.append(BodyEntry(link.name, "flexible link (Craig-Bampton)", item.dof,
                                    reduced.n_fixed_interface, item.mass, reduced.decision.reason))
        else:
            why = ("all links rigid (effects.flexible_links off)" if not case.effects.flexible_links
                   else "link asked to be rigid (flexible = False)")
            bodies.append(BodyEntry(link.name, "rigid link", item.dof, 0, item.mass, why))
    for name in scene.transducers:
        assert case.test_rig is not None
        bodies.append(BodyEntry(name, "force transducer (point mass)", 3, 0, case.test_rig.mass,
                                "test-rig transducer under a pylon pin: moving half on its spring to ground"))
    assert scene.excitation is not None
    card = ModelCard(case.name, scene.excitation.name, bodies, _effects(scene, preload, method),
                     _solver(scene, plan) if solver is None else dict(solver),
                     [(m.frequency_hz, m.damping_ratio, m.description) for m in mounted], dict(timings),
                     method.method, method.reason)
    return card


def _engine_bodies(scene) -> list[BodyEntry]:
    """The engine: one rigid body, or the rigid core and the flexible casing."""
    engine, items = scene.case.engine, scene.casing
    if items is None:
        return [BodyEntry(ENGINE, "rigid body", 6, 0, engine.mass, "one rigid body: mass, CG and inertia from the case")]
    reduced = items.reduced
    return [BodyEntry(ENGINE, "rigid core", 6, 0, items.core.mass,
                      "rotors and core: the engine's mass, CG and inertia less the casing's"),
            BodyEntry(CASING, "flexible casing (Craig-Bampton)", items.casing.dof, reduced.n_fixed_interface,
                      items.casing.mass, reduced.decision.reason)]


def _flexible_engine(scene) -> EffectEntry:
    """The flexible engine: why, its size, its first casing mode, the modes kept and the time it cost."""
    items = scene.casing
    if items is None:
        return EffectEntry("flexible engine", False, "no engine casing given: the engine is one rigid body")
    casing, reduced = scene.case.engine.casing, items.reduced
    source = "parametric casing" if casing.geometry is not None else f"casing mesh {casing.mesh}"
    stages = ", ".join(f"{words} {reduced.info[key]:.2f} s" for key, words in (
        ("mesh_seconds", "mesh"), ("assembly_seconds", "assembly"), ("reduction_seconds", "factorisation and modes"),
        ("frequency_seconds", "free-free frequencies")) if key in reduced.info)
    timing = f"reduction {'loaded from the cache (it took ' + stages + ')' if reduced.cache_hit else stages}"
    radial, axial = casing.bearing_stiffness
    return EffectEntry("flexible engine", True,
                       f"the case gives an engine casing: {source} ({reduced.info.get('fe_dof', 0)} FE DOF, "
                       f"{items.casing.mass:.1f} kg of {scene.case.engine.mass:g} kg) reduced to {items.casing.dof} "
                       f"DOF ({reduced.n_fixed_interface} fixed-interface modes); first free-free casing mode "
                       f"{reduced.frequencies['free_free_hz'][0]:.1f} Hz; mount eyes on the casing (RBE2), the "
                       f"rotors' loads on the rigid core ({items.core.mass:.1f} kg), joined at "
                       f"{len(items.bearings)} bearing planes (RBE3; axial {axial:.3g}, radial {radial:.3g} N/m) "
                       f"and by a spin restraint at {casing.core_spin_hz:g} Hz; casing modal damping "
                       f"{casing.modal_damping:g}; {timing}; {items.seconds:.2f} s in this run's scene")


def _effects(scene, preload, method) -> list[EffectEntry]:
    case, effects = scene.case, scene.case.effects
    flexible = [link.name for link in case.links if case.link_is_flexible(link.name)]
    damped_links = [link.name for link in case.links
                    if link.name in flexible and (link.stiffness_damping > 0 or link.mass_damping > 0)]
    modal_links = [link.name for link in case.links if link.name in flexible and link.modal_damping > 0]
    hinge_damping = [h for h in case.hinges if h.values("damping").max() > 0]
    hinge_loss, link_loss = loss_factors(case)
    loads = ", ".join(load.name for load in case.static_loads)
    entries = [
        EffectEntry("link flexibility", bool(flexible),
                    f"{len(flexible)} of {len(case.links)} links flexible" if flexible else
                    ("switched off: all links rigid" if not effects.flexible_links else "every link asked to be rigid")),
        EffectEntry("static preload", preload.solved,
                    f"{loads} solved first; dynamics start from that equilibrium" if preload.solved else
                    ("switched off" if not effects.preload else "no static loads given")),
        EffectEntry("hinge damping", effects.hinge_damping and bool(hinge_damping),
                    f"{len(hinge_damping)} hinges with viscous damping" if effects.hinge_damping and hinge_damping
                    else ("switched off" if not effects.hinge_damping else "no hinge has viscous damping")),
        _loss_factor_entry(scene, "hinge loss factor", hinge_loss, effects.hinge_damping, "hinge", "k",
                           len(case.hinges)),
        *(EffectEntry(law.name, *entry) for law in hinge_laws.HINGE_LAWS if (entry := law.card_entry(case)) is not None),
        EffectEntry("link damping", effects.link_damping and bool(damped_links),
                    f"Rayleigh damping on {', '.join(damped_links)}" if effects.link_damping and damped_links else
                    ("switched off" if not effects.link_damping else "no flexible link has Rayleigh damping")),
        EffectEntry("link modal damping", effects.link_damping and bool(modal_links),
                    "damping ratio zeta of every elastic mode (2 zeta w_i per mass-normalised mode) on "
                    + ", ".join(f"{name} ({case.link_map[name].modal_damping:g})" for name in modal_links)
                    if effects.link_damping and modal_links else
                    ("switched off" if not effects.link_damping else "no flexible link has a modal damping ratio")),
        _loss_factor_entry(scene, "link material loss factor", link_loss, effects.link_damping, "flexible link",
                           "K_red", len(flexible)),
        _flexible_engine(scene),
        _spin_restraints(scene),
        _gyroscopics(scene),
        _rig_sensors(scene),
        _stress_stiffening(preload),
        *_imbalance_planes(scene),
        *_strength(case, flexible),
    ]
    time_detail = "implicit generalized-alpha; amplitude by DFT of the last window"
    frequency_detail = "harmonic solution of the scene linearised about the preload"
    entries += [EffectEntry("time domain", method.method == "time",
                            f"{time_detail}: {method.reason}" if method.method == "time" else "not used"),
                EffectEntry("frequency domain", method.method == "frequency",
                            f"{frequency_detail}: {method.reason}" if method.method == "frequency" else "not used")]
    return entries


def _loss_factor_entry(scene, name: str, lossy: dict, switched_on: bool, kind: str, stiffness: str,
                       total: int) -> EffectEntry:
    """Loss factors of hinges or links: how they were built (exact complex
    stiffness, or its viscous equivalent at one frequency), or why not."""
    if not lossy:
        return EffectEntry(name, False, f"no {kind} has a loss factor" if switched_on else "switched off")
    groups: dict[str, list[str]] = {}
    for item, eta in lossy.items():
        value = f"{eta:g}" if isinstance(eta, float) else f"({', '.join(f'{e:g}' for e in eta)}) per direction"
        groups.setdefault(value, []).append(item)
    listing = "; ".join(f"eta = {value} on " + (f"every {kind} ({total})" if len(items) == total else ', '.join(items))
                        for value, items in groups.items())
    if scene.loss_factor_hz is None:
        how = f"complex stiffness {stiffness} (1 + i eta), exact at every frequency"
    else:
        how = (f"as the equivalent viscous damping eta {stiffness} / w at {scene.loss_factor_hz:g} Hz (the "
               f"excitation frequency of this run): exact in the steady state at {scene.loss_factor_hz:g} Hz only")
    return EffectEntry(name, True, f"{listing}: {how}")


def _spin_restraints(scene) -> EffectEntry:
    """The links' torsional spin restraints: what they are and the mode each adds."""
    name, links = "link spin restraints", scene.links
    if not links:
        return EffectEntry(name, False, "no links")
    stiffness = [item.spin_stiffness for item in links.values()]
    frequencies = sorted({round(item.spin_frequency_hz, 6) for item in links.values()})
    return EffectEntry(name, True, f"{len(links)} torsional springs, one per link from its eye A to a ground "
                       f"point, about the link's axis (k = {min(stiffness):.3g} to {max(stiffness):.3g} N m/rad): "
                       f"they stop the free spin of a link on two ball hinges, move no hinge point and each add "
                       f"one spin mode at {', '.join(f'{f:g}' for f in frequencies)} Hz")


def _gyroscopics(scene) -> EffectEntry:
    """The rotors' gyroscopic moment: built or not, and why."""
    from workbook.scene.build import net_angular_momentum

    name, rotors = "gyroscopic rotor", scene.case.rotors
    if scene.gyroscopics is None:
        if rotors and scene.case.effects.gyroscopics:
            return EffectEntry(name, False, f"not built: the spin angular momenta of "
                               f"{', '.join(r.name for r in rotors)} cancel (net "
                               f"{np.linalg.norm(net_angular_momentum(scene.case)):.3g} kg m^2/s), so their "
                               f"gyroscopic moments cancel too")
        return EffectEntry(name, False, "switched off: rotor inertia lumped in the engine" if rotors
                           else "no rotors given: rotor inertia lumped in the engine")
    listing = ", ".join(f"{r.name} Ip = {r.polar_inertia:g} kg m^2 at {r.frequency:g} Hz" for r in rotors)
    return EffectEntry(name, True, f"{listing}: moment -Ip Omega (omega x a) on the engine (symbolic "
                                   f"ObjectGenericODE2); their mass and transverse inertia lumped in the engine")


def _imbalance_planes(scene) -> list[EffectEntry]:
    """The excitation's imbalance planes (one force per plane) and its
    simultaneous parts (several frequencies in one run)."""
    from workbook.model.case import Imbalance, Simultaneous

    excitation = scene.excitation.excitation if scene.excitation is not None else None
    parts: tuple[Any, ...] = excitation.parts if isinstance(excitation, Simultaneous) else (excitation,)
    details = []
    for part in (p for p in parts if isinstance(p, Imbalance)):
        forces = "; ".join(f"{f.force_amplitude:.4g} N at x = {f.point[0]:g} m, phase {f.phase_deg:g} deg"
                           for f in part.plane_forces())
        details.append(f"{len(part.planes)} planes of {part.name!r} at {part.frequency:g} Hz, each its own rotating "
                       f"force U w^2 (or given force): {forces}; T refers to their summed amplitude "
                       f"{part.force_amplitude:.4g} N")
    planes = EffectEntry("imbalance planes", bool(details), "; ".join(details) or "the excitation is one force at "
                         "one point")
    together = EffectEntry("simultaneous excitations", isinstance(excitation, Simultaneous),
                           f"{', '.join(f'{p.name} at {p.frequency:g} Hz' for p in parts)} in one run; the amplitude "
                           f"at each frequency by least squares over the measured window, T per part against its "
                           f"own force" if isinstance(excitation, Simultaneous) else "one frequency per run")
    return [planes, together]


def _rig_sensors(scene) -> EffectEntry:
    """The test-rig force transducers: built or not, and why."""
    name, rig = "test-rig force-sensor compliance", scene.case.test_rig
    if not scene.transducers:
        fittings = ("the case's flexible pylon is at the pins instead"
                    if scene.case.flexible_pylon else "the pylon fittings are rigid")
        return EffectEntry(name, False, f"switched off: {fittings}" if rig is not None
                           else f"no transducers given: {fittings}")
    pins = "; ".join(" + ".join(items.hinges) for items in scene.transducers.values())
    stiffness = ", ".join(f"{k:.3g}" for k in rig.stiffness)
    damping = "" if not any(rig.damping) else f", d = ({', '.join(f'{d:.3g}' for d in rig.damping)}) N s/m"
    return EffectEntry(name, True, f"{len(scene.transducers)} transducers, k = ({stiffness}) N/m in x, y, z"
                       f"{damping}, m = {rig.mass:g} kg on pins {pins}; their forces make the pylon force")


def _strength(case, flexible: list) -> list[EffectEntry]:
    """The links' strength settings: the limit load cases, the fatigue materials and the speed spectra."""
    cases = case.load_cases
    entries = [EffectEntry("limit load cases", bool(cases),
                           f"{len(cases)} for the links' static margins, solved apart from the runs: "
                           + "; ".join(f"{c.name} (FS {c.factor_of_safety:g}"
                                       + (f", without {c.without_link}" if c.without_link else "") + ")" for c in cases)
                           if cases else "none given")]
    materials = {case.link_map[name].model.material for name in flexible}

    def curve(m) -> str:
        strengths = ", ".join(f"{label} {value / 1e6:g} MPa" for label, value in
                              (("S_e", m.endurance_strength), ("S_u", m.ultimate_strength)) if value is not None)
        sn = (f", S-N knee N_e {m.endurance_cycles:g}, b {m.fatigue_exponent:.4g}"
              if m.endurance_cycles is not None and m.fatigue_exponent is not None else ", no S-N curve")
        return f"{m.name}: {strengths or 'no strengths'}{sn}"

    spectra = case.speed_spectra
    entries.append(EffectEntry(
        "link fatigue", bool(materials),
        "Goodman and Gerber factors of the flexible links (mountwb stress, Result fatigue); "
        + "; ".join(curve(m) for m in sorted(materials, key=lambda m: m.name))
        + ("; Miner sums over the speed spectra of " + ", ".join(
            f"{s.excitation} ({s.hours:g} h in {len(s.bands)} band(s))" for s in spectra) if spectra
           else "; no speed spectrum: no Miner sum") if materials else "no flexible link"))
    return entries


def _stress_stiffening(preload) -> EffectEntry:
    """The links' stress stiffening by their axial preload: where, why, per-link shift."""
    record = preload.stiffening
    if record is None:
        return EffectEntry("link stress stiffening", False, "not assessed (the preload was solved alone)")
    return EffectEntry("link stress stiffening", record.applied, record.describe())


def _solver(scene, plan) -> dict[str, Any]:
    analysis = scene.case.analysis
    return {
        "integrator": f"generalized-alpha, spectral radius {analysis.spectral_radius:g}, modified Newton",
        "time step": f"{plan.step:.4g} s ({plan.steps_per_period} steps per period of {plan.frequency_hz:g} Hz)",
        "ramp": (f"{plan.ramp_periods} periods ({plan.ramp_periods / plan.frequency_hz:.3g} s), raised cosine"
                 if plan.start == "rest" else "none: from the steady state the excitation acts in full from the "
                 "first step"),
        "settle": f"{plan.settle_periods} periods ({plan.settle_periods / plan.frequency_hz:.3g} s): "
                  f"{plan.settle_reason}",
        "measured": f"2 windows of {plan.measured_periods} periods, steady if within "
                    f"{100 * analysis.steady_tolerance:g} %",
        "integrator accuracy": (f"estimated amplitude error {100 * plan.amplitude_error:.2g} %, largest on "
                                f"{plan.error_source}; {plan.steps_needed} steps per period keep it below "
                                f"{100 * plan.accuracy_target:g} %"
                                if plan.error_source else "no modes to estimate it on"),
        "steps": plan.steps,
        "end time": f"{plan.end_time:.4g} s",
        "Newton absolute tolerance": f"{analysis.newton_tolerance * scene.load_scale:.3g} "
                                     f"({analysis.newton_tolerance:g} x load scale {scene.load_scale:.4g} N)",
        "static equilibrium check": f"relative {analysis.equilibrium_tolerance:g}",
    }
