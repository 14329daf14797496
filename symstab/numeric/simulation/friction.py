"""Coulomb friction on a loop's driven mass: the state space it acts in.

Friction acts inside the period, on the velocity of the mass the force
drives, so a loop with friction is stepped on a continuous state space
rather than on its pulse transfer function.  The plant is split as
``G = A M``: the actuator ``A`` (the loop's ``actuator``, default 1: force
command to the force on the mass) and the mass ``M = G / A`` (force to
position, relative degree 2, :meth:`symstab.Loop.driven_mass`).  Each is
realised in controllable canonical form and put in series:

    x' = F x + B_u u + B_f (-friction),      y = C x,      v = C_v x = C F x

(``C B_u = C B_f = 0``: the velocity is a state, driven by no input
directly).  With the friction held over a sub-step of ``h = T / n`` both
inputs are piecewise constant, so every sub-step is exact:
``exp([[F, B_u, B_f], [0, 0, 0], [0, 0, 0]] h)`` gives ``Phi``, ``Gamma_u``
and ``Gamma_f``, at 30 digits (mpmath), rounded once.

At rest, the force on the mass besides friction is ``net = (C_v F x + C_v
B_u u) / (C_v B_f)`` (its mass times the acceleration it would have); the
mass stays at rest while ``|net|`` is within the stiction force, and then
moves by the constrained dynamics ``x' = P (F x + B_u u)`` with ``P = I -
B_f C_v / (C_v B_f)``, the friction taking exactly ``net`` (for a rigid
mass: nothing moves; for two masses: the one not held goes on).  A moving
mass feels ``friction_coulomb sign(v)``; a sub-step that would reverse its
velocity ends at rest, by the friction's impulse on the mass alone,
``x -= B_f (C_v x) / (C_v B_f)``, where the mass stopped: forward of the
sub-step's start by ``v0 t* / 2`` at the time ``t*`` its velocity reached
zero (``StatePlant._stopped_at``), never behind it (friction stops a
mass; it does not push it back): the paper's simulator's friction model,
for any mass with any linear structure around it (the paper's device is
one: :func:`symstab.numeric.paper.simulate.simulate` runs on :class:`StatePlant`).
Without friction the same state space steps a plant from a given state
(the paper's device from ``x0`` and ``v0``), exactly, a period at a time.
"""

import dataclasses

import mpmath
import numpy as np

__all__ = ["FrictionSpace", "friction_space", "friction_spaces", "stacked_spaces", "StatePlant",
           "substeps_of"]

#: Digits of the matrix exponentials (as the plant's pulse transfer function).
DIGITS = 30


@dataclasses.dataclass(frozen=True)
class FrictionSpace:
    """The sub-step matrices of one plant (floats), in coordinates whose first two
    are the mass's position and velocity.

    Attributes
    ----------
    phi, gamma_u, gamma_f : ndarray
        Moving sub-step: ``x <- phi x + gamma_u u - gamma_f friction``
        (``(n, n)``, ``(n,)``, ``(n,)``).
    stuck_phi, stuck_gamma : ndarray
        Sub-step of a mass held at rest.
    net_state, net_input : ndarray, float
        ``net = net_state . x + net_input u``, the force on the resting mass.
    impulse : ndarray
        ``B_f / (C_v B_f)``: the state change that stops the mass.
    start_position, start_change : ndarray
        The state after positions ``x0 - k v0`` (``k = 0, 1, ...``) with no
        force: ``x0 start_position + v0 start_change``.
    substep : float
        The sub-step's length ``h = T / substeps`` (s).
    per_mass : float
        ``C_v B_f``: the acceleration of a unit force on the mass (one over
        its mass), so that its acceleration is ``per_mass (net - friction)``.
    """

    phi: np.ndarray
    gamma_u: np.ndarray
    gamma_f: np.ndarray
    stuck_phi: np.ndarray
    stuck_gamma: np.ndarray
    net_state: np.ndarray
    net_input: float
    impulse: np.ndarray
    start_position: np.ndarray
    start_change: np.ndarray
    substep: float
    per_mass: float


