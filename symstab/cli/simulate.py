"""``symstab simulate`` (one point, a CSV trajectory) and ``symstab map`` (a grid).

The device and delay options are those of the numeric commands
(:mod:`symstab.cli.numeric`); the non-idealities are given in physical
units and need the physical device options (the default device is the
paper's).  Output paths are checked before the simulation
(:func:`symstab.cli.commands.check_outputs`) and files are written atomically
(:func:`symstab.cli.commands.write_output`): a failed or interrupted run leaves
nothing behind.
"""

import io
import pathlib
import sys

import numpy as np

from . import loop as cli_loop
from .._resources import check_memory
from .numeric import _add_model_options, _parse_list, _resolve, stiffness_and_damping

__all__ = ["add_commands"]


def _add_nonideal_options(p):
    g = p.add_argument_group("non-idealities (physical units; each off by default)")
    g.add_argument("--encoder-resolution", type=float, metavar="Q",
                   help="position quantum, m or rad (the paper's: 3 arc seconds = 1.454e-5 rad)")
    g.add_argument("--paper-encoder", action="store_true",
                   help="use the paper's encoder resolution (3 arc seconds)")
    g.add_argument("--velocity-cutoff", type=float, metavar="HZ",
                   help="first-order low-pass filter on the velocity, Hz (the paper's: 50)")
    g.add_argument("--coulomb", type=float, metavar="F", help="Coulomb friction, N or N m")
    g.add_argument("--stiction", type=float, metavar="F", help="breakaway force (default: --coulomb)")
    g.add_argument("--friction-compensation", action="store_true",
                   help="add the Coulomb friction times sign(estimated velocity) to the command")
    g.add_argument("--actuator-bandwidth", type=float, metavar="HZ", help="first-order lag, Hz")
    g.add_argument("--substeps", type=int, default=20,
                   help="sub-steps per period for friction and the actuator lag (default 20)")
    p.add_argument("--steps", type=int, help="periods to simulate (default 12000 + 800 d)")
    p.add_argument("--x0", type=float, default=None,
                   help="initial position, m or rad (default 1; 0.01 with non-idealities)")


def _nonideal(args, setup):
    from ..numeric.simulate import PAPER_ENCODER_RESOLUTION, Nonidealities, check_x0

    resolution = args.encoder_resolution
    if args.paper_encoder:
        if resolution is not None:
            raise ValueError("give --encoder-resolution or --paper-encoder, not both")
        resolution = PAPER_ENCODER_RESOLUTION
    nonideal = Nonidealities(encoder_resolution=resolution, velocity_cutoff=args.velocity_cutoff,
                             coulomb_friction=args.coulomb, stiction=args.stiction,
                             friction_compensation=args.friction_compensation,
                             actuator_bandwidth=args.actuator_bandwidth, substeps=args.substeps)
    if not nonideal.ideal and not setup.physical:
        raise ValueError("non-idealities are in physical units: use --m --b --T --Td (or their "
                         "defaults), not --delta")
    if setup.physical:
        nonideal.check(setup.device.T)
    # Checked here, not only by the simulator, so that nothing is printed before the error.
    x0 = check_x0(args.x0) if args.x0 is not None else (1.0 if nonideal.ideal else 0.01)
    return nonideal, x0


#: Bytes of CSV text per trajectory row ("k,t,x" with 17 digits) and per
#: map cell, with the Python objects that build them (generous).
_TRAJECTORY_ROW_BYTES = 120
_MAP_CELL_BYTES = 300


def _outputs(pairs):
    from .commands import check_outputs

    return check_outputs([(flag, path, "file") for flag, path in pairs])


def map_outputs(args):
    """``(out, png)`` paths of ``map``, checked before any work (png None with --no-png).

    ``--out`` must be a .csv or .npz file; the PNG defaults to ``--out``
    with the suffix .png.
    """
    if not args.out.endswith((".csv", ".npz")):
        raise ValueError(f"--out must end in .csv or .npz, got {args.out}")
    if args.no_png and args.png is not None:
        raise ValueError("give --png or --no-png, not both")
    png = None if args.no_png else (
        str(pathlib.Path(args.out).with_suffix(".png")) if args.png is None else args.png)
    paths = _outputs([("--out", args.out), ("--png", png)])
    return paths["--out"], paths.get("--png")


def _write(path, data, flag):
    from .commands import write_output

    write_output(path, data, flag)


def _single(text, name):
    values = _parse_list(text, name)
    if values.size != 1:
        raise ValueError(f"{name} takes one value here, got {values.size}")
    return float(values[0])


def _point(args, setup):
    alpha, beta = stiffness_and_damping(args, setup, _single)
    return float(alpha), float(beta)


