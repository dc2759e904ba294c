"""The status page of ``gatetherm live --status-port N``: a small page on loopback that an operator
looks at instead of reading ``live.csv``.

``http://127.0.0.1:N/`` shows the last hours of δ, the compensated δ (where the machine reports it)
and the correction as inline SVG, each sensor's health (its last value; ``missing`` where it was
NaN, ``held`` where the last period was held), the guards that fired, their counts and the last
events. A small inline script fetches the page again every :data:`REFRESH_S` seconds and swaps its
content in place (no reload, no flicker); when the service stops answering the page keeps what it
showed and says in red since when it is not updated (an operator must not read a stale page as
live). Without script it reloads itself. ``/status.json`` is the same as data. Served by asyncio in
the service's own loop, on 127.0.0.1 only; no external resource.
"""
from __future__ import annotations

import asyncio
import html
import json
import math
from collections import deque
from pathlib import Path

REFRESH_S = 5
"""The page reloads itself after this many seconds."""
SERIES = (("delta_um", "#c0392b", "δ measured"), ("delta_residual_um", "#2c7a2c", "δ compensated"),
          ("offset_um", "#1f4e9c", "correction"))
GUARDS = ("missed", "held", "limited", "reconnects", "worse")
"""The counts that say a guard fired (shown under "fired" when not zero)."""
SCRIPT = """<script>(function () {
  var n = 0, link = document.getElementById("link"), ok = new Date();
  function refresh() {
    fetch("/", {cache: "no-store"}).then(function (r) {
      if (!r.ok) throw new Error("HTTP " + r.status);
      return r.text();
    }).then(function (text) {
      var live = new DOMParser().parseFromString(text, "text/html").getElementById("live");
      if (!live) throw new Error("no content");
      document.getElementById("live").replaceWith(live);
      ok = new Date(); n += 1;
      document.body.setAttribute("data-refreshed", String(n));
      link.className = ""; link.textContent = "updated " + ok.toLocaleTimeString();
    }).catch(function (err) {
      link.className = "stale";
      link.textContent = "NOT UPDATED since " + ok.toLocaleTimeString() + ": the service does not answer (" + err.message + ")";
    });
  }
  setInterval(refresh, %d);
})();</script>"""
"""The page's script: fetch the page every REFRESH_S s and swap ``#live`` in place; say when it is stale."""


class Status:
    """The rows of the last ``hours`` of machine time and the counts, as a page."""

    def __init__(self, directory: Path, sensors, hours: float = 6.0):
        self.dir, self.sensors, self.span_s = Path(directory), tuple(sensors), hours * 3600.0
        self.rows: deque[dict] = deque()
        self.counts: dict = {}

    def add(self, row: dict, counts: dict) -> None:
        """Keep one period's row (older ones beyond the span are dropped)."""
        self.rows.append(dict(row))
        self.counts = dict(counts)
        while self.rows and self.rows[0]["time_s"] < row["time_s"] - self.span_s:
            self.rows.popleft()

    def events(self, n: int = 20) -> list[str]:
        """The last ``n`` lines of ``events.log``."""
        p = self.dir / "events.log"
        return p.read_text(encoding="utf-8", errors="replace").splitlines()[-n:] if p.exists() else []

    def data(self) -> dict:
        last = self.rows[-1] if self.rows else {}
        health = {}
        for s in self.sensors:
            v = last.get(s, math.nan)
            health[s] = {"value": v if math.isfinite(v) else None,
                         "state": "missing" if not math.isfinite(v) else "held" if last.get("held") else "ok"}
        return {"time_s": last.get("time_s"), "offset_um": last.get("offset_um"), "counts": self.counts,
                "sensors": health, "events": self.events(),
                "series": {k: [[r["time_s"], r.get(k)] for r in self.rows
                               if r.get(k) is not None and math.isfinite(r[k])] for k, _, _ in SERIES}}

    def page(self) -> str:
        d = self.data()
        rows = "".join(f"<tr><td>{html.escape(s)}</td><td>{_number(h['value'])}</td>"
                       f"<td class='{h['state']}'>{h['state']}</td></tr>" for s, h in d["sensors"].items())
        counts = "".join(f"<li>{html.escape(k)}: {v}</li>" for k, v in d["counts"].items())
        fired = ", ".join(f"{html.escape(k)} ({v})" for k, v in d["counts"].items() if k in GUARDS and v) or "none"
        events = "".join(f"<li>{html.escape(e)}</li>" for e in d["events"]) or "<li>none</li>"
        last = self.rows[-1] if self.rows else {}
        t = "—" if d["time_s"] is None else f"{d['time_s']:g} s"
        now = "; ".join(f"{name} {_um(last.get(k))}" for k, _, name in SERIES)
        return (f"<!DOCTYPE html><html><head><meta charset='utf-8'><noscript><meta http-equiv='refresh' "
                f"content='{REFRESH_S}'></noscript><title>gatetherm live</title><style>body{{font-family:sans-serif;"
                "margin:1em}.missing,.stale{color:#c0392b}.held{color:#b7791f}.ok{color:#2c7a2c}td{padding:0 1em}"
                "</style></head><body><h1>gatetherm live</h1><p id='link'>updated every "
                f"{REFRESH_S} s</p><div id='live'><p id='now'>machine time {t}; {now}</p>"
                f"{_chart(d['series'])}<h2>Sensors</h2><table id='sensors'>{rows}</table>"
                f"<h2>Guards</h2><p id='fired'>fired: {fired}</p><ul id='counts'>{counts}</ul>"
                f"<h2>Events</h2><ul id='events'>{events}</ul></div>{SCRIPT % (1000 * REFRESH_S)}</body></html>")