def _canonical(num, den):
    """Controllable canonical ``(A, B, C, D)`` of ``num / den`` (mpmath, highest power first)."""
    while den and den[0] == 0:
        den = den[1:]
    lead = den[0]
    den = [c / lead for c in den]
    num = [c / lead for c in num]
    n = len(den) - 1
    num = [mpmath.mpf(0)] * (n + 1 - len(num)) + list(num)
    direct = num[0]
    A = mpmath.zeros(n, n)
    for j in range(n):
        A[0, j] = -den[j + 1]
    for i in range(1, n):
        A[i, i - 1] = 1
    B = mpmath.zeros(n, 1)
    if n:
        B[0, 0] = 1
    C = mpmath.matrix([[num[k] - direct * den[k] for k in range(1, n + 1)]]) if n else mpmath.zeros(1, 0)
    return A, B, C, direct


def _exponential(A, inputs, h):
    """``(Phi, [Gamma_i])`` of ``x' = A x + sum B_i u_i`` over ``h`` with the inputs held."""
    n, k = A.rows, len(inputs)
    M = mpmath.zeros(n + k, n + k)
    M[:n, :n] = A
    for j, B in enumerate(inputs):
        M[:n, n + j] = B
    E = mpmath.expm(M * h)
    return E[:n, :n], [E[:n, n + j] for j in range(k)]


def friction_space(coefficients, T, substeps):
    """The :class:`FrictionSpace` of one plant from ``[A_n, A_d, N, D]`` (:meth:`symstab.Loop.driven_mass`).

    Raises
    ------
    ValueError
        If the state is not determined by the positions (the actuator's
        pole cancels a zero of the mass), or the numbers are not finite.
    """
    with mpmath.workdps(DIGITS):
        a_num, a_den, m_num, m_den = ([mpmath.mpf(c) for c in part] for part in coefficients)
        Aa, Ba, Ca, Da = _canonical(a_num, a_den)
        Am, Bm, Cm, _ = _canonical(m_num, m_den)
        na, nm = Aa.rows, Am.rows
        n = na + nm
        F = mpmath.zeros(n, n)
        B_u, B_f, C = mpmath.zeros(n, 1), mpmath.zeros(n, 1), mpmath.zeros(1, n)
        if na:
            F[:na, :na] = Aa
            B_u[:na, 0] = Ba
            F[na:, :na] = Bm * Ca
        F[na:, na:] = Am
        B_u[na:, 0] = Bm * Da
        B_f[na:, 0] = Bm
        C[0, na:] = Cm
        C_v = C * F
        per_mass = (C_v * B_f)[0, 0]
        if per_mass == 0:
            raise ValueError("the driven mass has no velocity state (C F B = 0)")
        h = mpmath.mpf(T) / substeps
        phi, (gamma_u, gamma_f) = _exponential(F, [B_u, B_f], h)
        P = mpmath.eye(n) - B_f * C_v / per_mass
        stuck_phi, (stuck_gamma,) = _exponential(P * F, [P * B_u], h)
        # Positions at t = -(n-1)T, ..., -T, 0 with no force from the state w
        # at the first: C exp(F k T) w (forward in time, so a fast stable mode
        # is a small number, not exp(+|p| T) overflowing); the start is
        # exp(F (n-1) T) w.
        period = mpmath.expm(F * mpmath.mpf(T))
        rows, row = mpmath.zeros(n, n), C
        for k in range(n):
            rows[k, :] = row
            row = row * period
        try:
            start = [period ** (n - 1) * mpmath.lu_solve(
                rows, mpmath.matrix([f(n - 1 - k) for k in range(n)]))
                for f in (lambda k: 1, lambda k: -k)]
        except ZeroDivisionError:
            raise ValueError("the plant's state is not determined by its positions (a pole "
                             "of the actuator cancels a zero of the mass?)") from None
        # New coordinates whose first two are the mass's position and velocity,
        # so that a held mass keeps its position to the bit and a stopped one
        # has velocity 0 exactly (in the canonical form both are sums, and a
        # held position drifting by an ulp a period reads as growth).
        S = _with_rows(C, C_v)
        S_inv = S ** -1
        out = dict(phi=S * phi * S_inv, gamma_u=S * gamma_u, gamma_f=S * gamma_f,
                   stuck_phi=S * stuck_phi * S_inv, stuck_gamma=S * stuck_gamma,
                   net_state=C_v * F * S_inv / per_mass,
                   net_input=(C_v * B_u)[0, 0] / per_mass, impulse=S * B_f / per_mass,
                   start_position=S * start[0], start_change=S * start[1])
        for key in ("phi", "stuck_phi"):
            out[key] = _snapped(out[key])
        out = {k: np.array(v.tolist(), dtype=float).squeeze() if isinstance(v, mpmath.matrix)
               else float(v) for k, v in out.items()}
    out["substep"] = float(T) / substeps
    out["per_mass"] = float(per_mass)
    for key in ("phi", "stuck_phi"):
        out[key] = out[key].reshape(n, n)
    for key, value in out.items():
        if not np.all(np.isfinite(value)):
            raise ValueError(f"the friction state space of the plant is not finite ({key})")
        if key not in ("phi", "stuck_phi", "net_input", "substep", "per_mass"):
            out[key] = np.reshape(value, n)
    # The impulse stops the mass exactly: its velocity component is 1.
    out["impulse"][1] = 1.0
    return FrictionSpace(**out)