def _theory(setup, nonideal):
    """The :class:`symstab.numeric.simulate.LinearTheory` of the loop simulated."""
    from ..numeric.simulate import linear_theory

    return linear_theory(gamma=setup.gamma, d=setup.d, delta=setup.delta,
                         device=setup.device, nonideal=nonideal)


def _cmd_simulate(args):
    from ..numeric.simulate import simulate
    from ..numeric.stability import MARGINAL, STABLE, UNSTABLE

    from ..numeric.simulate import check_steps, progress_printer

    setup = _resolve(args)
    alpha, beta = _point(args, setup)
    nonideal, x0 = _nonideal(args, setup)
    _outputs([("--out", args.out)])
    steps = check_steps(args.steps, setup.d)
    record = args.out is not None
    if record:
        check_memory(f"the --out trajectory of {steps} periods", (steps + 1) * _TRAJECTORY_ROW_BYTES)
    # The theory is that of the loop simulated (its linear part), decided
    # before the run so that a refusal costs no simulation.
    theory = _theory(setup, nonideal)
    code = theory.classify(alpha, beta)
    radius = theory.spectral_radius(alpha, beta)
    run = simulate(alpha=alpha, beta=beta, gamma=setup.gamma, d=setup.d,
                   delta=None if setup.physical else setup.delta, steps=steps, x0=x0,
                   device=setup.device, nonideal=nonideal, record=record,
                   progress=progress_printer("simulating", steps))
    for line in setup.echo:
        print(line)
    verdict = "diverged (unstable)" if run.diverged else ("stable" if run.stable else "unstable")
    amp = run.amplitude
    print(f"point: alpha = {alpha:.10g}, beta = {beta:.10g}"
          + (f" (K_w = {float(setup.device.stiffness(alpha)):.10g} {setup.units['K_w']}, "
             f"B_w = {float(setup.device.damping(beta)):.10g} {setup.units['B_w']})" if setup.physical else ""))
    print(f"simulated {run.steps} periods from x0 = {x0:g}: {verdict}; max |x| per quarter: "
          + ", ".join(f"{a:.4g}" for a in amp))
    print(f"theory ({theory.description}): spectral radius {radius:.12g} -> "
          + {STABLE: "stable", MARGINAL: "marginal", UNSTABLE: "unstable"}[code])
    if args.out is not None:
        k = np.arange(run.steps + 1)
        t = k * (setup.device.T if setup.physical else 1.0)
        buf = io.StringIO()
        buf.write(("k,t [s]," if setup.physical else "k,t [T],")
                  + ("x [rad]" if setup.physical and not args.linear else
                     "x [m]" if setup.physical else "x") + "\n")
        np.savetxt(buf, np.column_stack([k, t, run.positions]), delimiter=",", fmt=["%d", "%.9g", "%.17g"])
        _write(args.out, buf.getvalue(), "--out")
        print(f"wrote the trajectory to {args.out}")
    return 0


#: Largest number of grid points along one axis of ``symstab map``.
MAX_GRID = 2000


def _grid(text, name):
    parts = text.split(",")
    if len(parts) != 3:
        raise ValueError(f"{name} must be LOW,HIGH,N, got {text!r}")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        raise ValueError(f"{name} must be LOW,HIGH,N with a whole N, got {text!r}") from None
    # HIGH - LOW must be finite too: linspace takes it (1e308 - -1e308 is inf).
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi and np.isfinite(hi - lo)
            and 2 <= n <= MAX_GRID):
        raise ValueError(f"{name} must have finite LOW < HIGH (and HIGH - LOW finite) and "
                         f"2 <= N <= {MAX_GRID}, got {text!r}")
    return np.linspace(lo, hi, n)


