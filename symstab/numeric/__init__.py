"""The numeric API on the generated kernels: stability, the region engine and
limits, boundary curves, units, simulation, the 30-digit reference, and
:class:`symstab.Loop` for any loop.
"""
