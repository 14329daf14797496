"""Unit labels: table columns with units, and units for matplotlib (TeX)."""

__all__ = ["tex_unit", "physical_columns"]


def tex_unit(unit):
    """A unit string of :meth:`symstab.numeric.paper.device.Device.units` for matplotlib ("kg m^2" -> "kg m$^2$")."""
    return unit.replace("^2", "$^2$")


def physical_columns(setup, names):
    """Column labels with units for K_w, B_w (physical setups only)."""
    return [f"{n} [{setup.units[n]}]" for n in names]
