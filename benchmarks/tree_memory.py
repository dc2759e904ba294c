"""Peak memory of a command with every process it forks, against its largest process's (Linux).

    python benchmarks/tree_memory.py [--rounds 3] [--every 1.0] -- gatetherm simulate --condition 1 --dim 3 --out DIR

``benchmarks/peer.py`` reports a job's peak resident memory as ``wait4`` gives it: the largest of
the process and its waited-for children, each counted whole. With the painter's processes and the
elastic solver's helper beside the run, what the machine must hold is their sum, the pages they
share counted once: the proportional set size (PSS, ``/proc/PID/smaps_rollup``) summed over the
command's process tree, sampled every 50 ms (a shorter peak may be missed). Prints, per round,
that peak sum, each process's share of it (in the order the processes were started: the command
first), and the ``wait4`` figure; with ``--every S``, also the processes' PSS every S seconds.
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import time


def tree(root: int) -> list[int]:
    """``root`` and its descendants, by the parent ids in ``/proc/PID/stat``."""
    parent = {}
    for name in os.listdir("/proc"):
        if name.isdigit():
            try:
                with open(f"/proc/{name}/stat") as f:
                    parent[int(name)] = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, IndexError, ValueError):
                continue
    out, todo = [], [root]
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo += [p for p, pp in parent.items() if pp == pid]
    return out


def pss_kb(pid: int) -> int:
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            return next(int(line.split()[1]) for line in f if line.startswith("Pss:"))
    except (OSError, StopIteration):
        return 0


def measure(cmd: list[str], every: float | None = None) -> dict:
    """Run ``cmd`` to its end: peak summed PSS of its tree (GB), each process's PSS then (GB, by
    process id), wait4's peak (GB), wall s; every ``every`` s the processes' PSS printed."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    peak, shares, shown = 0, [], -1
    while not (done := os.wait4(p.pid, os.WNOHANG))[0]:
        pss = {pid: pss_kb(pid) for pid in sorted(tree(p.pid))}
        total = sum(pss.values())
        if total > peak:
            peak, shares = total, [v / 1e6 for v in pss.values()]
        t = time.perf_counter() - t0
        if every and int(t / every) > shown:
            shown = int(t / every)
            print(f"  {t:5.1f} s: {total / 1e6:.2f} GB = " + " + ".join(f"{v / 1e6:.2f}" for v in pss.values()),
                  flush=True)
        time.sleep(0.05)
    p.returncode = os.waitstatus_to_exitcode(done[1])
    if p.returncode:
        raise SystemExit(f"{' '.join(cmd)} failed (exit {p.returncode})")
    return {"pss_gb": peak / 1e6, "shares": shares, "wall": time.perf_counter() - t0, "rss_gb": done[2].ru_maxrss / 1e6}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--every", type=float, metavar="S", help="print the processes' PSS every S seconds")
    ap.add_argument("cmd", nargs=argparse.REMAINDER, help="the command, after --")
    args = ap.parse_args()
    cmd = args.cmd[1:] if args.cmd[:1] == ["--"] else args.cmd
    runs = []
    for r in range(args.rounds):
        res = measure(cmd, args.every)
        runs.append(res)
        print(f"round {r + 1}: tree {res['pss_gb']:.2f} GB (PSS, {len(res['shares'])} processes: "
              + " + ".join(f"{v:.2f}" for v in res["shares"])
              + f"), largest process {res['rss_gb']:.2f} GB (wait4), wall {res['wall']:.1f} s", flush=True)
    print(f"median: tree {statistics.median(r['pss_gb'] for r in runs):.2f} GB, largest process "
          f"{statistics.median(r['rss_gb'] for r in runs):.2f} GB")


if __name__ == "__main__":
    main()
