"""Studies over many runs: the accuracy-against-time ladder and parameter studies."""
