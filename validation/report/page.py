"""The report as one self-contained HTML page: inline style, no script, no network; figures are
PNG files beside it, linked relatively. Every table and figure is captioned with the command
that regenerates its section alone, the gatetherm version and the date it was computed."""
from __future__ import annotations

import datetime
import html
import re

from gatetherm import __version__

STYLE = """
body{font:15px/1.5 system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;color:#1d1d1f;margin:0;background:#fafafa}
main{max-width:1180px;margin:0 auto;padding:24px 28px 64px;background:#fff}
h1{font-size:28px;margin:0 0 4px}h2{font-size:21px;margin:40px 0 6px;padding-top:12px;border-top:2px solid #ddd}
p,li{max-width:900px}.meta{color:#555;font-size:13px}code{font:13px ui-monospace,Menlo,Consolas,monospace;
background:#f0f0f3;padding:1px 4px;border-radius:3px}
table{border-collapse:collapse;margin:6px 0 2px;font-size:13px}th,td{border:1px solid #d5d5da;padding:3px 7px;
text-align:left;vertical-align:top}th{background:#eef0f4}tr:nth-child(even) td{background:#f8f9fb}
.wrap{overflow-x:auto;margin:14px 0}.cap{font-size:12.5px;color:#444;margin:4px 0 0;max-width:1100px}
.regen{color:#666}.figs{display:grid;grid-template-columns:repeat(auto-fill,minmax(520px,1fr));gap:22px;margin:14px 0}
figure{margin:0}figure img{width:100%;height:auto;border:1px solid #e3e3e8;background:#fff}
.pending{background:#f4f4f6;border-left:4px solid #aaa;padding:8px 14px;color:#444}
.badge{display:inline-block;font-size:11.5px;padding:0 6px;border-radius:8px;background:#e7eef9;color:#234}
.badge.none{background:#eee;color:#666}nav ol{columns:2;max-width:900px}.wide td{white-space:nowrap}
"""


def inline(text: str) -> str:
    """Escaped text with `code` spans."""
    return re.sub(r"`([^`]+)`", r"<code>\1</code>", html.escape(text, quote=False))


def page(title: str, head: list[str], body: list[str]) -> str:
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            f"<title>{html.escape(title)}</title><style>{STYLE}</style></head>\n<body><main>\n"
            f"<h1>{html.escape(title)}</h1>\n" + "\n".join(f"<p class=\"meta\">{h}</p>" for h in head)
            + "\n" + "\n".join(body) + "\n</main></body></html>\n")


def stamp_text(stamp: dict, command: str) -> str:
    """The caption's tail: the command, the version with the code digest, the date."""
    day = stamp.get("date", "")[:10]
    code = f" (code {stamp['code']})" if stamp.get("code") else ""
    return (f"<span class=\"regen\">Regenerate: <code>{html.escape(command)}</code> · gatetherm "
            f"{html.escape(stamp.get('version', __version__))}{code} · {day}</span>")


def table_html(t, number: int, tail: str) -> str:
    head = "".join(f"<th>{inline(c)}</th>" for c in t.columns)
    rows = "".join("<tr>" + "".join(f"<td>{inline(c)}</td>" for c in r) + "</tr>" for r in t.rows)
    note = f" {inline(t.note)}" if t.note else ""
    wide = " class=\"wide\"" if len(t.columns) > 7 else ""
    return (f"<div class=\"wrap\"><table{wide}><thead><tr>{head}</tr></thead><tbody>{rows}</tbody></table>"
            f"<p class=\"cap\"><b>Table {number}.</b> {inline(t.title)}.{note} {tail}</p></div>")


def _join(folder: str, name: str) -> str:
    return f"{folder}/{name}" if folder else name


def figure_html(folder: str, f, number: int, tail: str) -> str:
    src = _join(folder, f.file)
    return (f"<figure><a href=\"{html.escape(src)}\"><img src=\"{html.escape(src)}\" alt=\"{html.escape(f.caption)}\" "
            f"loading=\"lazy\"></a><figcaption class=\"cap\"><b>Figure {number}.</b> {inline(f.caption)}. {tail}"
            "</figcaption></figure>")


