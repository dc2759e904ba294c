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


@pytest.mark.skipif(not (shutil.which("chromium") or shutil.which("chromium-browser")), reason="chromium not installed")
def test_status_page_renders_in_a_headless_browser(tmp_path):
    exe = shutil.which("chromium") or shutil.which("chromium-browser")

    def render(url):
        return subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu", f"--user-data-dir={tmp_path / 'p'}",
                               "--dump-dom", url + "/"], capture_output=True, text=True, timeout=300).stdout

    dom, _ = serve_and(tmp_path, render)
    assert "<svg id=\"chart\"" in dom and "missing" in dom and "gatetherm live" in dom
