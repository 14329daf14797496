"""Checks of the printed paper against the :mod:`symstab` derivation."""