def result_html(result, folder: str, command: str, counter: dict) -> list[str]:
    """Notes, tables, figures and file links of one result."""
    tail = stamp_text(result.stamp, command)
    out = ["<ul>" + "".join(f"<li>{inline(n)}</li>" for n in result.notes) + "</ul>"] if result.notes else []
    for t in result.tables:
        counter["table"] += 1
        out.append(table_html(t, counter["table"], tail))
    if result.figures:
        figs = []
        for f in result.figures:
            counter["figure"] += 1
            figs.append(figure_html(folder, f, counter["figure"], tail))
        out.append("<div class=\"figs\">" + "\n".join(figs) + "</div>")
    if result.files:
        out.append("<p>Files: " + ", ".join(f"<a href=\"{html.escape(_join(folder, f))}\">{html.escape(f)}</a> "
                                            f"({inline(what)})" for f, what in result.files) + "</p>")
    return out


def _status(section, result) -> str:
    if section.pending:
        return "<span class=\"badge none\">not in this build</span>"
    if result is None:
        return "<span class=\"badge none\">not computed</span>"
    return f"<span class=\"badge\">{'full' if result.stamp.get('full') else 'subset'}</span>"


def report_html(sections, results: dict, out: str, full: bool, code: str) -> str:
    """The validation report page of ``results`` {key: Result or None} in ``sections`` order;
    ``out`` is the folder as the user names it (for the commands in the captions)."""
    counter = {"table": 0, "figure": 0}
    now = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    head = [f"gatetherm {html.escape(__version__)}, code digest <code>{code[:12]}</code>; page written {now}.",
            f"Regenerate the page: <code>gatetherm report --out {html.escape(out)}"
            f"{' --full' if full else ''}</code> (the default run computes a stated subset of the long studies; "
            "<code>--full</code> runs them all). Each section is cached under <code>sections/</code> by a digest of "
            "its scope, gatetherm's version, the package's source files (all but the CLI and the report's builder, "
            "page, Markdown and browser modules) and its data files and external programs: a rerun with nothing "
            "changed recomputes nothing."]
    nav = "<nav><ol>" + "".join(f"<li><a href=\"#{s.key}\">{html.escape(s.title)}</a> {_status(s, results.get(s.key))}"
                                "</li>" for s in sections) + "</ol></nav>"
    body = [nav]
    for s in sections:
        r = results.get(s.key)
        body.append(f"<section id=\"{s.key}\"><h2>{html.escape(s.title)} {_status(s, r)}</h2>")
        if s.pending:
            body.append(f"<p class=\"pending\">Not in this build: {inline(s.pending)}. It is one entry in "
                        "<code>validation/report/registry.py</code> with its compute function under "
                        "<code>validation/report/sections/</code>.</p></section>")
            continue
        command = s.command(out, bool(r and r.stamp.get("full") and s.full))
        if r is None:
            body.append(f"<p class=\"pending\">Not computed in this folder for the current code: "
                        f"<code>{html.escape(command)}</code>.</p></section>")
            continue
        st = r.stamp
        scope = "full study" if st.get("full") else f"subset: {s.about}; `--full` runs the whole study"
        body.append(f"<p class=\"meta\">Computed {html.escape(st.get('date', ''))} in {st.get('seconds', 0):.0f} s "
                    f"(load average {st.get('load', 0):.1f} on {st.get('cpus', '?')} CPUs) · {inline(scope)}"
                    f" · digest <code>{st.get('digest', '')}</code>"
                    + (f" · outside the report: <code>{html.escape(s.also)}</code>" if s.also else "") + "</p>")
        body += result_html(r, f"sections/{s.key}", command, counter)
        body.append("</section>")
    return page("gatetherm validation report", head, body)


def drift_html(result, source: str, command: str) -> str:
    """The thermal drift report page of one time series (figures beside the page)."""
    head = [f"Data: <code>{html.escape(source)}</code>; gatetherm {html.escape(__version__)}; "
            f"{datetime.datetime.now().astimezone().isoformat(timespec='seconds')}."]
    return page("Thermal drift report", head, result_html(result, "", command, {"table": 0, "figure": 0}))
