"""The live service run in this process until SIGINT or SIGTERM, with its status page:
what ``gatetherm live`` runs once its stepper, journal and node map are made."""
from __future__ import annotations

import asyncio
import contextlib
import signal
import threading

from gatetherm import InputError
from gatetherm.process import frozen_heap
from gatetherm.validation.live.service import serve
from gatetherm.validation.live.status import Status, serve_status


async def serve_until_signal(stepper, journal, endpoint, nodes, params, read, on_period, status_port):
    """The live service (:func:`~gatetherm.validation.live.service.serve`) in this process until
    SIGINT or SIGTERM (from the main thread; the handlers given back after), with its status page
    on ``status_port`` (None: none); the service's counts."""
    stop = asyncio.Event()
    loop = asyncio.get_running_loop()
    handled = []
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGINT, signal.SIGTERM):
            old = signal.getsignal(sig)
            with contextlib.suppress(ValueError, RuntimeError):
                loop.add_signal_handler(sig, stop.set)
                handled.append((sig, old))
    status = server = None
    if status_port is not None:
        status = Status(journal.dir, stepper.columns)
        try:
            server = await serve_status(status, status_port)
        except OSError as err:
            raise InputError("--status-port", f"cannot serve on 127.0.0.1:{status_port} ({err.strerror})",
                             "give a free port") from None
    try:
        with frozen_heap():  # the modules and the model out of the full collections (~65 CPU-ms each otherwise)
            return await serve(stepper, journal, endpoint, nodes, params, read, on_period, stop, status)
    finally:
        if server is not None:
            server.close()
        for sig, old in handled:
            loop.remove_signal_handler(sig)
            signal.signal(sig, old)
