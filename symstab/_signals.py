"""Ctrl-C and SIGTERM that stop the program wherever they land.

Python runs a signal handler between two bytecodes of the main thread,
wherever that is: inside importlib's module-lock callback, a ``__del__`` or
a weakref callback.  An exception raised there is printed as "Exception
ignored in ..." and dropped, and the program runs on (a ``symstab map``
stopped by SIGTERM during an import ran to its end).  Python's own
KeyboardInterrupt has the same hole.

:func:`raising` closes it.  In its block SIGINT raises KeyboardInterrupt and
SIGTERM raises :class:`Terminated`.  When Python swallows that exception (it
reports it to :data:`sys.unraisablehook`, which the block watches), the
signal is delivered to the main thread again :data:`REDELIVER_SECONDS`
later, from a short-lived thread, and again until its handler has run; a block that ends before then ends
with the exception.  An error that Python raised from the interruption
(a class's ``__set_name__`` in Python 3.11 wraps it in a RuntimeError) is
found behind it by :func:`interruption_behind`, and a module that another imports inside a bare
``except`` is imported first, outside it (:func:`import_outside_swallowers`).
An interruption a caller catches and handles itself is not repeated.  A second signal while the first one's exception is handled
or cleaned up after (``except`` and ``finally`` blocks on its way) does
nothing, so a cleanup is never cut short by a second Ctrl-C.

Light on purpose (the standard library only): the command line enters
:func:`raising` before it imports SymPy and NumPy, so that a signal in the
first second is handled like one in the tenth.
"""

import contextlib
import functools
import signal
import sys
import threading
import time

__all__ = ["Terminated", "raising", "deferred", "exit_status", "import_outside_swallowers",
           "interruption_behind", "REDELIVER_SECONDS"]

#: How long after Python swallowed an interruption's exception the signal is delivered again.
REDELIVER_SECONDS = 0.1

_SIGNALS = (signal.SIGINT, signal.SIGTERM)

#: Modules that other modules import inside ``try: ... except: pass``:
#: mpmath's backend does so with gmpy2, so a SIGTERM landing in gmpy2's
#: import was dropped for good (no "Exception ignored": nothing for the
#: hook to see) and the command ran on.  :func:`import_outside_swallowers`
#: imports them first, where an interruption raises.
SWALLOWED_IMPORTS = ("gmpy2",)


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that cleanup (temporary files) runs.

    A BaseException, like KeyboardInterrupt, so that no ``except Exception``
    on the way swallows it.
    """


def exit_status(exc):
    """The exit status of a program stopped by ``exc``: 128 + the signal's number."""
    return 128 + (signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT)


class _State:
    """What the handlers share while a :func:`raising` block runs."""

    def __init__(self):
        self.depth = 0
        self.pending = None   # a signal whose exception Python swallowed, until delivered again
        self.deliverer = None   # the thread that delivers it again, while one runs
        # Re-entrant: a handler or the hook may run in the main thread while it holds it.
        self.lock = threading.RLock()


_state = _State()


def _on_its_way():
    """True when the exception of an interruption is being handled or cleaned up after."""
    exc = sys.exc_info()[1]
    while exc is not None:
        if isinstance(exc, (KeyboardInterrupt, Terminated)):
            return True
        exc = exc.__context__
    return False


def _exception(signum):
    return Terminated() if signum == signal.SIGTERM else KeyboardInterrupt()


def _in_the_hook(frame):
    """True when ``frame`` runs inside :func:`_unraisable` (Python swallows what it raises)."""
    while frame is not None:
        if frame.f_code is _unraisable.__code__:
            return True
        frame = frame.f_back
    return False


def _handler(signum, frame):
    if _in_the_hook(frame):
        # Raised here, the exception would be dropped for good ("Exception
        # ignored in sys.unraisablehook"): left to the delivery again.
        _deliver_again(signum)
        return
    with _state.lock:
        _state.pending = None   # delivered: no repeat
    # A second signal while the first one's exception is handled (its
    # cleanup runs) must not cut that cleanup short.
    if _on_its_way():
        return
    raise _exception(signum)


def import_outside_swallowers(names=SWALLOWED_IMPORTS):
    """Import ``names`` (those installed) before a module that would swallow an interruption does.

    See :data:`SWALLOWED_IMPORTS`: imported here, an interruption landing
    in their import raises as anywhere else; the swallowing module then
    finds them in ``sys.modules``.
    """
    for name in names:
        try:
            __import__(name)
        except ImportError:
            pass


