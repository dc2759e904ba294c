"""The ``gatetherm`` console command: argument parsing and error reporting only.

Exit codes: 0 done; 1 an I/O failure (a full disk, an output directory that cannot be
written or that another run is writing into) or failed sweep points; 2 bad input (also
equations made from it that no solver can solve); 130 Ctrl-C; 143 SIGTERM. Each failure is
one line on stderr, never a traceback; argument errors too (the usage is printed by
``--help``). Only ``os``, ``signal``, ``sys`` and ``threading`` are imported before
:func:`main` runs, so that a Ctrl-C while the command modules are imported ends in that one
line as well.
"""
from __future__ import annotations

import os
import signal
import sys
import threading


def _commands() -> tuple[str, ...]:
    """The sub-command modules of this package: every module with a top-level ``def register(``, in
    ``--help`` order (its ``ORDER = N``, then its name). Read from the sources, not imported: a
    command's run imports its own module only. A new command is one module, ``NAME.py``."""
    found = {}
    for here in __path__:
        for entry in sorted(os.listdir(here)):
            if entry.endswith(".py") and not entry.startswith("_") and entry[:-3] not in found:
                with open(os.path.join(here, entry), encoding="utf-8") as f:
                    lines = f.read().splitlines()
                if any(line.startswith("def register(") for line in lines):
                    order = next((line.split("=")[1].split("#")[0] for line in lines if line.startswith("ORDER = ")),
                                 "")
                    found[entry[:-3]] = int(order) if order.strip().isdigit() else 10 ** 6
    return tuple(sorted(found, key=lambda name: (found[name], name)))


COMMAND_MODULES = _commands()
"""Sub-command modules of this package, in ``--help`` order (:func:`_commands`)."""


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that a run cleans up (temporaries, lock) on its way out."""


class _Signals:
    """SIGINT and SIGTERM while a command runs (main thread only): KeyboardInterrupt or
    :class:`Terminated` in the main thread, so that the run cleans up on its way out. Some
    extension modules swallow or convert an exception raised while they load; so a signal is
    also remembered (the command then ends with its line however it unwinds) and, should the
    command go on regardless, ends the process after :attr:`GRACE_S`. A signal ignored when
    the command starts (SIGINT of a background job) stays ignored."""

    GRACE_S = 5.0
    CODES = {signal.SIGINT: ("interrupted", 130), signal.SIGTERM: ("terminated", 143)}

    def __init__(self):
        self.seen = None
        """(message, exit code) of the first signal received."""
        self.timer = None
        self.previous = {}
        if threading.current_thread() is threading.main_thread():
            self.previous = {sig: signal.signal(sig, self._received) for sig in self.CODES
                             if signal.getsignal(sig) is not signal.SIG_IGN}

    def _received(self, signum, frame):
        if self.seen is None:
            self.seen = self.CODES[signum]
            self.timer = threading.Timer(self.GRACE_S, self._exit_now)
            self.timer.daemon = True
            self.timer.start()
        raise KeyboardInterrupt if signum == signal.SIGINT else Terminated

    def _exit_now(self) -> None:
        os.write(2, f"gatetherm: {self.seen[0]}\n".encode())
        os._exit(self.seen[1])

    def report(self) -> int:
        """Print the signal's one line (ignoring another meanwhile); its exit code."""
        for sig in self.previous:
            signal.signal(sig, signal.SIG_IGN)
        return _say(*self.seen)

    def restore(self) -> None:
        if self.timer:
            self.timer.cancel()
        for sig, handler in self.previous.items():
            signal.signal(sig, handler)


def _command(argv: list[str]) -> str | None:
    """The command named in ``argv`` (its first word that is no option), if it is one."""
    word = next((a for a in argv if not a.startswith("-")), None)
    return word if word in COMMAND_MODULES else None


