"""
Reducing one link by Craig-Bampton
==================================

One thrust rod of the reference mount (titanium, 60 x 50 mm shank), reduced
by :func:`flexbodies.reduce_link` for the HP rotor at 248.5 Hz. ``"auto"``
applies the low-frequency rule on the link's first frequency as mounted (both
bore centres pinned): below a quarter of it static modes suffice; otherwise
fixed-interface modes are kept up to four times the excitation. The reduced
link is cached (``~/.cache/mountwb`` or ``MOUNTWB_CACHE``), so a second call
only loads it.
"""

import workbook as wb
from flexbodies import reduce_link

link = next(link for link in wb.reference_case().links if link.name == "thrust-left")
reduced = reduce_link(link.model, modes="auto", excitation_hz=248.5)

# %%
# What was kept, and why:

print(reduced.decision.reason)
print(f"{reduced.info['fe_dof']} FE DOF -> {reduced.dof} DOF as a floating body "
      f"({reduced.n_fixed_interface} fixed-interface modes), loaded from the cache: {reduced.cache_hit}")

# %%
# The first natural frequencies (Hz) of the full finite-element model, free and
# as mounted, and of the reduced free body:

for key in ("free_free_hz", "mounted_hz", "reduced_hz"):
    print(f"{key:14s}", " ".join(f"{f:8.1f}" for f in reduced.frequencies[key][:6]))
