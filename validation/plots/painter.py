"""Pictures drawn beside the work: a :class:`Painter` hands each picture (a plot function, its
arguments and the PNG's path) to processes of its own, which import matplotlib while the caller
computes and draw while it writes its other files.

Created before a run (``gatetherm simulate`` and ``gatetherm run`` make one first), it forks one
process, which imports matplotlib, draws a small figure (fonts loaded) and forks the second, so
that matplotlib is imported once. :meth:`Painter.draw` sends a picture to the process with fewer
queued; :meth:`Painter.finish` waits for every PNG and raises the first failure. Each process
writes its PNG atomically (:func:`gatetherm.validation.plots.save`) and ends with the caller
(``PR_SET_PDEATHSIG``) or when the painter closes. ``Painter(0)``, and a process that cannot fork
(not POSIX, one core, or threads running: a forked child would miss them), draws each picture
when it is given, in the process.
"""
from __future__ import annotations

import contextlib
import glob
import logging
import os
import select
import signal
import threading
import time
from pathlib import Path

from gatetherm import TEMP_PREFIX
from gatetherm.process import can_fork, end_with_parent, fork, keep_freed, message, receive, send

log = logging.getLogger(__name__)

STOP_S = 2.0
"""Longest a painting process is given to end on SIGTERM (it removes the PNG it was writing), s."""


def _paint(job) -> None:
    from gatetherm.validation.plots import save

    plot, args, kwargs, path, tight = job
    save(plot(*args, **kwargs), path, tight=tight)


def _warm() -> None:
    """Import matplotlib and draw a small figure with text: its fonts are loaded."""
    import io

    from matplotlib.figure import Figure

    import gatetherm.validation.plots.field  # noqa: F401 - the plot modules, imported once
    import gatetherm.validation.plots.run  # noqa: F401

    fig = Figure(figsize=(1, 1))
    fig.subplots().set(title="0", xlabel="[°C]")
    fig.tight_layout()
    fig.savefig(io.BytesIO(), format="png", dpi=20)


def _stopped(err: BaseException) -> bool:
    """Whether ``err`` came of the SIGTERM that ends a painting process (:func:`end_with_parent`'s
    SystemExit, perhaps wrapped by the import it interrupted: matplotlib's C extension says
    "ImportError: initialization failed"): an ended process, not a failed one."""
    seen = set()
    while err is not None and id(err) not in seen:
        if isinstance(err, SystemExit):
            return True
        seen.add(id(err))
        err = err.__cause__ or err.__context__
    return False


def _serve(jobs: int, replies: int) -> None:
    """A painting process's life: draw every job on ``jobs``, answer each on ``replies``
    (``(is OSError, error text)``, the text empty once the PNG is written)."""
    while (job := receive(jobs)) is not None:
        if job[3] is None:  # made ready (Painter.prepare): no picture, no answer
            try:
                job[0]()
            except Exception:  # noqa: BLE001 - the picture that needs it reports the failure
                log.debug("preparing a picture failed", exc_info=True)
            continue
        try:
            _paint(job)
            reply = (False, "")
        except Exception as err:  # noqa: BLE001 - reported to the caller, which raises
            reply = (isinstance(err, OSError), f"{type(err).__name__}: {err}"[:4000])
        with contextlib.suppress(BrokenPipeError):  # closed without waiting for the answers
            send(replies, reply)


def _remove_temporaries(paths) -> None:
    """Remove the temporaries :func:`gatetherm.atomic_path` made for ``paths`` (a process killed
    while writing one cannot)."""
    for path in paths:
        for tmp in path.parent.glob(f"{TEMP_PREFIX}{glob.escape(path.stem)}.*{glob.escape(path.suffix)}"):
            with contextlib.suppress(OSError):
                tmp.unlink()


def _can_fork() -> bool:
    from gatetherm.geometry.isolate import THREADS_STARTED

    return can_fork() and not THREADS_STARTED["here"]


