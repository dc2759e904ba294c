"""The status page of ``gatetherm live --status-port`` (validation/live/status.py) over real HTTP on
loopback: δ, the correction and each sensor's health while the rows come in; the same as JSON; and,
where chromium is installed, rendered by a headless browser."""
from __future__ import annotations

import asyncio
import json
import math
import shutil
import socket
import subprocess
import urllib.error
import urllib.request

import pytest

from gatetherm.validation.live.status import Status, serve_status

SENSORS = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def rows():
    for k in range(400):  # 400 min: the first 40 fall out of the 6-h span
        a = math.nan if k == 399 else 20.0 + 0.01 * k
        yield {"time_s": 60.0 * k, "theta_A_degC": a, "theta_B_degC": 20.0, "theta_C_degC": 20.0,
               "delta_um": 0.1 * k, "delta_residual_um": 0.5, "offset_um": -0.1 * k, "held": int(k == 399)}


def get(url: str) -> tuple[int, str]:
    try:
        with urllib.request.urlopen(url, timeout=60) as r:
            return r.status, r.read().decode()
    except urllib.error.HTTPError as err:
        return err.code, ""


def serve_and(tmp_path, fetch):
    (tmp_path / "events.log").write_text("23940 sample held: theta_A_degC missing; correction held at -39.800 um\n")
    status, port = Status(tmp_path, SENSORS), free_port()
    counts = {"periods": 0, "held": 0}
    for row in rows():
        counts = {"periods": counts["periods"] + 1, "held": counts["held"] + row["held"]}
        status.add(row, counts)

    async def run():
        server = await serve_status(status, port)
        try:
            return await asyncio.get_running_loop().run_in_executor(None, fetch, f"http://127.0.0.1:{port}")
        finally:
            server.close()
            await server.wait_closed()

    return asyncio.run(asyncio.wait_for(run(), 600)), status


def test_status_page_and_json_over_http(tmp_path):
    (page, data, missing), status = serve_and(tmp_path, lambda url: (get(url + "/"), get(url + "/status.json"),
                                                                      get(url + "/nothing")))
    assert page[0] == 200 and data[0] == 200 and missing[0] == 404
    html = page[1]
    assert "http-equiv='refresh'" in html and "<svg id='chart'" in html and html.count("<polyline") == 3
    assert "<td class='missing'>missing</td>" in html and "theta_A_degC missing" in html
    d = json.loads(data[1])
    assert d["time_s"] == 23940.0 and d["counts"] == {"periods": 400, "held": 1}
    assert d["sensors"]["theta_A_degC"]["state"] == "missing" and d["sensors"]["delta_um"]["state"] == "held"
    assert len(d["series"]["delta_um"]) == 361 and d["series"]["delta_um"][0][0] == 2340.0  # the last 6 h


CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync",
         "--disable-dev-shm-usage")
"""Off line and as root (docs/live.md): without them chromium waits on the closed network (and a
container's small /dev/shm is not used)."""


@pytest.fixture(scope="module")
def chromium(tmp_path_factory) -> str:
    """The browser, once it has rendered a trivial page here; else the test skips with chromium's
    own last line (a machine where it is installed but cannot start, e.g. without a display
    library, says so instead of failing)."""
    if CHROMIUM is None:
        pytest.skip("chromium not installed (.ci/run installs Debian's chromium)")
    profile = tmp_path_factory.mktemp("probe")
    try:
        done = subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", "--dump-dom",
                               "data:text/html,<p id=probe>ready</p>"], capture_output=True, text=True, timeout=120)
    except subprocess.TimeoutExpired:
        pytest.skip("chromium did not render a trivial page in 120 s here")
    if "ready" not in done.stdout:
        pytest.skip(f"chromium cannot render here: {(done.stderr.strip().splitlines() or ['no output'])[-1][:200]}")
    return CHROMIUM


