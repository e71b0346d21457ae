"""Balancing: force-balance conditions found from the mechanism, the redesign problem, solvers."""
