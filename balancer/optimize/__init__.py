"""Balancing optimisers (placeholder while building)."""