class Ticking(Status):
    """The service's status with one more period in at every request of the page, as if a
    period passed between two looks."""

    def __init__(self, directory, rows):
        super().__init__(directory, SENSORS)
        self.pending, self.served = list(rows), 0

    def page(self) -> str:
        if self.pending:
            row = self.pending.pop(0)
            self.add(row, {"periods": int(row["time_s"] // 60) + 1, "held": row["held"], "limited": 0})
        self.served += 1
        return super().page()


def test_status_page_in_a_headless_browser(tmp_path, chromium):
    """What an operator sees: the DOM after the page's script ran in headless chromium. The page
    is fetched again every 5 s (virtual time: ``--virtual-time-budget`` runs the timers without
    waiting on the wall clock), and each look shows one more period: δ, the correction, each
    sensor's health, the guards that fired, the events; then the service stops answering and the
    page says it is stale instead of showing old values as live."""
    (tmp_path / "events.log").write_text("23940 sample held: theta_A_degC missing; correction held at -39.800 um\n")
    all_rows = list(rows())
    status = Ticking(tmp_path, all_rows[-3:])
    for row in all_rows[:-3]:
        status.add(row, {"periods": int(row["time_s"] // 60) + 1, "held": 0, "limited": 0})
    dom = look(tmp_path, status, 12000)
    assert status.served == 3  # the first look and two refreshes, 5 s and 10 s of virtual time on
    assert 'data-refreshed="2"' in dom and "updated every" not in dom  # the script swapped the content in
    now = dom[dom.index('<p id="now">'):]
    now = now[:now.index("</p>")]
    # the third look: period 399 (the last row), δ 39.9 µm, compensated 0.5 µm, correction -39.9 µm
    assert now == '<p id="now">machine time 23940 s; δ measured 39.90 µm; δ compensated 0.50 µm; correction -39.90 µm'
    assert '<td>theta_A_degC</td><td></td><td class="missing">missing</td>' in dom
    assert '<td>theta_B_degC</td><td>20.000</td><td class="held">held</td>' in dom
    assert '<p id="fired">fired: held (1)</p>' in dom and "<li>periods: 400</li>" in dom
    assert "theta_A_degC missing; correction held at -39.800 um" in dom
    assert dom.count("<polyline") == 3 and '<svg id="chart"' in dom

    # the service stops answering after the second look: the page keeps the second look's content
    # and says since when it is not updated
    status = Ticking(tmp_path, all_rows[-3:])
    for row in all_rows[:-3]:
        status.add(row, {"periods": int(row["time_s"] // 60) + 1, "held": 0, "limited": 0})
    dom = look(tmp_path, status, 12000, close_after=2)
    assert status.served == 2 and 'data-refreshed="1"' in dom
    assert '<p id="link" class="stale">NOT UPDATED since' in dom and "the service does not answer" in dom
    assert '<p id="now">machine time 23880 s; δ measured 39.80 µm' in dom


def look(tmp_path, status, budget_ms, close_after=None) -> str:
    """The DOM of the status page after ``budget_ms`` of the browser's virtual time; with
    ``close_after``, the server stops listening once it has served the page that many times."""
    port, profile = free_port(), tmp_path / f"profile{status.served}{close_after}"

    def render(url):
        return subprocess.run([CHROMIUM, *FLAGS, f"--user-data-dir={profile}", f"--virtual-time-budget={budget_ms}",
                               "--dump-dom", url + "/"], capture_output=True, text=True, timeout=300).stdout

    async def run():
        server = await serve_status(status, port)
        loop = asyncio.get_running_loop()
        if close_after is not None:
            page = status.page

            def counted():
                text = page()
                if status.served >= close_after:
                    loop.call_soon_threadsafe(server.close)
                return text
            status.page = counted
        try:
            return await loop.run_in_executor(None, render, f"http://127.0.0.1:{port}")
        finally:
            server.close()
            await server.wait_closed()

    return asyncio.run(asyncio.wait_for(run(), 600))