def build_parser(only: str | None = None):
    """The argument parser of every command, or of the command ``only`` alone (a run imports
    just its own command's module: the others' libraries cost a second or more to import)."""
    import importlib

    from gatetherm.cli.options import Parser

    parser = Parser(
        prog="gatetherm",
        description="Thermal deformation of machine tools and its compensation: FE on the paper's frame or any "
        "machine in a case file, beam theory, reduced models, compensation, sensor placement, diagnosis.",
    )
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details")
    solver = parser.add_argument_group("solver options (docs/performance.md; each overrides the file's and the "
                                       "environment's)")
    solver.add_argument("--solver", choices=("auto", "direct", "iterative"),
                        help="the path of every SPD system: sparse Cholesky or AMG-CG (default: auto, per system)")
    solver.add_argument("--memory-gb", type=float, metavar="GB",
                        help="memory the solvers may hold (default: 3/4 of the machine's)")
    solver.add_argument("--spd-backend", choices=("auto", "pardiso", "cholmod", "superlu", "amg"),
                        help="the direct path's factoriser (amg: the iterative path for elasticity)")
    solver.add_argument("--blas-threads", type=int, metavar="N", help="BLAS threads (default: half the cores)")
    solver.add_argument("--solver-options", metavar="FILE.toml",
                        help="a TOML file whose [solver] table sets these options")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in (only,) if only else COMMAND_MODULES:
        importlib.import_module(f"gatetherm.cli.{name}").register(sub)
    return parser


def _say(message: str, code: int) -> int:
    print(f"gatetherm: {message}", file=sys.stderr)
    return code


def _os_message(err: OSError) -> str:
    return f"{err.filename}: {err.strerror}" if err.filename and err.strerror else str(err)


def _run(argv: list[str] | None) -> int:
    import logging

    from gatetherm.cli.options import UsageError

    parser = build_parser(_command(sys.argv[1:] if argv is None else argv))
    try:
        args = parser.parse_args(argv)
    except UsageError as err:
        print(err, file=sys.stderr)
        return 2
    except SystemExit as done:  # --help
        return done.code if isinstance(done.code, int) else 0
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    if args.verbose:  # gatetherm's own progress details; the libraries' INFO (scikit-fem: every assembly) stays quiet
        logging.getLogger("gatetherm").setLevel(logging.INFO)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    # The libraries' native threads (BLAS) start with SIGINT and SIGTERM blocked: a signal then
    # reaches the main thread only, which may defer it around C code that traps it (METIS).
    held = signal.pthread_sigmask(signal.SIG_BLOCK, set(_Signals.CODES))
    try:
        from gatetherm.api import InputError, PointsFailed, SolverError, SolverOptions, configure, start_libraries

        start_libraries(set(_Signals.CODES))  # the API imports the rest when first used
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)

    logging.captureWarnings(True)  # the numerical libraries' warnings: in the log, shown with -v
    logging.getLogger("py.warnings").setLevel(logging.INFO if args.verbose else logging.ERROR)
    try:
        options = SolverOptions.from_environment()
        if args.solver_options:
            options = SolverOptions.from_file(args.solver_options, options)
        options = options.merged(path=args.solver, memory_gb=args.memory_gb, backend=args.spd_backend,
                                 blas_threads=args.blas_threads)
        with options.use():
            configure(options)
            return int(args.func(args) or 0)
    except InputError as err:
        return _say(f"error: {err}", 2)
    except PointsFailed as err:
        return _say(f"error: {err}", 1)
    except SolverError as err:  # the equations of the input cannot be solved
        return _say(f"error: {err}", 2)
    except OSError as err:
        return _say(f"error: {_os_message(err)}", 1)
    finally:
        logging.captureWarnings(False)


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns the exit code (see the module docstring)."""
    signals = _Signals()
    try:
        try:
            code = _run(argv)
        except BaseException as err:
            if signals.seen is None and isinstance(err, KeyboardInterrupt):  # not raised by our handler
                signals.seen = _Signals.CODES[signal.SIGINT]
            if signals.seen is None:
                raise
        return code if signals.seen is None else signals.report()
    finally:
        signals.restore()


def console() -> None:
    """The ``gatetherm`` program (and ``python -m gatetherm.cli``): :func:`main`, then the
    process ends with its code. What the command made is left to the end of the process
    (:func:`gc.freeze`): the interpreter's collections on the way out would go over all of
    it (``benchmarks/two_d.py``, variant ``no gc.freeze``) and free nothing the operating system
    does not."""
    code = main()
    import gc

    gc.freeze()
    sys.exit(code)


if __name__ == "__main__":
    console()
