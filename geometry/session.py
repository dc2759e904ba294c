"""gmsh initialised in this process for the duration of a block (:func:`gmsh_session`), and whether it
has started threads here (:data:`THREADS_STARTED`)."""
from __future__ import annotations

import contextlib
import signal
import threading

from gatetherm.geometry import sandbox


THREADS_STARTED = {"here": False}
"""Whether gmsh has started threads in this process (a 3-D mesh made here, in
:func:`gmsh_session`): they would be missing in a forked child, which then waits for them
for ever; gmsh's processes are then started afresh (a new interpreter, ~0.3 s more)."""


@contextlib.contextmanager
def gmsh_session(name: str = "frame", verbosity: int = 0):
    """Initialise gmsh for the duration of the block (without the user's option files),
    printing its messages from ``verbosity`` 1 on (1 errors, 2 warnings, 5 progress), and
    finalise it."""
    import gmsh

    threads = sandbox.threads()
    if gmsh.isInitialized():
        gmsh.finalize()
    gmsh.initialize(readConfigFiles=False, interruptible=False)
    if threading.current_thread() is threading.main_thread():  # gmsh resets SIGTERM: Python's handler back
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is not None:
                signal.signal(sig, signal.getsignal(sig))
    try:
        gmsh.option.setNumber("General.Terminal", int(verbosity > 0))
        gmsh.option.setNumber("General.Verbosity", verbosity)
        gmsh.model.add(name)
        yield gmsh
    finally:
        gmsh.finalize()
        THREADS_STARTED["here"] |= sandbox.threads() > threads
