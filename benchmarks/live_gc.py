"""What one full collection of garbage costs a ``live`` service and a ``twin`` of N machines, with
their heaps as set up and with them frozen (``gatetherm.process.frozen_heap``, as both run now).

    python benchmarks/live_gc.py [--machines 100]

A service: the process after ``import gatetherm; gatetherm.live`` and asyncua. A twin: the same
process with an OPC UA server of N machines' namespaces of 15 variables each (the layout
``gatetherm twin --machines N`` builds). Also what a service's imports cost. CPU time of
``gc.collect()`` (median of 3), before and after ``gc.freeze()``. A full
collection stops the whole process (every machine of a twin) for as long as it takes.
"""
from __future__ import annotations

import argparse
import asyncio
import gc
import math
import statistics
import time


def _collect_ms() -> float:
    times = []
    for _ in range(3):
        c = time.process_time()
        gc.collect()
        times.append(1e3 * (time.process_time() - c))
    return statistics.median(times)


def _measure(label: str) -> None:
    objects = len(gc.get_objects())
    before = _collect_ms()
    gc.freeze()
    after = _collect_ms()
    gc.unfreeze()
    print(f"{label}: {objects} objects tracked; a full collection {before:.1f} CPU-ms, frozen {after:.1f} CPU-ms")


async def _twin(machines: int) -> None:
    import logging

    from asyncua import Server, ua

    logging.getLogger("asyncua").setLevel(logging.ERROR)
    server = Server()
    await server.init()
    for i in range(machines):
        idx = await server.register_namespace(f"urn:gatetherm:machine:{i + 1}")
        obj = await server.nodes.objects.add_object(ua.NodeId("Machine", idx), ua.QualifiedName("Machine", idx))
        for n in range(15):
            await obj.add_variable(ua.NodeId(f"v{n}", idx), ua.QualifiedName(f"v{n}", idx), math.nan,
                                   ua.VariantType.Double)
    _measure(f"twin of {machines} machines (gatetherm imported as above, the server set up)")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machines", type=int, default=100)
    a = ap.parse_args()
    import resource
    import sys

    cpu = time.process_time()
    import asyncua  # noqa: F401

    import gatetherm as gt

    gt.live  # noqa: B018 - the API a service imports
    heavy = [m for m in ("skfem", "scipy.signal", "scipy.stats", "scipy.optimize") if m in sys.modules]
    print(f"a service's imports (gatetherm.live, asyncua): {time.process_time() - cpu:.2f} CPU-s, {len(sys.modules)} "
          f"modules ({', '.join(heavy)} among them), {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB RSS")
    _measure("live service (gatetherm.live and asyncua imported)")
    asyncio.run(_twin(a.machines))


if __name__ == "__main__":
    main()
