"""The answers of a run: amplitudes, transmissibility and isolation efficiency, the model card."""