def _cmd_map(args):
    if cli_loop.uses_loop(args):
        return cli_loop.run(args)
    from ..numeric.simulate import check_steps, progress_printer, stability_map
    from ..numeric.stability import MARGINAL, STABLE

    setup = _resolve(args)
    nonideal, x0 = _nonideal(args, setup)
    given = {}  # the grids as the user gave them, by flag: the PNG is drawn in their units

    def grid(text, flag):
        given[flag] = _grid(text, flag)
        return given[flag]

    alpha, beta = (np.atleast_1d(x) for x in stiffness_and_damping(args, setup, grid))
    out, png_path = map_outputs(args)
    check_memory(f"a map of {alpha.size} x {beta.size} cells", alpha.size * beta.size * _MAP_CELL_BYTES)
    steps = check_steps(args.steps, setup.d)
    # The loop simulated, classified by its roots before the simulation (a
    # refusal then costs no run): its linear part, filter and lag included.
    theory = _theory(setup, nonideal)
    A, B = np.meshgrid(alpha, beta, indexing="ij")
    code = theory.classify(A, B)
    for line in setup.echo:
        print(line)
    result = stability_map(alpha=alpha, beta=beta, gamma=setup.gamma, d=setup.d,
                           delta=None if setup.physical else setup.delta, steps=steps, x0=x0,
                           device=setup.device, nonideal=nonideal,
                           progress=progress_printer("simulating", steps))
    exact = code == STABLE
    physical = {}  # K_w and B_w beside alpha and beta, in the units of the echo
    if setup.physical:
        dev = setup.device
        physical = {"K_w": given.get("--Kw", np.atleast_1d(dev.stiffness(alpha))),
                    "B_w": given.get("--Bw", np.atleast_1d(dev.damping(beta)))}
    if out.suffix == ".npz":
        buf = io.BytesIO()
        units = {f"{name}_unit": np.array(setup.units[name]) for name in physical}
        np.savez(buf, alpha=alpha, beta=beta, **physical, **units, stable=result.stable,
                 growth=result.growth, exact_stable=exact, exact_code=code, gamma=setup.gamma,
                 d=setup.d, delta=setup.delta, steps=steps,
                 nonidealities=np.array(_nonideal_text(nonideal, args)),
                 theory=np.array(theory.description))
        data = buf.getvalue()
    else:
        buf = io.StringIO()
        columns = ["alpha", "beta"] + [f"{name} [{setup.units[name]}]" for name in physical]
        buf.write(",".join(columns + ["stable", "exact_stable", "growth"]) + "\n")
        cells = [A.ravel(), B.ravel()]
        if physical:
            K, Bw = np.meshgrid(physical["K_w"], physical["B_w"], indexing="ij")
            cells += [K.ravel(), Bw.ravel()]
        for *values, s, e, g in zip(*cells, result.stable.ravel(), exact.ravel(),
                                    result.growth.ravel()):
            buf.write(",".join(f"{v:.12g}" for v in values) + f",{int(s)},{int(e)},{g:.6g}\n")
        data = buf.getvalue().encode()
    png = _png(args, setup, result, nonideal, given, theory) if png_path is not None else None
    _write(out, data, "--out")
    written = [str(out)]
    if png is not None:
        _write(png_path, png, "--png")
        written.append(str(png_path))
    decided = code != MARGINAL
    differ = int(np.count_nonzero((result.stable != exact) & decided))
    print(f"{int(result.stable.sum())} of {result.stable.size} cells stable by simulation "
          f"({steps} periods); {differ} of the {int(decided.sum())} cells that are not marginal "
          f"differ from the root-counting classification of the {theory.description}")
    print("wrote " + ", ".join(written))
    return 0


def _nonideal_text(nonideal, args):
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
    return ", ".join(parts) if parts else "ideal loop: no quantization, filter, friction or lag"


def _tex_unit(unit):
    """A unit string of :meth:`symstab.numeric.units.Device.units` for matplotlib ("kg m^2" -> "kg m$^2$")."""
    return unit.replace("^2", "$^2$")


def _keep_nan(convert):
    """``convert`` (a Device's, which refuses NaN) applied to the finite entries only."""
    def apply(values):
        values = np.asarray(values, dtype=float)
        out = np.full(values.shape, np.nan)
        finite = np.isfinite(values)
        out[finite] = convert(values[finite])
        return out
    return apply


def _map_axes(setup, given, result):
    """``(x, y, x label, y label, to_x, to_y)`` in the units of the grids the user gave.

    ``to_x``/``to_y`` convert beta/alpha (the boundary curve) to the axes,
    keeping the NaN that break a curve between its branches.
    """
    dev, units = setup.device, setup.units
    if "--Bw" in given:
        x, xlabel, to_x = given["--Bw"], f"$B_w$ [{_tex_unit(units['B_w'])}]", _keep_nan(dev.damping)
    else:
        x, xlabel, to_x = result.beta, r"$\beta = B_w T / m$", np.asarray
    if "--Kw" in given:
        y, ylabel, to_y = given["--Kw"], f"$K_w$ [{_tex_unit(units['K_w'])}]", _keep_nan(dev.stiffness)
    else:
        y, ylabel, to_y = result.alpha, r"$\alpha = K_w T^2 / m$", np.asarray
    return x, y, xlabel, ylabel, to_x, to_y


def _map_title(setup, nonideal, args, steps_text):
    if setup.physical:
        dev, units = setup.device, setup.units
        loop = (f"$T_d$ = {dev.delay(setup.d) * 1e3:g} ms (d = {setup.d}), "
                f"$M_w$ = {float(dev.mass(setup.gamma)):g} {_tex_unit(units['M_w'])}")
    else:
        loop = f"$\\delta$ = {setup.delta:g}, d = {setup.d}, $\\gamma$ = {setup.gamma:g}"
    return (f"stable by simulation (green, {steps_text}); {loop}\n"
            f"{_nonideal_text(nonideal, args)}")


