"""A body's Craig-Bampton reductions for several excitations, from the cache or made once.

Free bodies share this path: links (:mod:`flexbodies.link`) and the engine
casing (:mod:`flexbodies.casing_reduction`). The mesh pylon, clamped, has its
own reduction (:mod:`flexbodies.pylon_reduction`) in the same cache.

1. the body's inputs (its fingerprint) hash to the key of its FE summary,
   the reference frequencies its mode decisions are judged on;
2. each excitation's decision keys one stored reduction;
3. what is missing is made under the body's cache lock (another process may
   have made it while this one waited, so the cache is read again there),
   from one FE model and one factorisation of its interior for every
   missing decision (:func:`flexbodies.reduction.reduce_for_decisions`).
"""
from __future__ import annotations

import hashlib
import json
from typing import Callable

import numpy as np

from .cache import BodyCache
from .reduced import package_version, with_decision

__all__ = ["record_hash", "entry_key", "stored_reductions", "cached_reductions"]


def record_hash(record: dict) -> str:
    """Short SHA-256 of a JSON-able record (the key of a cache entry)."""
    text = json.dumps(record, sort_keys=True, default=lambda v: np.asarray(v).tolist())
    return hashlib.sha256(text.encode()).hexdigest()[:24]


def entry_key(fe_hash: str, decision) -> str:
    """The key of one stored reduction: the body's FE hash and the decision's modes (entries
    keep the omitted modes' residual mass since ``"basis": 2``)."""
    return record_hash({"fe": fe_hash, "modes": decision.key, "basis": 2})


def stored_reductions(cache: BodyCache, fe_hash: str, decide: Callable, excitations_hz) -> tuple:
    """The stored frequencies, the decisions, their keys and the stored reductions (None where missing).

    Parameters
    ----------
    cache : BodyCache
    fe_hash : str
        :func:`record_hash` of the body's fingerprint.
    decide : callable
        ``decide(frequencies, excitation_hz)`` gives the ModeDecision of one excitation.
    excitations_hz : sequence of float or None

    Returns
    -------
    tuple
        ``(None, None, None, None)`` when the cache has no FE summary.
    """
    frequencies = cache.read_summary(fe_hash)
    if frequencies is None:
        return None, None, None, None
    decisions = [decide(frequencies, f) for f in excitations_hz]
    keys = [entry_key(fe_hash, d) for d in decisions]
    return frequencies, decisions, keys, [cache.load_body(key) for key in keys]


def cached_reductions(fingerprint: dict, decide: Callable, excitations_hz, prepare: Callable, *, cache_dir=None,
                      use_cache: bool = True) -> tuple:
    """One reduction per excitation, loaded or made from one FE model.

    Parameters
    ----------
    fingerprint : dict
        Every input of the body, JSON-able.
    decide : callable
        ``decide(frequencies, excitation_hz)`` gives the ModeDecision of one excitation.
    excitations_hz : sequence of float or None
    prepare : callable
        ``prepare(frequencies)`` meshes, assembles and couples the body and
        factorises its interior: it returns ``(coupled, solver, frequencies,
        timings)``, computing the reference frequencies (Hz) when given None
        and returning those given otherwise; ``timings`` holds its stages, s.
    cache_dir : str or Path, optional
    use_cache : bool
        False recomputes and does not read or write the cache.

    Returns
    -------
    tuple of ReducedBody
        One per excitation, in order, each carrying its own decision;
        ``cache_hit`` tells whether it was loaded.
    """
    excitations_hz = list(excitations_hz)
    cache = BodyCache(cache_dir, enabled=use_cache)
    fe_hash = record_hash(fingerprint)

    def complete(stored):
        bodies = stored[3]
        return bodies is not None and all(body is not None for body in bodies)

    def answer(decisions, keys, bodies, made):
        return tuple(with_decision(body, d, cache_hit=True) if body is not None else with_decision(made[key], d, False)
                     for body, d, key in zip(bodies, decisions, keys, strict=True))

    frequencies, decisions, keys, bodies = stored = stored_reductions(cache, fe_hash, decide, excitations_hz)
    if complete(stored):
        return answer(decisions, keys, bodies, {})
    with cache.lock(fe_hash):
        # another process may have made the entries while this one waited
        frequencies, decisions, keys, bodies = stored = stored_reductions(cache, fe_hash, decide, excitations_hz)
        if complete(stored):
            return answer(decisions, keys, bodies, {})
        from .reduction import reduce_for_decisions  # scikit-fem and the solvers: only when a reduction is made

        known = frequencies is not None
        coupled, solver, frequencies, timings = prepare(frequencies)
        if not known:
            cache.write_summary(fe_hash, frequencies)
            decisions = [decide(frequencies, f) for f in excitations_hz]
            keys = [entry_key(fe_hash, d) for d in decisions]
            bodies = [None] * len(decisions)
        missing = {key: decision for key, decision, body in zip(keys, decisions, bodies, strict=True) if body is None}
        infos = [{"inputs": fingerprint, "input_hash": key, "package_version": package_version(), **timings}
                 for key in missing]
        made = dict(zip(missing, reduce_for_decisions(coupled, solver, list(missing.values()), frequencies, infos), strict=True))
        for key, body in made.items():
            cache.save_body(key, body)
        return answer(decisions, keys, bodies, made)
