"""The pictures of a run directory (:func:`write_pictures`): which of a run's pictures it has,
in which order a :class:`~gatetherm.validation.plots.painter.Painter` draws them, and what each
needs made ready in the painting process."""
from __future__ import annotations

from gatetherm.validation.plots.labels import signal_labels
from gatetherm.validation.plots.run import has_response, plot_channels, plot_fluids, plot_response, state_title


PAINTING_ORDER = {2: ("deformed.png", "response.png", "channels.png", "oil_temperatures.png"),
                  3: ("deformed.png", "channels.png", "oil_temperatures.png", "response.png")}
"""The order the pictures are handed out in, by dimension: each goes to the painting process
given fewer, so that deformed and channels share one in 2-D, response and oil temperatures the
other (about equal work), while a 3-D deformed picture (pyvista) gets only the cheapest, oil
temperatures, beside it (``docs/performance.md``, "The 2-D default condition")."""


def _renderer(problem):
    """What the deformed picture of a run of ``problem`` needs made ready in a painting
    process: a 3-D body's renderer (:func:`~gatetherm.validation.plots.field.warm_surface`), or None."""
    from gatetherm.validation.plots.field import warm_surface

    return warm_surface if problem.elastic and problem.dim == 3 else None


def prepare_pictures(run, painter) -> None:
    """What the pictures of ``run`` (a :class:`~gatetherm.studies.run.scenario.ScenarioRun`, or
    the case it will run: made ready the sooner) need made ready in ``painter``'s process before
    :func:`write_pictures` gives them: the renderer of a 3-D body's deformed picture, in the
    process that will draw it."""
    work = _renderer(run.model.problem if hasattr(run, "model") else run.problem)
    if work is not None:
        painter.prepare(work)


def write_pictures(run, out, title: str, picture_s: float | None, solved: dict | None = None,
                   caption=None, painter=None, only=None) -> list[str]:
    """The pictures of a run (a :class:`~gatetherm.studies.run.scenario.ScenarioRun`) into ``out``,
    by what the case has: ``channels.png`` (every channel of a transient run), ``response.png``
    (θ_A, θ_B, θ_C and δ: Figs. 11–13), ``oil_temperatures.png`` (its fluids' supply, volume and
    wall: Fig. 10) and ``deformed.png`` (the state kept nearest ``picture_s``; ``caption``: its
    title as a function of the time drawn, default ``title, t = … min``); returns the names.
    Given a :class:`~gatetherm.validation.plots.painter.Painter`, they are handed to it (written
    once its ``finish`` returns); else written here. ``only``: the names to write (default: all)."""
    from pathlib import Path

    from gatetherm.validation.plots.field import deformed, render_deformed
    from gatetherm.validation.plots.painter import Painter

    out, cols, jobs = Path(out), run.columns, {}
    transient = len(cols["time_s"]) > 1
    wanted = (lambda name: True) if only is None else only.__contains__
    if picture_s is not None and run.model.elastic is not None and wanted("deformed.png"):  # the largest first
        caption = caption or (lambda t: state_title(title, t if transient else None))
        jobs["deformed.png"] = render_deformed, deformed(run, picture_s, caption, solved)
    if transient:
        jobs["channels.png"] = plot_channels, (cols, title)
    if transient and run.model.problem.fluids:
        jobs["oil_temperatures.png"] = plot_fluids, (cols, run.model.problem, title)
    if has_response(cols):
        jobs["response.png"] = plot_response, (cols, title, None, None, signal_labels(run.model.problem))
    order = PAINTING_ORDER[3 if run.model.dim == 3 else 2]
    jobs = dict(sorted(((k, v) for k, v in jobs.items() if wanted(k)), key=lambda job: order.index(job[0])))
    painter = Painter(0) if painter is None else painter
    for name, (plot, args) in jobs.items():
        painter.draw(plot, *args, path=out / name, tight=name != "channels.png",
                     needs=_renderer(run.model.problem) if name == "deformed.png" else None)
    return list(jobs)