def _um(v) -> str:
    return "—" if v is None or not math.isfinite(v) else f"{v:.2f} µm"


def _number(v) -> str:
    return "" if v is None else f"{v:.3f}"


def _chart(series: dict, w: int = 720, h: int = 240) -> str:
    """Inline SVG of the series (time in h, µm), with a legend."""
    pts = [p for s in series.values() for p in s]
    if not pts:
        return "<p id='chart'>no data yet</p>"
    t0, t1 = min(p[0] for p in pts), max(p[0] for p in pts)
    y0, y1 = min(p[1] for p in pts), max(p[1] for p in pts)
    t1, y1 = (t1 if t1 > t0 else t0 + 1), (y1 if y1 > y0 else y0 + 1)

    def xy(p):
        return f"{40 + (w - 50) * (p[0] - t0) / (t1 - t0):.1f},{h - 20 - (h - 30) * (p[1] - y0) / (y1 - y0):.1f}"

    lines = "".join(f"<polyline fill='none' stroke='{c}' points='{' '.join(map(xy, series[k]))}'/>"
                    for k, c, _ in SERIES if series.get(k))
    legend = " ".join(f"<span style='color:{c}'>■ {n}</span>" for k, c, n in SERIES if series.get(k))
    return (f"<svg id='chart' width='{w}' height='{h}' xmlns='http://www.w3.org/2000/svg'>"
            f"<text x='2' y='12' font-size='11'>{y1:.1f} µm</text><text x='2' y='{h - 22}' font-size='11'>{y0:.1f} µm</text>"
            f"<text x='40' y='{h - 4}' font-size='11'>{t0 / 3600:.2f} h</text>"
            f"<text x='{w - 60}' y='{h - 4}' font-size='11'>{t1 / 3600:.2f} h</text>{lines}</svg><p>{legend}</p>")


async def serve_status(status: Status, port: int) -> asyncio.AbstractServer:
    """Serve ``status`` on ``127.0.0.1:port`` (``/`` and ``/status.json``) in the running loop."""
    async def handle(reader, writer):
        try:
            line = (await asyncio.wait_for(reader.readline(), 5.0)).decode("latin-1").split()
            while (await asyncio.wait_for(reader.readline(), 5.0)) not in (b"\r\n", b"\n", b""):
                pass
            path = line[1] if len(line) > 1 else "/"
            if path == "/":
                body, kind, code = status.page().encode(), "text/html; charset=utf-8", "200 OK"
            elif path == "/status.json":
                body, kind, code = json.dumps(status.data()).encode(), "application/json", "200 OK"
            else:
                body, kind, code = b"not found\n", "text/plain", "404 Not Found"
            writer.write(f"HTTP/1.0 {code}\r\nContent-Type: {kind}\r\nContent-Length: {len(body)}\r\n"
                         "Cache-Control: no-store\r\n\r\n".encode() + body)
            await writer.drain()
        except (asyncio.TimeoutError, ConnectionError):
            pass
        finally:
            writer.close()

    return await asyncio.start_server(handle, "127.0.0.1", port)
