"""Balancing: the redesign problem, its convex and nonlinear solvers, fronts and counterweights."""
