"""Process-wide settings of :func:`gatetherm.configure`: numpy's huge-page advice is off after it,
unless numpy's own ``NUMPY_MADVISE_HUGEPAGE`` says how it should be; glibc's malloc keeps freed
memory till :func:`gatetherm.process.give_back` returns it."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

from gatetherm.process import host_reclaims_freed_memory, virtual_machine

ADVICE_AFTER_CONFIGURE = ("import gatetherm as gt; from gatetherm.process import _huge_page_advice as advice; "
                          "gt.configure(); print(advice(True))")


@pytest.mark.parametrize("setting, advised", [(None, str(not virtual_machine())), ("1", "True"), ("0", "False")])
def test_configure_turns_numpys_huge_page_advice_off_unless_numpy_is_told(setting, advised):
    """Off on a virtual machine (this one: the CPU's hypervisor flag), numpy's own elsewhere."""
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if setting is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = setting
    out = subprocess.run([sys.executable, "-c", ADVICE_AFTER_CONFIGURE], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == advised


KEPT_AFTER_CONFIGURE = """
import sys
import numpy as np
import gatetherm as gt
from gatetherm.process import give_back, keep_freed

def resident():  # MB
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 >> 20
if sys.argv[1] != "plain":
    gt.configure()
if sys.argv[1] == "painter":
    keep_freed(False)
a = np.ones(8 << 20)  # 64 MB
before = resident()
del a
freed = before - resident()
give_back()
print(freed, before - resident())
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc's malloc")
@pytest.mark.parametrize("how, kept", [("configure", host_reclaims_freed_memory()), ("painter", False),
                                       ("plain", False)])
def test_configure_keeps_freed_arrays_till_given_back(how, kept):
    """After configure, on a machine whose host takes back freed memory (this one), a freed 64 MB
    array stays resident for the next arrays until give_back returns it; a painting process
    (keep_freed(False)), like a plain one, returns it when freed."""
    out = subprocess.run([sys.executable, "-c", KEPT_AFTER_CONFIGURE, how], capture_output=True, text=True, check=True)
    freed, given_back = map(int, out.stdout.split())
    assert freed < 2 if kept else freed >= 63  # MB back to the system when freed
    assert given_back >= 63  # MB back once given back
