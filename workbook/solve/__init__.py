"""Solving a scene: preload, mounted modes, time or frequency domain, the guards that refuse bad answers."""
