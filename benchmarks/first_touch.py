"""What memory new to a process costs on this machine: the first touch of each page.

    python benchmarks/first_touch.py [--gb 1 6] [--rounds 3]

For each size, a fresh interpreter maps that many GB of anonymous memory, writes one byte per
4 KiB page, and reports the seconds, the system time and the page faults it took; then the same
with transparent huge pages asked for (``madvise(MADV_HUGEPAGE)``, as numpy does for its large
arrays unless told not to). The sizes and the two kinds interleaved per round; medians printed.

On a machine whose host takes back the memory its guest frees (a virtual machine with free page
reporting), memory new to the guest costs what the host charges to fault it in, and that is
what a large run pays for each GB it takes beyond what it freed itself (``docs/performance.md``,
"2026-12-06 night"). On a bare machine the same write costs about as much as zeroing it.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys

MADV_HUGEPAGE = 14


def touch(gb: float, huge: bool) -> dict:
    """In this process: map ``gb`` GB, write each page once; seconds, system seconds, faults."""
    import ctypes
    import mmap
    import resource
    import time

    size = int(gb * 2 ** 30)
    m = mmap.mmap(-1, size, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS)
    buf = (ctypes.c_char * size).from_buffer(m)
    if huge:
        ctypes.CDLL(None).madvise(ctypes.c_void_p(ctypes.addressof(buf)), ctypes.c_size_t(size), MADV_HUGEPAGE)
    view = memoryview(m).cast("B")
    r0, t0 = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    view[::4096] = b"\1" * len(range(0, size, 4096))
    secs, r1 = time.perf_counter() - t0, resource.getrusage(resource.RUSAGE_SELF)
    return {"s": secs, "sys": r1.ru_stime - r0.ru_stime, "faults": r1.ru_minflt - r0.ru_minflt}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--gb", type=float, nargs="+", default=[1.0, 6.0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)  # GB, huge: one touch in this interpreter
    args = ap.parse_args()
    if args.one:
        print(json.dumps(touch(float(args.one[0]), args.one[1] == "huge")))
        return
    runs: dict = {}
    for _ in range(args.rounds):
        for gb in args.gb:
            for kind in ("4 KiB", "huge"):
                out = subprocess.run([sys.executable, __file__, "--one", str(gb), kind], check=True,
                                     capture_output=True, text=True).stdout
                runs.setdefault((gb, kind), []).append(json.loads(out.splitlines()[-1]))
    print(f"medians of {args.rounds} rounds, each touch in a new interpreter:")
    for (gb, kind), rs in runs.items():
        s, sys_s, faults = (statistics.median(r[k] for r in rs) for k in ("s", "sys", "faults"))
        each = ", ".join(f"{r['s']:.2f}" for r in rs)
        print(f"  {gb:g} GB, {kind:5s} pages: {s:6.2f} s ({s / gb:5.2f} s per GB; runs {each}), "
              f"system {sys_s:6.2f} s, {faults / 1e3:7.1f} k faults")


if __name__ == "__main__":
    main()
