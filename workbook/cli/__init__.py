"""The ``mountwb`` command line: one module per command."""
