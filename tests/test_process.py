"""Process-wide settings of :func:`gatetherm.configure`: numpy's huge-page advice is off after it,
unless numpy's own ``NUMPY_MADVISE_HUGEPAGE`` says how it should be."""
from __future__ import annotations

import os
import subprocess
import sys

import pytest

ADVICE_AFTER_CONFIGURE = ("import gatetherm as gt; from gatetherm.process import _huge_page_advice as advice; "
                          "gt.configure(); print(advice(True))")


@pytest.mark.parametrize("setting, advised", [(None, "False"), ("1", "True"), ("0", "False")])
def test_configure_turns_numpys_huge_page_advice_off_unless_numpy_is_told(setting, advised):
    env = {k: v for k, v in os.environ.items() if k != "NUMPY_MADVISE_HUGEPAGE"}
    if setting is not None:
        env["NUMPY_MADVISE_HUGEPAGE"] = setting
    out = subprocess.run([sys.executable, "-c", ADVICE_AFTER_CONFIGURE], env=env, capture_output=True, text=True,
                         check=True)
    assert out.stdout.strip() == advised
