"""The Exudyn scene of a case: bodies, the ball-hinge law, the excitation signal."""