class Painter:
    """Draws pictures in processes of its own, beside the caller's work (see the module).

    Parameters
    ----------
    workers : int
        Processes to draw in (at most 2); 0, or where the process cannot fork, each picture is
        drawn when given.

    A context manager: on its way out it stops the processes (:meth:`close`), at once when the
    block raised. Make it before the work it should overlap::

        with gt.plot.Painter() as painter:
            run = gt.run(case)
            run.write("out", painter=painter)   # pictures drawn while the fields are written
    """

    def __init__(self, workers: int = 2):
        self._pipes: list[tuple[int, int]] = []  # (jobs to write, replies to read), one per process
        self._queued: list[list[Path]] = []  # the pictures each is given and has not answered
        self._outbox: list[bytearray] = []  # what is not yet written to each one's pipe
        self._reserved: list[int] = []  # prepared work whose picture is not yet given, per process
        self._lock, self._writer, self._closing = threading.Lock(), None, False
        self._pid = None
        self._prepared: dict = {}  # work made ready: the process it was given to
        if workers > 0 and _can_fork():
            self._start(min(workers, 2))
        log.debug("pictures drawn by %d processes", self.workers)

    def _start(self, workers: int) -> None:
        pairs = [(os.pipe(), os.pipe()) for _ in range(workers)]  # (jobs r, w), (replies r, w)
        pid = fork()
        if pid == 0:  # pragma: no cover - the child's coverage is not collected
            code, child = 1, None
            try:
                end_with_parent()  # on SIGTERM the PNG being written (its temporary) is removed
                keep_freed(False)  # a picture's memory (a 3-D renderer's) not held while it waits
                for (jr, jw), (rr, rw) in pairs:
                    os.close(jw)
                    os.close(rr)
                _warm()
                mine = pairs[0]
                if len(pairs) > 1:  # the second process: matplotlib imported already
                    child = fork()
                    if child == 0:
                        end_with_parent()
                    mine, other = (pairs[1], pairs[0]) if child == 0 else (pairs[0], pairs[1])
                    os.close(other[0][0])  # the other's jobs and replies
                    os.close(other[1][1])
                _serve(mine[0][0], mine[1][1])
                code = 0
            except SystemExit:
                pass
            except BaseException as err:  # noqa: BLE001 - the caller reports the pictures not drawn
                if not _stopped(err):  # SIGTERM inside an extension's import comes out as an ImportError
                    log.exception("the painting process failed")
            finally:
                signal.signal(signal.SIGTERM, signal.SIG_IGN)  # a second SIGTERM here: no SystemExit out of the child
                if child:
                    with contextlib.suppress(OSError):
                        if code:  # stopped: the second one too
                            os.kill(child, signal.SIGTERM)
                        os.waitpid(child, 0)
                os._exit(code)
        self._pid = pid
        for (jr, jw), (rr, rw) in pairs:
            os.close(jr)
            os.close(rw)
            os.set_blocking(jw, False)  # what the pipe does not take waits in the outbox
            self._pipes.append((jw, rr))
            self._queued.append([])
            self._outbox.append(bytearray())
            self._reserved.append(0)

    @property
    def workers(self) -> int:
        """The number of processes drawing (0: each picture is drawn in this process)."""
        return len(self._pipes)

    def draw(self, plot, *args, path: str | os.PathLike, tight: bool = True, needs=None, **kwargs) -> None:
        """Write ``plot(*args, **kwargs)`` (a plot function of :mod:`gatetherm.validation.plots`,
        its arguments picklable) to the PNG ``path``, laid out by ``tight_layout`` if ``tight``;
        returns at once (what the pipe does not take, a thread writes while the process reads).
        ``needs``: work given to :meth:`prepare` for this picture; it goes to the process that did it."""
        job = (plot, args, kwargs, Path(path), tight)
        if not self._pipes:
            return _paint(job)
        k = self._prepared.pop(needs, None) if needs is not None else None
        if k is not None:
            self._reserved[k] -= 1
        self._hand(job, k)

    def prepare(self, work) -> None:
        """Have the process given fewer pictures call ``work()`` (picklable) meanwhile: what a
        picture drawn later with ``needs=work`` needs made ready (an import, a first small
        rendering) while the caller computes; till then that picture counts as given to it. The
        same ``work`` again, before its picture is drawn, is not handed. Without processes nothing
        is done."""
        if self._pipes and work not in self._prepared:
            self._prepared[work] = k = self._least()
            self._reserved[k] += 1
            self._hand((work, (), {}, None, False), k)

    def _least(self) -> int:
        """The process given fewer pictures (a tie: the first)."""
        return min(range(self.workers), key=lambda i: len(self._queued[i]) + self._reserved[i])

    def _hand(self, job, k: int | None = None) -> None:
        k = self._least() if k is None else k
        with self._lock:
            self._outbox[k] += message(job)
            if job[3] is not None:
                self._queued[k].append(job[3])
            if not self._flush(k) and not (self._writer and self._writer.is_alive()):
                self._writer = threading.Thread(target=self._drain, name="painter-writer", daemon=True)
                self._writer.start()

    def _flush(self, k: int) -> bool:
        """Write what the pipe of process ``k`` takes now; whether its outbox is empty."""
        box = self._outbox[k]
        try:
            while box:
                del box[:os.write(self._pipes[k][0], box)]
        except BlockingIOError:
            pass
        except BrokenPipeError:  # the process is gone: finish says so
            box.clear()
        return not box

    def _drain(self) -> None:
        """The writer thread: the outboxes into the pipes as the processes read them."""
        while not self._closing:
            with self._lock:
                waiting = [self._pipes[k][0] for k in range(self.workers) if not self._flush(k)]
            if not waiting:
                return
            select.select([], waiting, [], 0.05)

    def finish(self) -> None:
        """Wait for every picture given; raise the first failure (OSError for a file that could
        not be written, else RuntimeError), naming the picture."""
        start = time.monotonic()
        if self._writer is not None:
            self._writer.join()
        failed = None
        for (_, replies), queued in zip(self._pipes, self._queued):
            while queued:
                path, reply = queued.pop(0), receive(replies)
                if reply is None:  # the process is gone
                    failed = failed or RuntimeError(f"{path.name}: the process drawing it ended")
                    queued.clear()
                elif reply[1]:
                    failed = failed or (OSError if reply[0] else RuntimeError)(f"{path.name}: {reply[1]}")
        if self._pipes:
            log.info("pictures: %.2f s waited for the painter", time.monotonic() - start)
        if failed is not None:
            raise failed

    def close(self, kill: bool = False) -> None:
        """Stop the processes: once they have drawn what they were given, or at once if
        ``kill`` (SIGTERM: the PNG being drawn is not written; SIGKILL after :data:`STOP_S`)."""
        self._closing = kill  # else the writer thread first writes out what is given
        if self._writer is not None:
            self._writer.join()
        for jobs, replies in self._pipes:
            os.close(jobs)
            os.close(replies)
        given = [path for queued in self._queued for path in queued]
        self._pipes, self._queued, self._outbox, self._reserved, self._prepared = [], [], [], [], {}
        pid, self._pid = self._pid, None
        if pid is None:
            return
        if kill:
            os.kill(pid, signal.SIGTERM)
            end = time.monotonic() + STOP_S
            while os.waitpid(pid, os.WNOHANG) == (0, 0):
                if time.monotonic() > end:  # inside a long rendering: killed, its temporary removed here
                    os.kill(pid, signal.SIGKILL)
                    os.waitpid(pid, 0)
                    _remove_temporaries(given)
                    return
                time.sleep(0.01)
            else:
                return
        os.waitpid(pid, 0)

    def __enter__(self) -> Painter:
        return self

    def __exit__(self, kind, err, tb) -> None:
        self.close(kill=kind is not None)
