"""``python -m balancer``: the same as the ``balancer`` command."""

from .cli import entry_point

entry_point()
