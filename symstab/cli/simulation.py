"""The paper's device simulation, shared by ``simulate`` and ``map``: its options and theory.

The non-idealities are given in physical units and need the physical
device options (the default device is the paper's);
:func:`simulated_theory` is the linear part of the loop simulated (filter
and actuator lag included), whose root count each simulation is compared with.
"""

import re

__all__ = ["add_nonideal_options", "resolve_nonideal", "simulated_theory", "nonideal_text",
           "loop_nonideal_text", "with_option_names", "check_loop_friction"]


#: The option of each field of :class:`~symstab.numeric.paper.simulate.Nonidealities`.
_OPTION_OF = {"encoder_resolution": "--encoder-resolution", "velocity_cutoff": "--velocity-cutoff",
              "coulomb_friction": "--coulomb", "stiction": "--stiction",
              "friction_compensation": "--friction-compensation",
              "actuator_bandwidth": "--actuator-bandwidth", "substeps": "--substeps",
              "force_limit": "--force-limit", "force_resolution": "--force-resolution"}
_FIELD_NAMES = re.compile(r"(?:nonideal\.)?\b(" + "|".join(_OPTION_OF) + r")\b")


def add_nonideal_options(p, loop_only=False):
    """Add the non-idealities (encoder, velocity filter, friction, actuator lag), --steps and --x0.

    ``loop_only``: only those of a loop file's simulation (the encoder's quantum,
    Coulomb friction, the force limit and quantum, --steps, --x0), for a command that
    simulates loop files only.
    """
    g = p.add_argument_group("non-idealities (physical units; each off by default)")
    g.add_argument("--encoder-resolution", type=float, metavar="Q",
                   help="position quantum, m or rad (the paper's: 3 arc seconds = 1.454e-5 rad)")
    if not loop_only:
        g.add_argument("--paper-encoder", action="store_true",
                       help="use the paper's encoder resolution (3 arc seconds)")
        g.add_argument("--velocity-cutoff", type=float, metavar="HZ",
                       help="first-order low-pass filter on the velocity, Hz (the paper's: 50)")
    g.add_argument("--coulomb", type=float, metavar="F",
                   help="Coulomb friction on the driven mass, N or N m (a loop file's: after "
                        "its actuator)")
    g.add_argument("--stiction", type=float, metavar="F", help="breakaway force (default: --coulomb)")
    if not loop_only:
        g.add_argument("--friction-compensation", action="store_true",
                       help="add the Coulomb friction times sign(estimated velocity) to the command")
        g.add_argument("--actuator-bandwidth", type=float, metavar="HZ", help="first-order lag, Hz")
    g.add_argument("--substeps", type=int,
                   help="sub-steps per period for friction and the actuator lag (default 20; "
                        "only with --coulomb or --actuator-bandwidth)")
    _add_limit_and_run(p, g)


def _add_limit_and_run(p, g):
    """--force-limit and --force-resolution in the group ``g``, --steps and --x0 in ``p``."""
    g.add_argument("--force-limit", type=float, metavar="F",
                   help="largest force command, N or N m (the amplifier's saturation)")
    g.add_argument("--force-resolution", type=float, metavar="Q",
                   help="force quantum, N or N m (the DAC's step): the command is rounded to "
                        "it (not with --coulomb)")
    p.add_argument("--steps", type=int, help="periods to simulate (default 12000 + 800 d)")
    p.add_argument("--x0", type=float, default=None,
                   help="initial position, m or rad (default 1; 0.01 with non-idealities)")


def resolve_nonideal(args, setup, loop=None):
    """``(Nonidealities, x0)`` of the parsed options, checked before any work (raises ValueError).

    ``setup`` is the paper's device options, or None for a loop file,
    ``loop``, whose simulation the options are checked against.
    """
    from ..numeric.simulation.simulator import (
        PAPER_ENCODER_RESOLUTION,
        Nonidealities,
        check_loop_nonideal,
        check_x0,
        default_x0,
    )

    # A command with add_nonideal_options(loop_only=True) has not the paper's options.
    option = {name: getattr(args, name, None) for name in (
        "paper_encoder", "velocity_cutoff", "coulomb", "stiction", "friction_compensation",
        "actuator_bandwidth", "substeps")}
    resolution = args.encoder_resolution
    if option["paper_encoder"] and setup is None:
        raise ValueError("--paper-encoder is the paper's encoder, 3 arc seconds in rad; a loop "
                         "file's position may be in m: give --encoder-resolution Q in the unit "
                         "of its position")
    if option["paper_encoder"]:
        if resolution is not None:
            raise ValueError("give --encoder-resolution or --paper-encoder, not both")
        resolution = PAPER_ENCODER_RESOLUTION
    if option["substeps"] is not None and option["coulomb"] is None \
            and option["actuator_bandwidth"] is None:
        if setup is None:       # a loop file: its lag is in its plant, exact
            raise ValueError("--substeps divides the period for Coulomb friction: give "
                             "--coulomb, or drop --substeps")
        raise ValueError("--substeps divides the period for Coulomb friction and the actuator "
                         "lag: give --coulomb or --actuator-bandwidth, or drop --substeps")
    try:
        nonideal = Nonidealities(encoder_resolution=resolution,
                                 velocity_cutoff=option["velocity_cutoff"],
                                 coulomb_friction=option["coulomb"], stiction=option["stiction"],
                                 friction_compensation=bool(option["friction_compensation"]),
                                 actuator_bandwidth=option["actuator_bandwidth"],
                                 substeps=20 if option["substeps"] is None else option["substeps"],
                                 force_limit=args.force_limit,
                                 force_resolution=args.force_resolution)
        if setup is None:       # a loop file: its values are physical (SI)
            nonideal = check_loop_nonideal(nonideal, loop, friction_name="--coulomb")
        elif not nonideal.ideal and not setup.physical:
            raise ValueError("non-idealities are in physical units: use --m --b --T --Td (or "
                             "their defaults), not --delta")
        if setup is not None and setup.physical:
            nonideal.check(setup.device.T)
    except (TypeError, ValueError) as exc:
        # The library names its fields; the command line names its options.
        raise type(exc)(_FIELD_NAMES.sub(lambda m: _OPTION_OF[m.group(1)], str(exc))) from None
    # Checked here, not only by the simulator, so that nothing is printed before the error.
    x0 = check_x0(args.x0) if args.x0 is not None else default_x0(nonideal)
    return nonideal, x0