def _deliver_again(signum):
    """Deliver ``signum`` to the main thread every :data:`REDELIVER_SECONDS` until it is handled.

    One thread delivers, started when none is running (it is recorded
    before it starts: a signal landing in ``start()`` finds it).
    """
    with _state.lock:
        _state.pending = signum
        if _state.deliverer is not None:
            return
        _state.deliverer = threading.Thread(
            target=_redeliver, args=(threading.main_thread().ident,), name="symstab-redeliver",
            daemon=True)   # an exit does not wait for it
        _state.deliverer.start()


def _unraisable(args, *, previous):
    """Python swallowed an exception: if it was an interruption's, deliver the signal again."""
    if not isinstance(args.exc_value, (KeyboardInterrupt, Terminated)):
        previous(args)
        return
    # Not from here: the hook runs inside the callback that swallowed the
    # exception, and would swallow the next one too.
    _deliver_again(signal.SIGTERM if isinstance(args.exc_value, Terminated) else signal.SIGINT)


def _redeliver(main):
    """Send the pending signal to ``main`` until its handler has run or the block has ended.

    Once is not always enough: a signal that lands after the main thread's
    last check for handlers and before it enters a blocking call (a
    ``time.sleep``, a wait on a lock or a subprocess) sets Python's flag
    but does not interrupt the call, and the handler would run only when
    the call returns (CI: a 30-second sleep ran to its end).  The next
    delivery interrupts it.
    """
    while True:
        time.sleep(REDELIVER_SECONDS)
        with _state.lock:
            if _state.pending is None:
                _state.deliverer = None
                return
            signal.pthread_kill(main, _state.pending)


@contextlib.contextmanager
def raising():
    """In this block SIGINT raises KeyboardInterrupt and SIGTERM :class:`Terminated`.

    Wherever the signal lands, the exception reaches the block's end: a
    delivery swallowed by Python (a handler that fired inside an import's
    lock callback, a ``__del__``, a weakref callback) is repeated.  Blocks
    nest (an inner one does nothing).  Outside the main thread, where Python
    allows no handler, the block runs with the signals as they are.

    Yields
    ------
    None

    Examples
    --------
    >>> from symstab._signals import Terminated, exit_status, raising
    >>> try:
    ...     with raising():
    ...         raise Terminated
    ... except Terminated as exc:
    ...     status = exit_status(exc)
    >>> status
    143
    """
    if threading.current_thread() is not threading.main_thread() or _state.depth:
        yield
        return
    # Setting up and tearing down are held against a signal: one landing
    # there would leave the handlers (or the hook) installed for good.  A
    # signal held during the set-up arrives when it ends, inside the try.
    previous, previous_hook = {}, sys.unraisablehook
    try:
        with deferred():
            _state.depth += 1
            sys.unraisablehook = functools.partial(_unraisable, previous=previous_hook)
            previous = {sig: signal.signal(sig, _handler) for sig in _SIGNALS}
        yield
        with _state.lock:
            swallowed, _state.pending = _state.pending, None
        if swallowed is not None:  # the block ended before the signal was delivered again
            raise _exception(swallowed)
    finally:
        with deferred():
            with _state.lock:
                _state.pending = None   # a re-delivery still to come does nothing
            for sig, handler in previous.items():
                # None: a handler not set from Python, which cannot be put back from it.
                if handler is not None:
                    signal.signal(sig, handler)
            sys.unraisablehook = previous_hook
            _state.depth -= 1

def interruption_behind(exc):
    """The interruption ``exc`` was raised from, when Python turned one into another error.

    Python 3.11 wraps an exception raised while a class is created, in a
    descriptor's ``__set_name__`` (NumPy's ``finfo`` has one, run on
    import), in a RuntimeError "Error calling __set_name__" raised from
    it: a SIGTERM landing there ended ``symstab`` with a traceback and
    exit status 1.  None when no interruption is behind ``exc``.
    """
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, (KeyboardInterrupt, Terminated)):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__
    return None


@contextlib.contextmanager
def deferred():
    """Hold SIGINT and SIGTERM back from the main thread until the block is done.

    Only the main thread's mask: a signal sent to the process while another
    thread (NumPy's BLAS, Dask) has it unblocked still trips Python's flag,
    and the handler runs at the main thread's next bytecode.  Outside the
    main thread the block runs with the signals as they are.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    before = signal.pthread_sigmask(signal.SIG_BLOCK, set(_SIGNALS))
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)
