"""The validation results as one Markdown page: ``R/validation.md`` beside ``R/index.html``,
and with ``--docs DIR`` the repository's results page ``DIR/validation.md``. Every section's
scope, notes and tables, each captioned with the command that regenerates it, the gatetherm
version with the code digest and the date, so that the docs quote the numbers the report
computed (the page is written by the report, never by hand)."""
from __future__ import annotations

import datetime
import re

from gatetherm import __version__

_BLOCK = re.compile(r'<a id="([\w-]+)"></a>\n\n(.*?)(?=\n<a id="|\Z)', re.S)


def table_markdown(t, number: int) -> str:
    """A table with its caption (title and note) under it."""
    def line(cells):
        return "| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |"
    note = f" {t.note}" if t.note else ""
    return "\n".join([line(t.columns), "|" + " --- |" * len(t.columns), *map(line, t.rows), "",
                      f"*Table {number}.* {t.title}.{note}"])


def _status(section, result) -> str:
    if section.pending:
        return "not in this build"
    if result is None:
        return "not computed"
    return "full study" if result.stamp.get("full") else "subset"


def previous_sections(page: str) -> dict[str, tuple[str, str]]:
    """{key: (its status in the list of contents, its text)} of the sections of a results page."""
    toc = dict(re.findall(r"^- \[.*?\]\(#([\w-]+)\) \((.*?)\)$", page, re.M))
    return {k: (toc.get(k, "subset"), text.rstrip("\n")) for k, text in _BLOCK.findall(page)}


def results_markdown(sections, results: dict, out: str, full: bool, code: str, figures: bool = True,
                     previous: str | None = None) -> str:
    """The results page of ``results`` {key: Result or None} in ``sections`` order. ``out``: the
    report's folder as the commands name it; ``figures``: link the figures (the page lies in
    ``out``), else name them as shown on ``out/index.html``; ``previous``: an earlier page whose
    sections stand where a section was not computed now (each says when and from what code it was
    computed; the tables are numbered again)."""
    now = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
    kept = {k: v for k, v in previous_sections(previous or "").items() if results.get(k) is None}
    counter = 0

    def renumbered(match) -> str:  # a kept section's table, numbered in this page's order
        nonlocal counter
        counter += 1
        return f"*Table {counter}.*"
    L = ["# Validation results", "",
         f"Written by `gatetherm report --out {out}{' --full' if full else ''}` (gatetherm {__version__}, code "
         f"digest `{code[:12]}`, {now}); `--docs DIR` writes this page into `DIR/validation.md`. Do not edit it: "
         "rerun the report. The default run computes a stated subset of the long studies and `--full` all of "
         "them; each section says which it shows and the command that regenerates it alone. "
         f"The figures are on the HTML page, `{out}/index.html`."
         + (" The sections this run did not compute are those of the page before, each with its own date and "
            "code." if kept else ""), ""]
    L += [f"- [{s.title}](#{s.key}) ({kept[s.key][0] if s.key in kept else _status(s, results.get(s.key))})"
          for s in sections] + [""]
    for s in sections:
        r = results.get(s.key)
        if s.key in kept:
            L += [f'<a id="{s.key}"></a>', "", re.sub(r"^\*Table \d+\.\*", renumbered, kept[s.key][1], flags=re.M), ""]
            continue
        L += [f'<a id="{s.key}"></a>', "", f"## {s.title}", ""]
        if s.pending or r is None:
            L += [f"Not in this build: {s.pending}." if s.pending else
                  f"Not computed for the current code: `{s.command(out, full)}`.", ""]
            continue
        st = r.stamp
        scope = "the full study" if st.get("full") else f"a subset ({s.about}; `--full` runs the whole study)"
        L += [f"Computed {st.get('date', '')[:10]} in {st.get('seconds', 0):.0f} s (load average "
              f"{st.get('load', 0):.1f} on {st.get('cpus', '?')} CPUs), gatetherm {st.get('version', __version__)} "
              f"(code `{st.get('code', '')}`): {scope}. Regenerate: "
              f"`{s.command(out, bool(st.get('full') and s.full))}`"
              + (f"; outside the report: `{s.also}`." if s.also else "."), ""]
        L += [f"- {n}" for n in r.notes] + ([""] if r.notes else [])
        for t in r.tables:
            counter += 1
            L += [table_markdown(t, counter), ""]
        if figures:
            L += [f"![{f.caption}](sections/{s.key}/{f.file})" for f in r.figures] + ([""] if r.figures else [])
        elif r.figures:
            L += ["Figures (on the HTML page): " + "; ".join(f.caption for f in r.figures) + ".", ""]
    return "\n".join(L).rstrip("\n") + "\n"
