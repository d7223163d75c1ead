"""Test-rig records: reading them, measuring T and eta, comparing with simulation."""
