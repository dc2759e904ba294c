"""``gatetherm report``: every validation result on one page.

A registry of sections (:mod:`.registry`), each a title, the command that regenerates it
alone, a compute function (:mod:`.sections`) returning tables and figures, and the inputs
its cache digest covers; :mod:`.build` computes or reuses each section's result, :mod:`.page`
writes ``index.html``, :mod:`.markdown` the same results as
a Markdown page (``validation.md``; ``--docs DIR``: the repository's results page), :mod:`.drift`
is the thermal drift report of one time series and :mod:`.browser` checks a page in
headless Chromium.
"""