def with_option_names(exc):
    """``exc`` (a TypeError or ValueError of the library) naming the options, not the fields.

    For the checks the simulation makes itself before it runs (the friction
    against the plant's step, :func:`~symstab.numeric.paper.simulate.check_friction_size`).
    """
    return type(exc)(_FIELD_NAMES.sub(lambda m: _OPTION_OF[m.group(1)], str(exc)))


def check_loop_friction(nonideal, loop, values):
    """Refuse, naming ``--coulomb``, a friction too large to step on ``loop``'s plant at ``values``.

    Decided before the run (and before anything is printed): the friction
    spaces are the run's own (cached by the loop).
    """
    from ..numeric.simulation.friction import substeps_of
    from ..numeric.simulation.simulator import check_friction_size

    if nonideal.coulomb_friction is not None:
        spaces, _ = loop.friction_spaces(substeps_of(nonideal), **values)
        check_friction_size(nonideal, spaces, name="--coulomb")


def simulated_theory(setup, nonideal):
    """The :class:`symstab.numeric.paper.simulate_theory.LinearTheory` of the loop simulated."""
    from ..numeric.paper.simulate_theory import linear_theory

    try:
        return linear_theory(gamma=setup.gamma, d=setup.d, delta=setup.delta,
                             device=setup.device, nonideal=nonideal)
    except (TypeError, ValueError) as exc:
        # Its refusals before a run (Coulomb friction at a fractional delay) name the options.
        raise with_option_names(exc) from None


def nonideal_text(nonideal, args):
    """The non-idealities of a run in one line, for the PNG title and the NPZ."""
    position, force = ("m", "N") if args.linear else ("rad", "N m")
    parts = []
    if nonideal.encoder_resolution is not None:
        parts.append(f"encoder quantum {nonideal.encoder_resolution:.4g} {position}")
    if nonideal.velocity_cutoff is not None:
        parts.append(f"velocity filter {nonideal.velocity_cutoff:g} Hz")
    if nonideal.coulomb_friction is not None:
        parts.append(f"Coulomb friction {nonideal.coulomb_friction:g} {force}"
                     + (f" (stiction {nonideal.stiction:g})" if nonideal.stiction is not None else "")
                     + (", compensated" if nonideal.friction_compensation else ""))
    if nonideal.actuator_bandwidth is not None:
        parts.append(f"actuator lag {nonideal.actuator_bandwidth:g} Hz")
    if nonideal.force_limit is not None:
        parts.append(f"force limit {nonideal.force_limit:g} {force}")
    if nonideal.force_resolution is not None:
        parts.append(f"force quantum {nonideal.force_resolution:.4g} {force}")
    return ", ".join(parts) if parts else "ideal loop: no quantization, filter, friction or lag"


def loop_nonideal_text(nonideal):
    """A loop file's non-idealities in one line (its SI units: position m or rad, force N or N m)."""
    parts = []
    if nonideal.encoder_resolution is not None:
        parts.append(f"encoder quantum {nonideal.encoder_resolution:.4g}")
    if nonideal.coulomb_friction is not None:
        stiction = "" if nonideal.stiction is None else f", stiction {nonideal.stiction:g}"
        compensated = (", compensated on the backward-difference velocity"
                       if nonideal.friction_compensation else "")
        parts.append(f"Coulomb friction {nonideal.coulomb_friction:g}{stiction}{compensated}, "
                     f"{nonideal.substeps} sub-steps a period")
    if nonideal.force_limit is not None:
        parts.append(f"force limit {nonideal.force_limit:g}")
    if nonideal.force_resolution is not None:
        parts.append(f"force quantum {nonideal.force_resolution:.4g}")
    return ("ideal loop" if not parts else ", ".join(parts) + " (SI units of the loop file)")
