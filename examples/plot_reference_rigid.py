"""
The reference mount with rigid links
====================================

The bundled reference mount (eight links, sixteen ball hinges, the LP rotor
at 59 Hz and the HP rotor at 248.5 Hz) with every link made rigid: the
quickest answer the package gives, and the first rung of the accuracy study.
:func:`~workbook.solve.pipeline.run_case` solves the preload and then each
rotor excitation; the scene is linear, so the frequency domain answers it.
"""

import workbook as wb

case = wb.reference_case().with_rigid_links()
result = wb.run_case(case)

# %%
# Isolation efficiency eta = (1 - T) x 100 % of the pylon force, per direction:

print(result.to_pandas("efficiency").round(2))

# %%
# The same answers as transmissibility levels, 20 log10 T (dB):

print(result.to_pandas("db").round(1))

# %%
# The model card of a run says how it was solved and what the scene held
# (its first lines: the method and the bodies):

card = result.model_cards["LP rotor"].to_text()
print("\n".join(card.splitlines()[:14]))

# %%
# Efficiency per rotor and direction as bars:

fig = result.plot_efficiency()