def _snapped(matrix):
    """``matrix`` with the entries at its 30 digits' rounding of 0 set to 0.

    In the position-velocity coordinates a mass's step has exact zeros
    (the position does not feed the velocity) that the change of
    coordinates leaves as 1e-40; as zeros, the step skips them.
    """
    out = matrix.copy()
    for i in range(out.rows):
        size = max(abs(out[i, j]) for j in range(out.cols))
        for j in range(out.cols):
            if abs(out[i, j]) <= mpmath.mpf(10) ** (4 - DIGITS) * size:
                out[i, j] = 0
    return out


def _with_rows(*rows):
    """An invertible matrix whose first rows are ``rows``, completed by unit rows."""
    n = rows[0].cols
    S = mpmath.zeros(n, n)
    for i, row in enumerate(rows):
        S[i, :] = row
    filled = len(rows)
    for j in range(n):
        if filled == n:
            break
        S[filled, :] = mpmath.zeros(1, n)
        S[filled, j] = 1
        # Keep the unit row if it is independent of the rows so far.
        if mpmath.mnorm(_residual(S[:filled + 1, :]), 1) > mpmath.mpf(10) ** (-DIGITS // 2):
            filled += 1
    if filled < n:
        raise ValueError("the mass's position and velocity are not independent states")
    return S


def _residual(rows):
    """The last row minus its projection on the others (mpmath)."""
    last = rows[rows.rows - 1, :]
    if rows.rows == 1:
        return last
    basis = rows[:rows.rows - 1, :]
    gram = basis * basis.T
    return last - (last * basis.T) * gram ** -1 * basis


def substeps_of(nonideal):
    """Sub-steps a period for ``nonideal``: its own with friction, else 1 (every step is exact)."""
    friction = nonideal.coulomb_friction or nonideal.stiction
    return nonideal.substeps if friction else 1


def stacked_spaces(spaces, inverse):
    """One :class:`FrictionSpace` for many points: the distinct plants' ``spaces`` indexed by ``inverse``.

    One plant (a plane of the environment) keeps its matrices; several
    get a last axis of points.
    """
    if len(spaces) == 1:
        return spaces[0]
    fields = {}
    for field in dataclasses.fields(FrictionSpace):
        stacked = np.stack([np.asarray(getattr(s, field.name)) for s in spaces], axis=-1)
        fields[field.name] = np.ascontiguousarray(stacked[..., inverse])
    return FrictionSpace(**fields)


def _times(matrix, state):
    """``matrix @ state`` for ``(n, n)`` or per-point ``(n, n, N)`` matrices, state ``(n, N)``."""
    return matrix @ state if matrix.ndim == 2 else np.einsum("ijp,jp->ip", matrix, state)


def _dot(row, state):
    """``row . state`` per point: ``(N,)``."""
    return row @ state if row.ndim == 1 else np.einsum("ip,ip->p", row, state)


def _column(vector):
    """A vector of the state as a column that broadcasts over points."""
    return vector[:, None] if vector.ndim == 1 else vector


class StatePlant:
    """A plant on its state space for N points, with Coulomb friction on its mass when given.

    :meth:`step` advances one period.  ``state`` is ``(n, N)``; its rows 0
    and 1 are the mass's position and velocity.  ``rest`` marks the points
    whose mass is at rest (held by stiction or stopped by a reversal).
    Without friction, with one matrix for every point, the state is kept
    as its rows and each sub-step sums the nonzero entries into new rows
    (:func:`substeps_of` gives one a period): the paper's device's step is
    a few products per point and no copy.
    """

    def __init__(self, space, state, rest, *, substeps, coulomb, stiction):
        self.space = space
        self.friction = bool(coulomb or stiction)
        self.substeps = substeps
        self.coulomb, self.stiction = coulomb, stiction
        self.rest = rest
        self._rows = None
        if not self.friction and space.phi.ndim == 2:
            # Coefficients as arrays of the points: NumPy multiplies by an
            # array in half the time it takes to convert a float (the same
            # doubles); 1 as itself (an addition).
            n_points = state.shape[1]
            self._terms = [[(j, 1.0 if c == 1.0 else np.full(n_points, float(c)))
                            for j, c in enumerate(row) if c != 0] for row in space.phi]
            self._gains = {}
            self._scratch = np.empty(n_points)
            self._rows = list(state)
        else:
            self._state = state
        if self.friction:
            # The friction's change of the state a sub-step, per direction;
            # the columns and the product a sub-step uses, made once.
            self._friction_step = _column(space.gamma_f) * coulomb
            self._impulse = _column(space.impulse)
            self._gamma_u = _column(space.gamma_u)
            # One plant for every point: its products inline (a call of
            # _times or _dot costs a sixth of one of its NumPy calls).
            shared = space.phi.ndim == 2
            self._phi = space.phi if shared else None
            self._stuck_phi = space.stuck_phi if shared else None
            self._net_state = space.net_state if shared else None
            self._stop(self.rest)

    @property
    def state(self):
        """The ``(n, N)`` state (rows 0 and 1: the mass's position and velocity)."""
        return self._state if self._rows is None else np.stack(self._rows)

    @classmethod
    def from_history(cls, space, x0, v0, n_points, nonideal):
        """The plant after positions ``x0 - k v0`` with no force (the loop simulator's start).

        A history of one position is everything at rest.  Friction and
        stiction in the loop's force unit, from ``nonideal``.
        """
        coulomb = nonideal.coulomb_friction
        state = (_column(space.start_position) * x0
                 + _column(space.start_change) * v0) * np.ones(n_points)
        return cls(space, state, np.full(n_points, v0 == 0), substeps=substeps_of(nonideal),
                   coulomb=coulomb,
                   stiction=nonideal.stiction if nonideal.stiction is not None else coulomb)

    def _stop(self, where):
        """Stop the mass at ``where``: the friction's impulse on the mass alone (velocity 0 exactly)."""
        # (count_nonzero: a quarter of any()'s time on a few points, per sub-step.)
        self._resting = bool(np.count_nonzero(where))
        if self._resting:
            # (np.where(where, v, 0.0) as a fill and a masked copy: a third of its time.)
            velocity = np.zeros(where.shape)
            np.copyto(velocity, self._state[1], where=where)
            self._state -= self._impulse * velocity

    def step(self, force, sign=1.0, out=None):
        """Advance one period under the input ``sign * force`` (per point); the new position.

        (``sign = -1``: the loop's ``u = -f`` without a pass to negate it.)
        The position is a new array each period (a history may keep it), or
        ``out``, which the plant may then keep as its state until the next
        period (the loop simulator's buffer row).
        """
        if self._rows is not None:
            for substep in range(self.substeps, 0, -1):
                self._rows = self._linear_rows(force, sign, out if substep == 1 else None)
            return self._rows[0]
        if not self.friction:
            for _ in range(self.substeps):
                self._state = _times(self.space.phi, self._state) + (
                    _column(sign * self.space.gamma_u) * force)
            return self._state[0] if out is None else _copied(out, self._state[0])
        held = sign * force
        drive = self._gamma_u * held
        # The input's share of the net force is the period's (as the drive).
        net_drive = self.space.net_input * held
        self._stuck_drive = None        # the held step's input term, made when a mass sticks
        # A stop's time divides by its rate (:meth:`_stopped_at`): one error
        # state for the period's sub-steps, not one for each stop.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            for _ in range(self.substeps):
                self._friction_substep(held, drive, net_drive)
        return self._state[0].copy() if out is None else _copied(out, self._state[0])

    def _friction_substep(self, held, drive, net_drive):
        """One sub-step with friction: moving, stopped by a reversal, or held.

        Where no point rests (:attr:`_resting`, known from the last
        sub-step's stop) the direction is the velocity's and nothing sticks,
        so the net force is computed only for a reversal: the same numbers
        as every term computed at every point, in half the NumPy calls.
        """
        sp, state, rest, resting = self.space, self._state, self.rest, self._resting
        moving = self._phi @ state if self._phi is not None else _times(sp.phi, state)
        moving += drive
        net = None
        if resting:
            net = self._net_state @ state if self._phi is not None else _dot(sp.net_state, state)
            net += net_drive
            # (np.where(rest, net, v) as a copy and a masked copy: half its time.)
            direction = state[1].copy()
            np.copyto(direction, net, where=rest)
            np.sign(direction, out=direction)
        else:
            direction = np.sign(state[1])
        # gamma_f (F_c direction) to the bit: direction is +-1, +-0 or NaN.
        moving -= self._friction_step * direction
        # A reversal within the sub-step ends at rest (friction cannot
        # push the mass backwards); a stuck mass stays where it is.
        # (v direction < 0 is sign(v) = -direction with direction != 0.)
        reversed_ = moving[1] * direction < 0
        if resting:
            reversed_ = reversed_ > rest          # and not resting
            stuck = rest & (np.abs(net) <= self.stiction)
        n_reversed = np.count_nonzero(reversed_)
        if n_reversed:
            if net is None:
                net = _dot(sp.net_state, state)
                net += net_drive
            np.copyto(moving[0], self._stopped_at(moving[1], net, direction), where=reversed_)
        self._state = moving
        if not resting:
            self.rest = reversed_
            if n_reversed:
                self._stop(reversed_)
            else:
                self._resting = False     # (what _stop finds: no point to stop)
            return
        n_stuck = np.count_nonzero(stuck)
        if n_stuck:
            if self._stuck_drive is None:
                self._stuck_drive = _column(sp.stuck_gamma) * held
            kept = (self._stuck_phi @ state if self._phi is not None
                    else _times(sp.stuck_phi, state))
            kept += self._stuck_drive
            kept[0] = state[0]
            np.copyto(moving, kept, where=stuck)
        self.rest = reversed_ | stuck
        if n_reversed or n_stuck:
            self._stop(self.rest)
        else:
            self._resting = False     # (what _stop finds: no point to stop)

    def _stopped_at(self, velocity, net, direction):
        """Where a moving mass stops within the sub-step whose end ``velocity`` is reversed.

        The sub-step's moving step holds the friction to its end, so its
        position is where a force that reversed the mass would have pushed
        it back to (with a large friction, far behind the start: it stopped
        the mass within the sub-step, then drove it backwards).  The mass
        stops instead at ``t*``, at ``x0 + v0 t* / 2``: its velocity falls
        from ``v0`` at the rate of the start, ``per_mass (F_c - sign(v0)
        net)``, the friction with the other forces on it (``net``), which
        puts ``t*`` where that rate reaches zero.  Where that rate does not
        stop the mass within the sub-step (the other forces turned it
        round), the rate is the sub-step's mean, from ``v0`` to its end
        ``v1``: ``t* = h v0 / (v0 - v1)``.  Either way the mass ends forward
        of its start by less than ``v0 h / 2``; the position is exact for
        forces constant over the stop and otherwise off by their change
        over it (relatively, at most the other forces over the friction:
        the stick and reversal times are first order in ``h`` besides).
        The other states keep the sub-step's end: the stop's impulse acts
        on the mass alone.
        """
        sp = self.space
        position, start = self._state[0], self._state[1]
        # (Divisions by zero and overflows are ignored by the caller, step().)
        rate = sp.per_mass * (self.coulomb - direction * net)
        at_start = np.abs(start) / rate
        time = sp.substep * start / (start - velocity)      # the mean rate's
        np.copyto(time, at_start, where=(rate > 0) & (at_start <= sp.substep))
        travel = 0.5 * start * time
        np.copyto(travel, 0.0, where=~np.isfinite(travel))
        return position + travel

    def _linear_rows(self, force, sign, out=None):
        """The rows of ``phi state + gamma_u sign force``: new arrays, summed over ``phi``'s nonzero entries."""
        rows, tmp = self._rows, self._scratch
        gains = self._gains.get(sign)
        if gains is None:
            gains = self._gains[sign] = [np.full(force.shape, sign * float(g))
                                         for g in self.space.gamma_u]
        # Positional outs (the keyword costs a fifth of a call on small arrays).
        new, multiply, add = [], np.multiply, np.add
        for gain, terms in zip(gains, self._terms, strict=True):
            row = multiply(gain, force) if out is None else multiply(gain, force, out)
            out = None
            for j, c in terms:
                if isinstance(c, float):      # 1
                    add(row, rows[j], row)
                else:
                    add(row, multiply(c, rows[j], tmp), row)
            new.append(row)
        return new

    def finite(self):
        """Per point: is every state finite?"""
        if self._rows is None:
            return np.all(np.isfinite(self._state), axis=0)
        ok = np.isfinite(self._rows[0])
        for row in self._rows[1:]:
            ok &= np.isfinite(row)
        return ok

    def freeze(self, bad):
        """Zero the points ``bad`` (diverged) and hold them at rest."""
        for row in (self._state if self._rows is None else self._rows):
            row[bad] = 0.0
        self.rest[bad] = True
        self._resting = bool(self.rest.any())


def _copied(out, values):
    """``out`` holding ``values``."""
    np.copyto(out, values)
    return out


def friction_spaces(loop, substeps, **values):
    """The state spaces of a loop in which friction acts: ``(spaces, inverse)``.

    One :class:`FrictionSpace` per distinct plant among the points
    (``values`` broadcast), and the index of each point's (of the
    broadcast shape); each space is built once per loop
    (:meth:`symstab.numeric.loop.evaluation.LoopEvaluation.friction_spaces`).

    Parameters
    ----------
    loop : symstab.Loop
        The loop.
    substeps : int
        Sub-steps per period (:class:`~symstab.numeric.paper.simulate.Nonidealities`).
    **values
        The loop's parameters (or their defaults); arrays broadcast.

    Returns
    -------
    (list of FrictionSpace, ndarray of int)

    Raises
    ------
    ValueError
        When the plant (over :attr:`~symstab.Loop.actuator`) is not a mass's
        force to position, or its state is not determined by its positions.
    """
    return loop.evaluation.friction_spaces(substeps, values, build=friction_space, digits=DIGITS)
