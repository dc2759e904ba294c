"""Check a report page: every image and link resolves (read from the HTML), and headless
Chromium renders it without a console message, a failed load or a broken image; saves a
screenshot.

Chromium runs off line with a fresh profile (``--headless --no-sandbox --disable-gpu
--disable-background-networking --disable-component-update --disable-sync --no-first-run
--user-data-dir=TMP``). Images that fail to decode are caught by a probe copy of the page
with a small script that lists them after the load event (the page itself has no script).
"""
from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlparse

FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
         "--disable-component-update", "--disable-sync", "--no-first-run", "--enable-logging=stderr", "--v=0")
PROBE = """<script>window.addEventListener("load", function () {
  var bad = [], imgs = document.images;
  for (var i = 0; i < imgs.length; i++) if (!imgs[i].complete || imgs[i].naturalWidth === 0) bad.push(imgs[i].getAttribute("src"));
  document.body.setAttribute("data-images", String(imgs.length));
  document.body.setAttribute("data-broken", bad.join(" "));
});</script>"""
"""Injected into the probe copy only."""
PROBE_NAME = ".browser-check.html"
ERRORS = re.compile(r"net::ERR_\w+|ERR_FILE_NOT_FOUND|Failed to load resource|Not allowed to load local resource")


@dataclass
class Check:
    """What a check found."""

    problems: list[str] = field(default_factory=list)
    """One line each; empty: the page is clean."""
    images: int = 0
    """``img`` elements in the HTML."""
    links: int = 0
    """``a href`` elements in the HTML."""
    rendered_images: int | None = None
    """Images the browser counted on the page (None: not rendered)."""
    screenshot: Path | None = None
    """The PNG written, if any."""


class _Page(HTMLParser):
    def __init__(self):
        super().__init__()
        self.images, self.links, self.ids = [], [], set()

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "img":
            self.images.append(a.get("src") or "")
        elif tag == "a" and "href" in a:
            self.links.append(a["href"])


def _image_ok(path: Path) -> bool:
    from PIL import Image

    try:
        with Image.open(path) as im:
            im.verify()
        return True
    except Exception:  # noqa: BLE001 - any failure to decode is a broken image
        return False


def static_check(index: Path) -> Check:
    """Every ``img src`` is a local image that decodes; every ``a href`` is a local file or an
    anchor of the page (the page is self-contained: no network address)."""
    index = Path(index)
    page = _Page()
    page.feed(index.read_text(encoding="utf-8"))
    out = Check(images=len(page.images), links=len(page.links))
    for src in page.images:
        p = index.parent / unquote(src)
        if urlparse(src).scheme or not p.is_file():
            out.problems.append(f"image {src!r}: no such file beside the page")
        elif not _image_ok(p):
            out.problems.append(f"image {src!r}: does not decode")
    for href in page.links:
        u = urlparse(href)
        if u.scheme:
            out.problems.append(f"link {href!r}: not a local file (the page must work off line)")
        elif not u.path:
            if u.fragment not in page.ids:
                out.problems.append(f"link {href!r}: no element with that id")
        elif not (index.parent / unquote(u.path)).exists():
            out.problems.append(f"link {href!r}: no such file")
    return out


def chromium() -> str | None:
    return shutil.which("chromium") or shutil.which("chromium-browser")


def _run(exe: str, args: list[str], profile: Path, timeout: float) -> subprocess.CompletedProcess:
    return subprocess.run([exe, *FLAGS, f"--user-data-dir={profile}", *args], capture_output=True, text=True,
                          timeout=timeout)


def _console(stderr: str) -> list[str]:
    """Console messages and failed loads in Chromium's log."""
    return [ln.strip() for ln in stderr.splitlines() if ":CONSOLE" in ln or ERRORS.search(ln)]


def browser_check(index: Path, screenshot: Path, exe: str | None = None, width: int = 1280, height: int = 3000,
                  timeout: float = 180.0) -> Check:
    """:func:`static_check`, then render the page in headless Chromium: a console message, a
    failed load or an image the browser cannot show is a problem; the top ``width`` × ``height``
    pixels go to ``screenshot`` (PNG)."""
    index, screenshot = Path(index).resolve(), Path(screenshot).resolve()
    out = static_check(index)
    exe = exe or chromium()
    if exe is None:
        out.problems.append("chromium is not installed")
        return out
    probe = index.parent / PROBE_NAME
    text = index.read_text(encoding="utf-8").replace(' loading="lazy"', "")
    probe.write_text(text.replace("</body>", PROBE + "</body>"), encoding="utf-8")
    try:
        with tempfile.TemporaryDirectory(prefix="gatetherm-chromium-") as tmp:
            dom = _run(exe, ["--virtual-time-budget=20000", "--dump-dom", probe.as_uri()], Path(tmp) / "a", timeout)
            shot = _run(exe, [f"--window-size={width},{height}", "--virtual-time-budget=20000",
                              f"--screenshot={screenshot}", index.as_uri()], Path(tmp) / "b", timeout)
    finally:
        probe.unlink(missing_ok=True)
    for name, run in (("probe", dom), ("screenshot", shot)):
        if run.returncode != 0:
            out.problems.append(f"chromium ({name}) exited with {run.returncode}")
        out.problems += [f"browser: {ln}" for ln in _console(run.stderr)]
    body = re.search(r"<body[^>]*>", dom.stdout)
    attrs = dict(re.findall(r'data-(images|broken)="([^"]*)"', body.group(0))) if body else {}
    if "images" not in attrs:
        out.problems.append("chromium did not finish loading the page (no probe result in the DOM)")
    else:
        out.rendered_images = int(attrs["images"])
        out.problems += [f"browser: image {src!r} did not load" for src in attrs["broken"].split()]
        if out.rendered_images != out.images:
            out.problems.append(f"browser counted {out.rendered_images} images, the HTML has {out.images}")
    if screenshot.is_file() and screenshot.stat().st_size > 0:
        out.screenshot = screenshot
    else:
        out.problems.append("no screenshot written")
    return out
