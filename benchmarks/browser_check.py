"""Render a gatetherm report page in headless Chromium and fail on a missing image, a broken
link or a console error; save a screenshot.

    python benchmarks/browser_check.py R/index.html [--screenshot R/screenshot.png]

Exit status 0 when the page is clean, 1 otherwise (every problem is printed).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from gatetherm.validation.report.browser import browser_check


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("index", type=Path, help="the page, e.g. R/index.html")
    p.add_argument("--screenshot", type=Path, help="PNG to write (default: screenshot.png beside the page)")
    args = p.parse_args()
    t0 = time.perf_counter()
    c = browser_check(args.index, args.screenshot or args.index.parent / "screenshot.png")
    print(f"{args.index}: {c.images} images, {c.links} links; the browser showed {c.rendered_images} images; "
          f"screenshot {c.screenshot}; {time.perf_counter() - t0:.1f} s")
    for problem in c.problems:
        print(f"PROBLEM {problem}")
    print("browser check: " + ("passed" if not c.problems else f"FAILED ({len(c.problems)} problems)"))
    return 1 if c.problems else 0


if __name__ == "__main__":
    sys.exit(main())