def _png(args, setup, result, nonideal, given, theory):
    """The map as PNG bytes, or None without matplotlib.

    Drawn in the units of the grids the user gave (K_w, B_w or alpha, beta),
    with the non-idealities of the simulation in the title and the boundary
    of the loop simulated (its linear part, ``theory``) over it.
    """
    from ..figures import pyplot

    try:
        plt = pyplot()
    except ValueError:
        print("matplotlib is not installed: no PNG", file=sys.stderr)
        return None

    from matplotlib.colors import ListedColormap

    x, y, xlabel, ylabel, to_x, to_y = _map_axes(setup, given, result)
    fig, ax = plt.subplots(figsize=(6.4, 4.8), dpi=120)
    ax.pcolormesh(x, y, result.stable.astype(float), shading="nearest",
                  cmap=ListedColormap(["white", "#7fc97f"]), vmin=0, vmax=1)
    arc_beta, arc_alpha, lines = theory.boundary(n=4000 if theory.loop is not None else 2000)
    arc_beta = cli_loop._visible(arc_beta, result.beta[0], result.beta[-1])
    arc_alpha = cli_loop._visible(arc_alpha, result.alpha[0], result.alpha[-1])
    arc_beta[np.isnan(arc_alpha)] = np.nan
    drawn = []
    if np.any(np.isfinite(arc_beta)):
        name = ("the ideal loop, eq. (7)" if theory.loop is None
                else f"the {theory.label} (D-decomposition)")
        drawn += ax.plot(to_x(arc_beta), to_y(arc_alpha), "k-", lw=1.2,
                         label=f"boundary of {name}")
    drawn += cli_loop.draw_lines(ax, lines, result.beta, result.alpha, to_x, to_y)
    ax.set_xlim(x[0], x[-1])
    ax.set_ylim(y[0], y[-1])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(_map_title(setup, nonideal, args, f"{result.steps} periods"), fontsize=10)
    if drawn:
        ax.legend(handles=drawn, loc="upper right", fontsize=9)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    plt.close(fig)
    return buf.getvalue()


def add_commands(sub):
    """Register ``simulate`` and ``map``."""
    from .commands import add_command

    p = add_command(
        sub, "simulate", help="simulate one point; write its trajectory as CSV",
        description="Simulate the sampled loop at one stiffness-damping point, with the "
                    "encoder quantization, velocity filter, friction and actuator lag you "
                    "switch on, and compare its verdict with the root count of the loop simulated "
                    "(its linear part, the filter and the actuator lag included; quantization "
                    "and friction are left out).",
        example="symstab simulate --Td 0.01 --Kw 30 --Bw 1 --paper-encoder --out trajectory.csv",
        func=_cmd_simulate)
    _add_model_options(p)
    _add_nonideal_options(p)
    p.add_argument("--alpha", help="dimensionless stiffness")
    p.add_argument("--beta", help="dimensionless damping")
    p.add_argument("--Kw", help="virtual stiffness (physical)")
    p.add_argument("--Bw", help="virtual damping (physical)")
    p.add_argument("--out", help="CSV file for the trajectory (k, t, x)")

    p = add_command(
        sub, "map", help="stability of a grid by simulation; write CSV or NPZ and a PNG",
        description="Simulate every point of a stiffness-damping grid and write which are "
                    "stable (CSV or NPZ, with the root count of the loop simulated beside, its "
                    "linear part with the filter and the actuator lag) and a PNG of the map with "
                    "that loop's boundary, in the units of the grid.",
        example="symstab map --Td 0.01 --Kw 0,50,100 --Bw=-0.1,1.8,100 --paper-encoder "
                "--velocity-cutoff 50 --out map.npz",
        func=_cmd_map)
    _add_model_options(p)
    _add_nonideal_options(p)
    p.add_argument("--alpha", metavar="LOW,HIGH,N", help="alpha grid (write --alpha=LOW,... "
                                                           "when LOW is negative)")
    p.add_argument("--beta", metavar="LOW,HIGH,N", help="beta grid (--beta=-0.01,0.3,100)")
    p.add_argument("--Kw", metavar="LOW,HIGH,N", help="K_w grid (physical)")
    p.add_argument("--Bw", metavar="LOW,HIGH,N", help="B_w grid (physical; --Bw=-0.1,3,100)")
    p.add_argument("--out", required=True, help="output file, .csv or .npz")
    p.add_argument("--png", help="PNG file (default: --out with .png)")
    p.add_argument("--no-png", action="store_true", help="do not draw the PNG")
    cli_loop.add_loop_options(p, "map")
