"""The options every command shares: its parser entry, the paper's device options.

:func:`add_command` adds a sub-command with its description and example;
:func:`add_model_options` the device and delay in physical units (``--m
--b --T``, default the paper's device, and ``--Td``) or dimensionless
(``--delta --d``), the virtual mass as ``--Mw`` (physical) or ``--gamma``,
and ``--format``; :func:`resolve` turns them into a :class:`Setup`, whose
echo is printed with the output (results in both unit systems).  ``--Td``
may be a fractional number of periods (``Td / T = 40.5``): every command
takes it; ``--d`` is whole.
Validation happens in the library; the caller
(:func:`symstab.cli.commands.main`) turns ``ValueError``/``TypeError`` into one
line on stderr and exit status 2.  A loop file's options are in
:mod:`symstab.cli.loop_options`.
"""

import argparse
import dataclasses
import math
import textwrap

import numpy as np

from .output import FORMATS, quiet_when_unread

__all__ = ["add_command", "Setup", "UNITS_RULE", "add_model_options", "resolve", "parse_list",
           "parse_one", "add_point_options", "stiffness_and_damping", "delay_text"]


def add_command(sub, name, *, help, description, example, func):
    """Add the sub-command ``name``: a one-sentence ``description`` and an ``example`` in --help.

    ``help`` is the short line of the command list of ``symstab --help``;
    ``example`` is the command line printed (indented) under "example:".
    A reader of its output that goes stops it quietly (:func:`quiet_when_unread`).
    """
    parser = sub.add_parser(name, help=help, description=textwrap.fill(description, 79),
                            epilog=f"example:\n  {example}",
                            formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.set_defaults(func=quiet_when_unread(func))
    return parser


@dataclasses.dataclass(frozen=True)
class Setup:
    """The resolved inputs of a numeric command."""

    device: object  # symstab.numeric.paper.device.Device or None (dimensionless input)
    gamma: float
    d: object  # int, or a float for a fractional delay (--Td not a whole number of periods)
    delta: float
    units: dict
    echo: tuple  # lines describing the inputs
    mass: bool = True  # False: the command searches over gamma; no virtual mass is an input

    @property
    def physical(self):
        return self.device is not None

    @property
    def fractional(self):
        """Whether the delay is not a whole number of samples (``Td / T = 40.5``)."""
        return not isinstance(self.d, int)

    def as_dict(self):
        out = {"gamma": self.gamma} if self.mass else {}
        out.update(d=self.d, delta=self.delta)
        if self.physical:
            out.update(m=self.device.m, b=self.device.b, T=self.device.T,
                       Td=self.d * self.device.T)
            if self.mass:
                out.update(M_w=self.device.mass(self.gamma))
            out.update(units=self.units)
        return out


#: The one rule for the units of the paper's device options (also in the README).
UNITS_RULE = ("Units: the device options are rotary by default, as the paper's device is a "
              "paddle (m and M_w in kg m^2, b and B_w in N m s/rad, K_w in N m/rad); --linear "
              "reads and prints the same numbers as a sliding mass's (kg, N s/m, N/m): the "
              "equations are the same, only the units' names change.  T and Td are in s.  A "
              "loop file (--loop) has its own units, converted to SI; --linear does not apply "
              "to it.")


def add_model_options(p):
    """Add the paper's device, delay and virtual mass options, --linear and --format."""
    g = p.add_argument_group("device and delay (physical; default: the paper's device)",
                             textwrap.fill(UNITS_RULE, 77))
    g.add_argument("--m", type=float, help="effective mass (inertia), kg m^2 (kg with --linear), "
                                           "> 0 (default 0.0128)")
    g.add_argument("--b", type=float, help="viscous friction, N m s/rad (N s/m with --linear), "
                                           ">= 0 (default 0.0324)")
    g.add_argument("--T", type=float, help="sample period, s, > 0 (default 0.001)")
    g.add_argument("--Td", type=float, help="loop delay, s, >= 0 (default 0); a fraction of a "
                                            "period (Td / T = 40.5) is taken by boundary, limits, "
                                            "classify, design and locus")
    g = p.add_argument_group("device and delay (dimensionless, instead of --m --b --T --Td)")
    g.add_argument("--delta", type=float, help="b T / m, from 0 (frictionless) to 1e6")
    g.add_argument("--d", type=_integer, help="delay in samples, an integer >= 0 (also allowed "
                                               "with the physical options instead of --Td, which "
                                               "takes a fractional delay)")
    g = p.add_argument_group("virtual mass")
    x = g.add_mutually_exclusive_group()
    x.add_argument("--gamma", type=float, help="M_w / m (default 0)")
    x.add_argument("--Mw", type=float, help="virtual mass, kg m^2 (kg with --linear)")
    p.add_argument("--linear", action="store_true",
                   help="linear units (kg, N s/m, N/m) instead of the rotary default (kg m^2, "
                        "N m s/rad, N m/rad) for the device options and the results: the same "
                        "numbers; not with --loop")
    p.add_argument("--format", choices=FORMATS, default="table", help="output format (default: table)")


def _integer(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if math.isfinite(value) and value >= 0 and not value.is_integer():
        raise argparse.ArgumentTypeError(
            f"delay d must be a whole number of samples, got {text!r}: give a fractional delay "
            f"in seconds with --Td (e.g. --Td 0.0405 at T = 0.001 s), or with --loop as "
            f"--set d={text}")
    if not (math.isfinite(value) and value.is_integer() and value >= 0):
        raise argparse.ArgumentTypeError(f"delay d must be a non-negative integer, got {text!r}")
    return int(value)


def delay_text(d, T=None):
    """The delay as printed: ``"d = 40"``; a fractional one ``"d = 40.5 samples"``.

    With the period ``T`` (s), the delay in time first: ``"Td = 0.04 s (d =
    40)"``, ``"Td = 40.5 ms (d = 40.5 samples)"`` (ms where Td is below a
    second and the delay fractional, as a reader writes it).
    """
    samples = f"d = {d}" if isinstance(d, int) else f"d = {d:.10g} samples"
    if T is None:
        return samples
    Td = d * T
    if not isinstance(d, int) and 0 < Td < 1:
        return f"Td = {Td * 1e3:.10g} ms ({samples})"
    return f"Td = {Td:g} s ({samples})"


def resolve(args, *, mass=True):
    """Turn the parsed options into a :class:`Setup` (raises ValueError).

    ``mass=False`` (``design``, which searches over the virtual mass) leaves
    the virtual mass out of the echo and of the JSON inputs.
    """
    from ..numeric.paper.device import PAPER_DEVICE, Device

    physical = [name for name in ("m", "b", "T", "Td") if getattr(args, name) is not None]
    if args.delta is not None:
        if physical:
            raise ValueError(f"--delta (dimensionless) cannot be combined with --{physical[0]} "
                             "(physical); give one or the other")
        if args.Mw is not None:
            raise ValueError("--Mw needs a physical device (--m); use --gamma with --delta")
        from .._validate import check_loop
        gamma, d, delta = check_loop(0.0 if args.gamma is None else args.gamma,
                                     0 if args.d is None else args.d, args.delta)
        echo = (f"dimensionless: delta = {delta:.6g}, {delay_text(d)}"
                + (f", gamma = {gamma:.6g}" if mass else ""),)
        return Setup(None, gamma, d, delta, {}, echo, mass)
    if args.Td is not None and args.d is not None:
        raise ValueError("give the delay once: --Td (seconds) or --d (samples)")
    device = Device(m=PAPER_DEVICE.m if args.m is None else args.m,
                    b=PAPER_DEVICE.b if args.b is None else args.b,
                    T=PAPER_DEVICE.T if args.T is None else args.T)
    if args.d is not None:
        from .._validate import check_delay
        d = check_delay(args.d)
    else:
        d = _delay_samples(0.0 if args.Td is None else args.Td, device.T)
    gamma = device.gamma(args.Mw) if args.Mw is not None else (0.0 if args.gamma is None else args.gamma)
    from .._validate import check_real
    gamma = check_real("gamma", gamma)
    units = device.units(rotary=not args.linear)
    mass_unit = units["M_w"]
    echo = (f"device: m = {device.m:g} {mass_unit}, b = {device.b:g} {units['B_w']}, "
            f"T = {device.T:g} s; delay {delay_text(d, device.T)}"
            + (f"; virtual mass M_w = {device.mass(gamma):g} {mass_unit} (gamma = {gamma:g})"
               if mass else ""),
            f"dimensionless: delta = b T / m = {device.delta:.6g}")
    return Setup(device, gamma, d, device.delta, units, echo, mass)


def _delay_samples(Td, T):
    """``Td / T`` in samples: an int when whole (to rounding), else the float (``40.5``).

    Refused in one line: ``Td`` negative or not finite, ``Td / T`` beyond
    ``SYMSTAB_MAX_DELAY``.
    """
    from .._validate import check_real, delay_samples

    return delay_samples(check_real("Td", Td, low=0.0) / T, name="Td / T")


def parse_list(text, name):
    """The finite numbers of a comma-separated list; an empty item ("1,,3") is an error."""
    items = [v.strip() for v in text.split(",")]
    if not any(items):
        raise ValueError(f"{name} must name at least one number")
    if not all(items):
        raise ValueError(f"{name} must be a comma-separated list of numbers without empty "
                         f"items, got {text!r}")
    try:
        values = [float(v) for v in items]
    except ValueError:
        raise ValueError(f"{name} must be a comma-separated list of numbers, got {text!r}") from None
    if not all(np.isfinite(values)):
        # Named here: a NaN passed on was refused later under the loop's name (K, not --alpha).
        raise ValueError(f"{name} must be finite numbers, got {text!r}")
    return np.array(values)


def parse_one(text, name):
    """One finite number (:func:`parse_list` of exactly one item)."""
    values = parse_list(text, name)
    if values.size != 1:
        raise ValueError(f"{name} takes one value here, got {values.size}")
    return float(values[0])


def add_point_options(p, *, lists=False):
    """Add ``--alpha``/``--beta`` and ``--Kw``/``--Bw``: the paper's stiffness and damping.

    One value each, or with ``lists`` comma-separated lists (one point per
    entry); :func:`stiffness_and_damping` reads them.
    """
    many, more = ("(es), comma-separated", "(s), comma-separated") if lists else ("", "")
    p.add_argument("--alpha", help=f"dimensionless stiffness{many}")
    p.add_argument("--beta", help=f"dimensionless damping{more}")
    p.add_argument("--Kw", help=f"virtual stiffness{many} (physical)")
    p.add_argument("--Bw", help=f"virtual damping{more} (physical)")


def stiffness_and_damping(args, setup, parse):
    """(alpha, beta) from --alpha/--Kw and --beta/--Bw, each read by ``parse(text, flag)``."""
    if (args.alpha is None) == (args.Kw is None) or (args.beta is None) == (args.Bw is None):
        raise ValueError("give the stiffness (--alpha or --Kw) and the damping (--beta or --Bw), once each")
    if (args.Kw is not None or args.Bw is not None) and not setup.physical:
        raise ValueError("--Kw and --Bw need a physical device; use --alpha and --beta with --delta")
    alpha = parse(args.alpha, "--alpha") if args.alpha is not None else \
        setup.device.alpha(parse(args.Kw, "--Kw"))
    beta = parse(args.beta, "--beta") if args.beta is not None else \
        setup.device.beta(parse(args.Bw, "--Bw"))
    return alpha, beta
