"""The OPC UA side of ``gatetherm live``: connect and resolve the map's nodes, read one consistent
sample, write the correction, and pace the reads between periods (:class:`Pace`)."""
from __future__ import annotations

import math
from collections import deque

from gatetherm.validation.live.nodes import NodeMap


async def _connect(url: str, nodes: NodeMap, timeout: float):
    """A connected client and the map's nodes; a failed attempt closes what it opened (a control
    has few sessions to spare, and an attempt that timed out half-way would keep one)."""
    from asyncua import Client, ua

    # its watchdog reads the server's state every watchdog_intervall s with that as the timeout (default
    # 1 s): a loaded control (one twin with 100 clients) would be declared lost; probe at the request timeout
    client = Client(url, timeout=timeout, watchdog_intervall=timeout)
    try:
        await client.connect()
        resolved, index = {}, {}
        for table in (nodes.read, nodes.write):
            for name, text in table.items():
                nid = ua.NodeId.from_string(text)
                uri = getattr(nid, "NamespaceUri", None)
                if uri:
                    if uri not in index:
                        index[uri] = await client.get_namespace_index(uri)
                    nid = ua.NodeId(nid.Identifier, index[uri], nid.NodeIdType)
                resolved[name] = client.get_node(nid)
    except BaseException:
        try:
            client.disconnect_socket()
        except Exception:  # noqa: BLE001 - nothing was opened
            pass
        raise
    return client, resolved


async def _sample(client, nodes, names, scale) -> dict | None:
    """One consistent sample (``time_s`` read before and after the rest), or None."""
    order = ("time_s", *names, "time_s")
    values = await client.read_values([nodes[n] for n in order])
    t0, t1 = values[0], values[-1]
    if t0 is None or t1 is None or not (math.isfinite(t0) and t0 == t1):
        return None
    return {n: (math.nan if v is None else float(v) / scale(n)) for n, v in zip(order, values)}


async def _write(resolved, nodes: NodeMap, offset: float, gradient=None, reference=None) -> None:
    """Write the offset and, where the compensator gives them and the map names them, the gradient
    and its reference position."""
    from asyncua import ua

    for name, value in (("offset_um", offset), ("gradient_um_per_m", gradient), ("reference_m", reference)):
        if name in resolved and name in nodes.write and value is not None and math.isfinite(value):
            await resolved[name].write_value(ua.DataValue(ua.Variant(value * nodes.factor(name), ua.VariantType.Double)))


async def _close(client) -> None:
    if client is not None:
        try:
            await client.disconnect()
        except Exception:  # noqa: BLE001 - the link is gone already
            pass


class Pace:
    """How long to wait before the next read. Right after a period the next sample is not due for
    about the wall time between the last periods (the smallest of the last five: a clock that
    speeds up is followed): the service waits until ``lead`` of it is left (a twentieth of it, at
    least two polls), then reads every ``poll_s``. Before any period is seen and after a
    reconnection, every ``poll_s``; after one period but before the interval is known (the second
    period, after a gap) the waits double from ``poll_s`` up to ``unknown_s`` (a sample is seen at
    most that late, and 100 services starting together read 4 times a second each, not 20). Each
    read is a request to the control: a 1-s period costs about 3 reads instead of 20, a 60-s one
    about 60 instead of 1200."""

    def __init__(self, poll_s: float, unknown_s: float = 0.25):
        self.poll, self.last, self.intervals = poll_s, None, deque(maxlen=5)
        self.unknown, self.waits = max(poll_s, unknown_s), 0

    def handled(self, k: int, wall: float) -> None:
        """Period ``k`` was read at ``wall`` (monotonic s)."""
        if self.last is not None and k == self.last[0] + 1:
            self.intervals.append(wall - self.last[1])
        elif self.last is not None:
            self.intervals.clear()
        self.last, self.waits = (k, wall), 0

    def reset(self) -> None:
        """The link was lost: poll until a period is seen, then back off until the interval is known."""
        self.last = None
        self.intervals.clear()

    def wait(self, now: float) -> float:
        """Wall seconds to wait before the next read (``now`` monotonic s); each call counts as a wait."""
        if self.last is None:
            return self.poll
        if not self.intervals:
            self.waits += 1
            return min(self.poll * 2.0 ** (self.waits - 1), self.unknown)
        per = min(self.intervals)
        return max(self.poll, self.last[1] + per - max(2.0 * self.poll, 0.05 * per) - now)
